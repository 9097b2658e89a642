#!/usr/bin/env bash
# Builds the unit tests and the blurcue executable with AddressSanitizer + UndefinedBehaviorSanitizer
# (cmake -DBLURCUE_SANITIZE=ON, in build-asan/) and runs them: every unit-test binary a module declares with
# add_module_test (read from src/*/CMakeLists.txt, so a new one is never left out; the GL ones on Mesa's llvmpipe
# through EGL), and the CLI tests of hostile input (tests/hostile_cli_tests.cmake). Leak checking stays on
# everywhere; any report fails the run. Usage: scripts/sanitize.sh [-jN]   (default -j2)
set -euo pipefail
cd "$(dirname "$0")/.."
JOBS="${1:--j2}"
BUILD=build-asan
mapfile -t TESTS < <(grep -ho 'add_module_test([a-z_]*' src/*/CMakeLists.txt | cut -d'(' -f2 | sort)
[ ${#TESTS[@]} -ge 19 ] || { echo "sanitize.sh: found only ${#TESTS[@]} unit-test binaries in src/*/CMakeLists.txt"; exit 1; }
cmake -S . -B "$BUILD" -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG="-g -O1" -DBLURCUE_SANITIZE=ON > /dev/null
cmake --build "$BUILD" "$JOBS" --target "${TESTS[@]}" blurcue
# halt_on_error: the first report ends the test (and fails it); UBSan aborts by itself (-fno-sanitize-recover).
export ASAN_OPTIONS="halt_on_error=1:detect_leaks=1:strict_string_checks=1:detect_stack_use_after_return=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
run() {
  local label=$1; shift
  local status=0
  for t in "$@"; do
    local exe
    exe=$(find "$PWD/$BUILD/src" -name "$t" -type f -executable | head -1)
    echo "== $label: $t"
    (cd "$BUILD" && "$exe" --gtest_brief=1) || status=1
  done
  return $status
}
start=$(date +%s)
status=0
# Mesa's DRI driver allocates one-time globals inside eglInitialize and is dlclose'd before exit, which turns them
# into "leaks" from an <unknown module>. Loading the driver up front keeps it mapped until the end: its globals stay
# reachable and LeakSanitizer reports only what the project loses (no suppression list needed). Harmless for the
# binaries that draw nothing, so every one runs with it.
DRI=$(find /usr/lib -name swrast_dri.so -print -quit 2>/dev/null || true)
if [ -n "$DRI" ]; then
  LD_PRELOAD="$(gcc -print-file-name=libasan.so) $DRI" run unit "${TESTS[@]}" || status=1
else
  echo "no swrast_dri.so found: the GL tests run without leak checking"
  ASAN_OPTIONS="$ASAN_OPTIONS:detect_leaks=0" run unit "${TESTS[@]}" || status=1
fi
echo "== cli: hostile input"
# The same driver preload for blurcue's GL commands; ctest and cmake in between are not instrumented, so the
# preload cannot put the ASan runtime first: blurcue links it anyway, and the link-order check is off.
(cd "$BUILD" && LD_PRELOAD="$DRI" ASAN_OPTIONS="$ASAN_OPTIONS:verify_asan_link_order=0" \
   ctest -R '^cli_hostile_' -j2 --output-on-failure) || status=1
echo "sanitized tests: $(( $(date +%s) - start )) s, $([ $status = 0 ] && echo 'no findings' || echo 'FAILED')"
exit $status
