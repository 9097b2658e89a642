#!/usr/bin/env bash
# Set up, build, and run every test (unit, integration, CLI) and the demo. Each stage says how long it took.
set -euo pipefail
cd "$(dirname "$0")/.."
start=$SECONDS
scripts/setup.sh --tests   # the main job's packages and the tests' (chromium), and the build
echo "test.sh: setup and build took $((SECONDS - start)) s"
stage=$SECONDS
scripts/demo.sh
echo "test.sh: demo took $((SECONDS - stage)) s"
stage=$SECONDS
cd build
status=0
ctest --output-on-failure -j2 --timeout 600 || status=$?
echo "test.sh: tests took $((SECONDS - stage)) s; all together $((SECONDS - start)) s"
exit $status
