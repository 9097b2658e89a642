#!/usr/bin/env python3
"""No report table or summary holds a number that means "not determined" (issue 23): every number in the report's
own tables (REPORT/*.csv, the exported tables/ and the benchmarks' measurements left out) and in index.html's text is
finite and at most 1e6 in size; such cases are written in words. Usage: report_numbers_check.py REPORT"""
import csv
import html
import math
import os
import re
import sys

LIMIT = 1e6
folder = sys.argv[1]
bad = []
checked = 0
for name in sorted(os.listdir(folder)):
    if not name.endswith(".csv") or name.startswith("bench-"):
        continue
    with open(os.path.join(folder, name), encoding="utf-8", newline="") as f:
        for line, row in enumerate(csv.DictReader(f), start=2):
            for column, cell in row.items():
                try:
                    x = float(cell)
                except (TypeError, ValueError):
                    continue
                checked += 1
                if not math.isfinite(x) or abs(x) > LIMIT:
                    bad.append(f"{name} line {line}, {column}: {cell}")
text = html.unescape(re.sub(r"<[^>]+>", " ", open(os.path.join(folder, "index.html"), encoding="utf-8").read()))
for number in re.findall(r"(?<![\w.])[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?(?![\w.])", text):
    if abs(float(number)) > LIMIT and not re.fullmatch(r"\d{7,}", number):  # long digit runs: seeds, hashes
        bad.append(f"index.html: {number}")
for word in ("inf", "nan", "1e+"):
    for m in re.finditer(rf"(?<![\w]){re.escape(word)}(?![\w])", text):
        bad.append(f"index.html: '{text[max(0, m.start() - 30):m.end() + 30]}'")
if bad:
    print("numbers that mean 'not determined' printed as results:\n  " + "\n  ".join(bad[:20]))
    sys.exit(1)
print(f"ok: {checked} numbers in the report's tables and its page, none beyond 1e6 or infinite")
