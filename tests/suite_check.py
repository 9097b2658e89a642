#!/usr/bin/python3
"""The suite's own rules, read from CTest's list of its tests (ctest --show-only=json-v1), so a test added later is held
to them too:
  - no test passes on its output alone: PASS_REGULAR_EXPRESSION makes CTest ignore the exit code (a crash after the
    matched line passed); a test that matches output runs through tests/expect_output.py (${BLURCUE_EXPECT});
  - no test can count a skip as a pass: no expected output mentions SKIP, and SKIP_RETURN_CODE is 77 where set (CTest
    then reports "Skipped", never "Passed");
  - no test's timeout is a speed check: none under 60 s (speed lives in blurcue bench).

usage: suite_check.py CTEST BUILD_DIR
"""
import json
import subprocess
import sys


def main():
    ctest, build = sys.argv[1], sys.argv[2]
    listing = subprocess.run([ctest, "--show-only=json-v1"], cwd=build, capture_output=True, text=True, check=True)
    tests = json.loads(listing.stdout)["tests"]
    problems = []
    wrapped = 0
    for t in tests:
        props = {p["name"]: p["value"] for p in t.get("properties", [])}
        name, command = t["name"], t.get("command", [])
        if "PASS_REGULAR_EXPRESSION" in props:
            problems.append(f"{name}: PASS_REGULAR_EXPRESSION {props['PASS_REGULAR_EXPRESSION']!r} ignores the exit "
                            "code; use ${BLURCUE_EXPECT} \"REGEX\" COMMAND...")
        if "SKIP_RETURN_CODE" in props and int(props["SKIP_RETURN_CODE"]) != 77:
            problems.append(f"{name}: SKIP_RETURN_CODE {props['SKIP_RETURN_CODE']} (the suite's skip code is 77)")
        if any(c.endswith("expect_output.py") for c in command):
            wrapped += 1
            rest = command[[c.endswith("expect_output.py") for c in command].index(True) + 1:]
            regex = rest[2] if rest[:1] == ["--exit"] else rest[0]
            if "SKIP" in regex:
                problems.append(f"{name}: its expected output {regex!r} lets a skip pass")
        if "TIMEOUT" in props and float(props["TIMEOUT"]) < 60:
            problems.append(f"{name}: TIMEOUT {props['TIMEOUT']} s reads as a speed check (speed lives in bench)")
    for p in problems:
        print(p)
    if problems or not tests:
        print(f"FAIL: {len(problems)} of {len(tests)} tests break the suite's rules")
        return 1
    print(f"ok: {len(tests)} tests: none passes on its output alone ({wrapped} match output through expect_output.py "
          "and check the exit code), none counts a skip as a pass, no timeout under 60 s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
