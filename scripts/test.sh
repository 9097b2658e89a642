#!/usr/bin/env bash
# Set up, build, and run every test (unit, integration, CLI) and the demo: the demo is ctest's test `demo`
# (tests/demo_tests.cmake), run beside the others. Each stage says how long it took.
set -euo pipefail
cd "$(dirname "$0")/.."
start=$SECONDS
scripts/setup.sh --tests   # the main job's packages and the tests' (chromium), and the build
echo "test.sh: setup and build took $((SECONDS - start)) s"
stage=$SECONDS
cd build
status=0
ctest --output-on-failure -j2 --timeout 600 || status=$?
echo "test.sh: the demo and the tests took $((SECONDS - stage)) s; all together $((SECONDS - start)) s"
# Where the tests' time went: the 15 longest of this run (wall seconds, two at a time), from ctest's own log.
echo "test.sh: the longest tests (s):"
awk '/^Test time =/ {t = $4} /" end time:/ {n = $1; gsub(/"/, "", n); printf "%8.1f %s\n", t, n}' \
    Testing/Temporary/LastTest.log 2>/dev/null | sort -g -r | head -15 || true
exit $status
