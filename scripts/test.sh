#!/usr/bin/env bash
# Set up, build, and run every test (unit, integration, CLI) and the demo.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh --tests   # the main job's packages and the tests' (chromium), and the build
scripts/demo.sh
cd build
ctest --output-on-failure -j2 --timeout 600
