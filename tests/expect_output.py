#!/usr/bin/python3
"""Runs a test's command and passes it only when it exits 0 AND its output (stdout and stderr together) matches
REGEX - what CTest's PASS_REGULAR_EXPRESSION alone cannot do: with it CTest ignores the exit code, so a crash after
the matched line (a GL teardown segfault, a sanitizer report) passed.

usage: expect_output.py REGEX COMMAND [ARGS...]

REGEX is searched in the whole output as CMake's regular expressions do: '^' is the output's start, '.' matches a line
break too. Exit 77 (a tool the test needs is missing) passes through: CTest reports the test as Skipped where its
SKIP_RETURN_CODE is 77, and as Failed elsewhere - never as Passed. Every other non-zero exit, a signal, or output
without the match fails, saying which.
"""
import re
import subprocess
import sys


def main():
    if len(sys.argv) < 3:
        print(__doc__, file=sys.stderr)
        return 2
    pattern, command = sys.argv[1], sys.argv[2:]
    try:
        done = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
    except OSError as e:
        print(f"expect_output: cannot run {command[0]}: {e}")
        return 1
    out = done.stdout.decode("utf-8", "replace")
    sys.stdout.write(out)
    if done.returncode == 77:
        print("expect_output: exit 77 (skipped: a tool the test needs is missing)")
        return 77
    if done.returncode != 0:
        what = f"signal {-done.returncode}" if done.returncode < 0 else f"exit code {done.returncode}"
        print(f"\nexpect_output: FAILED: {what}, expected 0 (the output above may still match)")
        return 1
    if not re.search(pattern, out, re.DOTALL):
        print(f"\nexpect_output: FAILED: exit 0, but the output does not match {pattern!r}")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
