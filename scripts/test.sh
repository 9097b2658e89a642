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
# The output is kept (build/ctest-output.log) for the longest tests below: ctest's own LastTest.log is rewritten by
# the tests that run ctest themselves.
set +e
ctest --output-on-failure -j2 --timeout 600 2>&1 | tee ctest-output.log
status=${PIPESTATUS[0]}
set -e
echo "test.sh: the demo and the tests took $((SECONDS - stage)) s; all together $((SECONDS - start)) s"
# Where the tests' time went: the 15 longest of this run (wall seconds, two at a time).
echo "test.sh: the longest tests (s):"
awk '$2 == "Test" && $3 ~ /^#[0-9]+:$/ && $NF == "sec" {printf "%8.1f %s\n", $(NF - 1), $4}' ctest-output.log \
    | sort -g -r | head -15 || true
exit $status
