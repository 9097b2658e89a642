#!/usr/bin/python3
"""Runs a test's command and passes it only when it exits 0 AND its output (stdout and stderr together) matches
REGEX - what CTest's PASS_REGULAR_EXPRESSION alone cannot do: with it CTest ignores the exit code, so a crash after
the matched line (a GL teardown segfault, a sanitizer report) passed.

usage: expect_output.py [--exit N] REGEX COMMAND [ARGS...]

--exit N: the command must exit N instead (a check that must catch something: a test of a test).

REGEX is searched in the whole output as CMake's regular expressions do: '^' is the output's start, '.' matches a line
break too. Exit 77 (a tool the test needs is missing) passes through: CTest reports the test as Skipped where its
SKIP_RETURN_CODE is 77, and as Failed elsewhere - never as Passed. Every other non-zero exit, a signal, or output
without the match fails, saying which.
"""
import re
import subprocess
import sys


def main():
    args = sys.argv[1:]
    expected = 0
    if args[:1] == ["--exit"] and len(args) > 1:
        expected, args = int(args[1]), args[2:]
    if len(args) < 2:
        print(__doc__, file=sys.stderr)
        return 2
    pattern, command = args[0], args[1:]
    try:
        done = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
    except OSError as e:
        print(f"expect_output: cannot run {command[0]}: {e}")
        return 1
    out = done.stdout.decode("utf-8", "replace")
    sys.stdout.write(out)
    if done.returncode == 77 and expected != 77:
        print("expect_output: exit 77 (skipped: a tool the test needs is missing)")
        return 77
    if done.returncode != expected:
        what = f"signal {-done.returncode}" if done.returncode < 0 else f"exit code {done.returncode}"
        print(f"\nexpect_output: FAILED: {what}, expected {expected} (the output above may still match)")
        return 1
    if not re.search(pattern, out, re.DOTALL):
        print(f"\nexpect_output: FAILED: exit {expected}, but the output does not match {pattern!r}")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
