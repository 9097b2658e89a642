#!/usr/bin/env bash
# blurcue init from an installed, moved prefix, run from another folder: shipped examples become study folders that
# validate at once (a synthetic scene, its calibration, the depth matching's pictures, test 3's board-free photo, a
# QUEST+), one of them runs a simulated session; a used folder and an unknown example are refused in one line.
# usage: init_test.sh BUILD_DIR WORK_DIR
set -euo pipefail
BUILD=$1 W=$2
source "$(dirname "$0")/lib.sh"
install_moved "$BUILD"
for example in yes-no-ball pre-research-depth-matching test3-no-board quest-blur-difference; do
  $BC init "$example" --from "$example" > "$example.log" 2>&1 || fail "init $example: $(tail -2 "$example.log")"
  grep -q "^ok: " "$example.log" || fail "init $example did not validate: $(tail -2 "$example.log")"
  # The folder stands on its own: no path in its protocol leaves it.
  if grep -q '"\.\./' "$example/protocol.json"; then fail "$example/protocol.json points outside its folder"; fi
done
(cd yes-no-ball && $BC run protocol.json --participant S1 --observer sim --db record.sqlite > run.log 2>&1) \
  || fail "run: $(tail -2 yes-no-ball/run.log)"
$BC export --db yes-no-ball/record.sqlite --out yes-no-ball/tables > /dev/null || fail "export"
[ "$(wc -l < yes-no-ball/tables/trials.csv)" -gt 10 ] || fail "too few trials exported"
# A study's report without benchmarks: no benchmark page and no lines about skipped benchmarks.
(cd yes-no-ball && MPLCONFIGDIR=$W/mpl $BC report --db record.sqlite --out report --boot 20 > report.out 2> report.err) \
  || fail "report: $(tail -2 yes-no-ball/report.err)"
[ -s yes-no-ball/report/index.html ] && [ ! -e yes-no-ball/report/bench.html ] || fail "report: bench.html without benchmarks"
if grep -qi "bench" yes-no-ball/report.err; then fail "report speaks of benchmarks: $(grep -i bench yes-no-ball/report.err | head -2)"; fi
set +e
$BC init yes-no-ball --from yes-no-ball > /dev/null 2> used.err; used=$?
$BC init fresh --from yes-no-bal > /dev/null 2> unknown.err; unknown=$?
set -e
[ $used = 3 ] && grep -q "exists and is not an empty folder; init never overwrites" used.err \
  || fail "a used folder: exit $used $(cat used.err)"
[ $unknown = 2 ] && grep -q "did you mean yes-no-ball?" unknown.err && [ ! -e fresh ] \
  || fail "an unknown example: exit $unknown $(cat unknown.err)"
echo "ok: init makes shipped examples study folders that validate and run from an installed prefix"
