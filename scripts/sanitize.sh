#!/usr/bin/env bash
# Builds the unit tests with AddressSanitizer + UndefinedBehaviorSanitizer (cmake -DBLURCUE_SANITIZE=ON, in
# build-asan/) and runs them: the fast, display-free ones with leak checking, then the GL ones (Mesa llvmpipe
# through EGL) with the leak suppressions of tests/lsan.supp for what Mesa itself keeps. Any report fails the run.
# Usage: scripts/sanitize.sh [-jN]   (default -j2)
set -euo pipefail
cd "$(dirname "$0")/.."
JOBS="${1:--j2}"
BUILD=build-asan
FAST_TESTS=(core_test optics_test protocol_test store_test synth_test calib_test stimuli_test session_test)
GL_TESTS=(render_test scene_render_test)
cmake -S . -B "$BUILD" -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG="-g -O1" -DBLURCUE_SANITIZE=ON > /dev/null
cmake --build "$BUILD" "$JOBS" --target "${FAST_TESTS[@]}" "${GL_TESTS[@]}"
# halt_on_error: the first report ends the test (and fails it); UBSan aborts by itself (-fno-sanitize-recover).
export ASAN_OPTIONS="halt_on_error=1:detect_leaks=1:strict_string_checks=1:detect_stack_use_after_return=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
run() {
  local label=$1; shift
  local status=0
  for t in "$@"; do
    local exe
    exe=$(find "$BUILD/src" -name "$t" -type f -executable | head -1)
    echo "== $label: $t"
    (cd "$BUILD" && "$exe" --gtest_brief=1) || status=1
  done
  return $status
}
start=$(date +%s)
status=0
run fast "${FAST_TESTS[@]}" || status=1
LSAN_OPTIONS="suppressions=$PWD/tests/lsan.supp:print_suppressions=0" run gl "${GL_TESTS[@]}" || status=1
echo "sanitized tests: $(( $(date +%s) - start )) s, $([ $status = 0 ] && echo 'no findings' || echo 'FAILED')"
exit $status
