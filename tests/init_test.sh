#!/usr/bin/env bash
# blurcue init from an installed, moved prefix, run from another folder: shipped examples become study folders that
# validate at once (a synthetic scene, its calibration, the depth matching's pictures, test 3's board-free photo, a
# QUEST+), each runs a simulated session into one record, and that record's report covers every study; a used folder
# and an unknown example are refused in one line.
# usage: init_test.sh BUILD_DIR WORK_DIR
set -euo pipefail
BUILD=$1 W=$2
source "$(dirname "$0")/lib.sh"
install_moved "$BUILD"
# Every shipped example, as the README's first study does it: init, validate, a simulated session, and one report of
# them all (one record: every study in one report, as a lab's record holds them).
examples=$($BC init --help | sed -n '/^Examples shipped/,$p' | sed -n 's/^  \([a-z0-9-]*\)$/\1/p')
[ "$(echo "$examples" | wc -w)" -ge 10 ] || fail "init --help lists $(echo "$examples" | wc -w) examples"
for example in $examples; do
  $BC init "$example" --from "$example" > "$example.log" 2>&1 || fail "init $example: $(tail -2 "$example.log")"
  grep -q "^ok: " "$example.log" || fail "init $example did not validate: $(tail -2 "$example.log")"
  # The folder stands on its own: no path in its protocol leaves it.
  if grep -q '"\.\./' "$example/protocol.json"; then fail "$example/protocol.json points outside its folder"; fi
  # The schema its "$schema" names is there.
  schema=$($PY -c 'import json, sys; print(json.load(open(sys.argv[1]))["$schema"])' "$example/protocol.json")
  [ -f "$example/$schema" ] || fail "$example/protocol.json names \$schema $schema, not in the folder"
  $BC validate "$example/protocol.json" > /dev/null 2> "$example.err" || fail "validate $example: $(cat "$example.err")"
  info=()
  if [ "$example" = groups-and-info ]; then info=(--info age=30 --info handedness=right --info vision=normal); fi
  (cd "$example" && $BC run protocol.json --participant S1 --observer sim --sim-fps 4 --db ../all.sqlite "${info[@]}" \
     > run.log 2>&1) || fail "run $example: $(tail -2 "$example/run.log")"
  grep -q "completed" "$example/run.log" || fail "run $example: $(tail -1 "$example/run.log")"
done
$BC export --db all.sqlite --out tables > /dev/null || fail "export"
[ "$(cut -d, -f1 tables/trials.csv | sort -u | wc -l)" -ge 10 ] || fail "the export lacks studies"
# A study's report without benchmarks: no benchmark page and no lines about skipped benchmarks.
MPLCONFIGDIR=$W/mpl $BC report --db all.sqlite --out report --boot 20 > report.out 2> report.err \
  || fail "report: $(tail -2 report.err)"
[ -s report/index.html ] && [ ! -e report/bench.html ] || fail "report: bench.html without benchmarks"
if grep -qi "bench" report.err; then fail "report speaks of benchmarks: $(grep -i bench report.err | head -2)"; fi
for example in $examples; do grep -q "$example" report/index.html || fail "the report lacks $example"; done
set +e
$BC init yes-no-ball --from yes-no-ball > /dev/null 2> used.err; used=$?
$BC init fresh --from yes-no-bal > /dev/null 2> unknown.err; unknown=$?
set -e
[ $used = 3 ] && grep -q "exists and is not an empty folder; init never overwrites" used.err \
  || fail "a used folder: exit $used $(cat used.err)"
[ $unknown = 2 ] && grep -q "did you mean yes-no-ball?" unknown.err && [ ! -e fresh ] \
  || fail "an unknown example: exit $unknown $(cat unknown.err)"
echo "ok: init makes shipped examples study folders that validate and run from an installed prefix"
