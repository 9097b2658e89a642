#!/usr/bin/env python3
"""Which of the reference folders (or files) a folder (file) is: outputs_same.py DIR REF... prints the index (0, 1, ...)
of the first reference DIR equals, or 'none' with the first difference. Equal: the same names (hidden names at the top,
the leftovers of killed runs, are not counted; the test checks those itself), the same bytes, except that timings
are not compared: keys and CSV columns whose name ends in _ms (a run's own speed)."""
import csv
import io
import json
import os
import sys


def files(root):
    out = {}
    for here, dirs, names in os.walk(root):
        rel = os.path.relpath(here, root)
        if rel == ".":
            dirs[:] = [d for d in dirs if not d.startswith(".")]
            names = [n for n in names if not n.startswith(".")]
        for n in names:
            out[os.path.normpath(os.path.join(rel, n))] = os.path.join(here, n)
    return out


def untimed(value):
    if isinstance(value, dict):
        return {k: untimed(v) for k, v in value.items() if not k.endswith("_ms")}
    if isinstance(value, list):
        return [untimed(v) for v in value]
    return value


def content(path):
    data = open(path, "rb").read()
    if path.endswith(".json"):
        return untimed(json.loads(data))
    if path.endswith(".csv"):
        rows = list(csv.reader(io.StringIO(data.decode())))
        if rows:
            keep = [i for i, name in enumerate(rows[0]) if not name.endswith("_ms")]
            return [[r[i] if i < len(r) else None for i in keep] for r in rows]
    return data


def difference(a, b):
    if os.path.isfile(a) or os.path.isfile(b):
        if not (os.path.isfile(a) and os.path.isfile(b)):
            return "not both files"
        return "" if content(a) == content(b) else "differs"
    fa, fb = files(a), files(b)
    if sorted(fa) != sorted(fb):
        return "names differ: %s" % sorted(set(fa) ^ set(fb))[:5]
    for name in sorted(fa):
        if content(fa[name]) != content(fb[name]):
            return "%s differs" % name
    return ""


def main():
    folder, refs = sys.argv[1], sys.argv[2:]
    why = []
    for i, ref in enumerate(refs):
        d = difference(folder, ref) if os.path.exists(folder) else "does not exist"
        if not d:
            print(i)
            return
        why.append("ref %d: %s" % (i, d))
    print("none (" + "; ".join(why) + ")")


main()
