#!/usr/bin/env bash
# The README's first study, command by command, as a newcomer types it: the sh block between <!-- first-study -->
# and <!-- /first-study --> in README.md is run from an installed, moved prefix (its bin on PATH) in an empty folder
# with no source tree in reach. Every command must succeed, and what the README says comes out must: the study's
# sheet (its four pairs flagged invisible, as the README says), two simulated sessions of 4 edges x 2 repetitions
# (16 answers, counted by hand from the protocol the block writes), and a report that names the study.
# usage: readme_walk_test.sh BUILD_DIR WORK_DIR
set -euo pipefail
BUILD=$1 W=$2
SRC=$(cd "$(dirname "$0")/.." && pwd)
source "$SRC/tests/lib.sh"
install_moved "$BUILD"
export PATH="$W/moved/bin:$PATH" MPLCONFIGDIR=$W/mpl

awk '/<!-- first-study -->/ {on = 1; next} /<!-- \/first-study -->/ {on = 0} on' "$SRC/README.md" \
  | sed '/^```/d' > "$W/first-study.sh"
[ -s "$W/first-study.sh" ] || fail "README.md has no sh block between <!-- first-study --> and <!-- /first-study -->"
if grep -nE '(^|[ /])(scripts|build|results)/|\.\./' "$W/first-study.sh"; then
  fail "the first study names a path of the source tree; a newcomer with an installed blurcue has none"
fi

# Command by command: bash -x writes each command before it runs it, -e stops at the first that fails.
set +e
bash -eu -o pipefail -x "$W/first-study.sh" > "$W/walk.out" 2> "$W/walk.err"
status=$?
set -e
[ $status = 0 ] || fail "the README's first study stopped (exit $status) at: $(grep '^+' "$W/walk.err" | tail -1)
$(grep -v '^+' "$W/walk.err" | tail -4)"
typed=$(grep -c '^blurcue ' "$W/first-study.sh")
ran=$(grep -c '^+ blurcue ' "$W/walk.err")
[ "$typed" = "$ran" ] && [ "$typed" -ge 6 ] || fail "the block has $typed blurcue commands, $ran ran"

S=$W/elsewhere/my-study
[ -s "$S/sheet.png" ] || fail "no contact sheet: preview wrote no sheet.png"
# The README says the preview flags all four pairs as invisible on the default monitor (62-67 % correct).
grep -q "4 distinct pairs, 4 invisible" "$W/walk.out" || fail "the preview no longer flags the README's four pairs: \
$(grep -m1 "distinct pairs" "$W/walk.out")"
answers=$(sql "$S/record.sqlite" "SELECT count(*) FROM responses r JOIN trials t ON t.id = r.trial_id
                                  JOIN sessions s ON s.id = t.session_id WHERE s.status = 'completed'")
[ "$answers" = 16 ] || fail "the record holds $answers answers of completed sessions; 2 participants x 4 edges x 2 = 16"
[ -s "$S/report/index.html" ] && grep -q "my-cards" "$S/report/index.html" \
  || fail "the report has no index.html naming the study my-cards"
echo "ok: the README's first study ran command by command ($ran blurcue commands) from an installed, moved prefix"
