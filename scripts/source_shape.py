#!/usr/bin/env python3
"""Checks the shape of the sources in src/ (issue 41): no source file over 800 lines, at most --max-long functions
over 120 lines, and each of those carrying a line `// long: <why>` in the comment right above it.

Only the project's own sources count: every .cc and .h under SRC_DIR except the *_test.cc files. A function is what
starts at column 0 (not a namespace, type, using, template or preprocessor line), reaches a line ending in '{' within
8 lines, and ends at the next line that starts with '}' (the project's clang-format puts a function's braces there).

usage: source_shape.py SRC_DIR [--max-long N] [--max-unjustified M]

Prints every long function (lines, file:line, signature, its reason or "NO REASON") and every file over the limit,
then `ok: ...` and exits 0, or `FAIL: ...` and exits 1 when N or M is exceeded or a file is too long.
"""
import argparse
import os
import re
import sys

MAX_FUNCTION_LINES = 120
MAX_FILE_LINES = 800
NOT_A_FUNCTION = re.compile(r"^(namespace|struct|class|enum|using|typedef|static_assert|extern|template|#)")


def sources(src_dir):
    for root, dirs, files in os.walk(src_dir):
        dirs.sort()
        for name in sorted(files):
            if name.endswith((".cc", ".h")) and not name.endswith("_test.cc"):
                yield os.path.join(root, name)


def reason_above(lines, start):
    """The `// long: <why>` in the comment block right above line `start` (0-based), or None."""
    k = start - 1
    while k >= 0 and lines[k].lstrip().startswith("//"):
        m = re.match(r"\s*// long: (\S.*)", lines[k])
        if m:
            return m.group(1)
        k -= 1
    return None


def long_functions(path):
    """(lines, first line 1-based, signature, reason or None) of each function over MAX_FUNCTION_LINES."""
    with open(path, encoding="utf-8") as f:
        lines = f.read().split("\n")
    found = []
    i = 0
    while i < len(lines):
        line = lines[i]
        if re.match(r"^[A-Za-z~]", line) and not NOT_A_FUNCTION.match(line) and not line.rstrip().endswith(";"):
            j = i
            # A signature ends at its '{'; a line that ends in ';' or '}' (a declaration, a one-line function) or a
            # blank line ends the search: the next function's '{' is not this one's.
            while (j < len(lines) and j < i + 8 and lines[j].strip()
                   and not lines[j].rstrip().endswith(("{", ";", "}"))):
                j += 1
            if j < len(lines) and lines[j].rstrip().endswith("{") and not lines[j].rstrip().endswith("= {"):
                k = j + 1
                while k < len(lines) and not lines[k].startswith("}"):
                    k += 1
                n = k - i + 1
                if n > MAX_FUNCTION_LINES:
                    found.append((n, i + 1, line.strip()[:80], reason_above(lines, i)))
                i = k + 1
                continue
        i += 1
    return found, len(lines) - (1 if lines and lines[-1] == "" else 0)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("src_dir")
    parser.add_argument("--max-long", type=int, default=8, help="functions over 120 lines allowed (default 8)")
    parser.add_argument("--max-unjustified", type=int, default=0,
                        help="long functions allowed without a `// long:` reason (default 0)")
    args = parser.parse_args()
    long_count = unjustified = 0
    big_files = []
    for path in sources(args.src_dir):
        found, length = long_functions(path)
        rel = os.path.relpath(path, os.path.dirname(os.path.abspath(args.src_dir)))
        if length > MAX_FILE_LINES:
            big_files.append(rel)
            print(f"file over {MAX_FILE_LINES} lines: {rel} ({length})")
        for n, at, signature, reason in found:
            long_count += 1
            unjustified += reason is None
            print(f"{n} lines: {rel}:{at} {signature} - {reason or 'NO REASON (add // long: <why> above it)'}")
    summary = (f"{long_count} functions over {MAX_FUNCTION_LINES} lines (limit {args.max_long}), {unjustified} of "
               f"them without a reason (limit {args.max_unjustified}), {len(big_files)} files over "
               f"{MAX_FILE_LINES} lines (limit 0)")
    if long_count > args.max_long or unjustified > args.max_unjustified or big_files:
        print(f"FAIL: {summary}")
        return 1
    print(f"ok: {summary}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
