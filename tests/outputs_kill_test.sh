#!/usr/bin/env bash
# What a kill -9 of merge, export or report leaves behind: usage: outputs_kill_test.sh CASE BLURCUE DIR
# DIR holds protocols/ (tests/copy_protocols.cmake) and the scene they show. Each case kills the command several
# times at different points, checks that the output is the old one or the complete new one (never a mix, never
# half), that no process of it survives, and that the next successful run removes every leftover. It prints what
# it checked and exits non-zero on the first failure.
set -euo pipefail
CASE=$1 BC=$2 DIR=$3
P=$DIR/protocols
W=$DIR/outputs-$CASE
rm -rf "$W" && mkdir -p "$W"
source "$(dirname "$0")/lib.sh"
# A record of participant $2 in $1, grown by $3 extra display flips so that merge and export take a moment.
record() {
  $BC run "$P/test1-static-grids.json" --participant "$2" --db "$1" --observer sim > /dev/null 2>&1
  $PY - "$1" "$3" <<'PYEOF'
import sqlite3, sys
con = sqlite3.connect(sys.argv[1])
trials = [r[0] for r in con.execute("SELECT id FROM trials")]
per = int(sys.argv[2]) // len(trials)
with con:
    con.executemany("INSERT INTO frames (trial_id, frame_index, flip_time_s, dropped) VALUES (?, ?, ?, 0)",
                    ((t, 100000 + i, i / 60.0) for t in trials for i in range(per)))
con.close()
PYEOF
}
counts() { sql "$1" "SELECT (SELECT count(*) FROM sessions), (SELECT count(*) FROM trials),
                            (SELECT count(*) FROM responses), (SELECT count(*) FROM frames)"; }
# Names in $W beside the output (everything but the inputs and the references).
beside() { (cd "$W" && ls -A | grep -Ev '^(a|b|ab)\.sqlite(-wal|-shm)?$|^(ref|ref-a|ref-b|mpl|no-bench|err|out\.log|failing-python)$' || true); }
# A PID no process has: a shell that has exited.
dead_pid() { bash -c 'echo $$'; }
# Waits (up to 30 s) until $1 exists or process $2 has ended.
wait_for() { for _ in $(seq 1 3000); do [ -e "$1" ] && return 0; kill -0 "$2" 2>/dev/null || return 0; sleep 0.01; done; }
# Waits (up to 30 s) for process $1 to be gone; fails naming $2 if it stays.
wait_gone() {
  for _ in $(seq 1 3000); do kill -0 "$1" 2>/dev/null || return 0; sleep 0.01; done
  fail "$2 (pid $1) still running after its parent was killed: $(ps -o pid,ppid,comm -p "$1" | tail -1)"
}
# Whether $1 is a leftover .NAME.KIND-PID(-wal|-shm|-journal) of target $2 (KIND: partial, old) of a killed PID.
killed=" "
ours() {
  local rest=${1#.$2.}
  [ "$rest" != "$1" ] || return 1
  rest=${rest#partial-}; rest=${rest#old-}
  rest=${rest%-wal}; rest=${rest%-shm}; rest=${rest%-journal}
  case "$killed" in *" $rest "*) return 0 ;; esac
  return 1
}
# Every file under $1 with its checksum: the state of a folder, to tell whether it changed.
snapshot() { (cd "$1" && find . -type f -print0 | sort -z | xargs -0 md5sum); }

case $CASE in
merge)
  # Killed at different points, merge leaves no output or the complete one; the next merge removes the leftovers
  # (also those of earlier versions: OUT.partialPID and its -wal) and says so.
  record "$W/a.sqlite" A1 300000
  record "$W/b.sqlite" B1 0
  $BC merge "$W/a.sqlite" "$W/b.sqlite" --out "$W/ref" > /dev/null
  want=$(counts "$W/ref")
  killed_midway=0 finished=0
  for delay in 0 0.02 0.1 poll 0.3 0.6 poll; do
    $BC merge "$W/a.sqlite" "$W/b.sqlite" --out "$W/all.sqlite" > /dev/null 2>&1 &
    pid=$!
    if [ $delay = poll ]; then wait_for "$W/.all.sqlite.partial-$pid" $pid; else sleep $delay; fi
    kill -9 $pid 2>/dev/null || true
    wait $pid 2>/dev/null || true
    killed="$killed$pid "
    if [ -e "$W/all.sqlite" ]; then
      # It finished before the kill: then it is whole.
      [ "$(sql "$W/all.sqlite" 'PRAGMA integrity_check')" = ok ] || fail "merge killed after $delay s: a broken output"
      [ "$(counts "$W/all.sqlite")" = "$want" ] || fail "merge killed after $delay s: $(counts "$W/all.sqlite") != $want"
      finished=$((finished + 1))
      rm "$W/all.sqlite"
    fi
    for f in $(beside); do ours "$f" all.sqlite || fail "merge killed after $delay s left $f"; done
    ls -A "$W" | grep -q "^\.all\.sqlite\.partial-$pid" && killed_midway=$((killed_midway + 1))
  done
  # What an earlier version left when killed.
  old=$(dead_pid)
  cp "$W/b.sqlite" "$W/all.sqlite.partial$old" && : > "$W/all.sqlite.partial$old-wal"
  before=$(beside | wc -l)
  $BC merge "$W/a.sqlite" "$W/b.sqlite" --out "$W/all.sqlite" > /dev/null 2> "$W/err" || fail "merge: $(cat "$W/err")"
  [ "$(beside)" = all.sqlite ] || fail "left after a successful merge: $(beside | tr '\n' ' ')"
  [ "$(grep -c "^merge: removed .*, left by an interrupted run" "$W/err")" = "$before" ] ||
    fail "$before leftovers, the merge said: $(cat "$W/err")"
  [ "$(counts "$W/all.sqlite")" = "$want" ] || fail "merged $(counts "$W/all.sqlite"), expected $want"
  echo "ok: merge killed 7 times ($finished finished first, $killed_midway mid-way): never a partial output;" \
       "the next merge removed all $before leftovers and said so" ;;
export)
  # Exports of two different records into one folder, killed at different points: the folder is always exactly
  # one whole export (compared file by file with a reference export of each), never a new trials.csv beside an
  # old frames.csv; the next export removes the leftovers beside it.
  record "$W/a.sqlite" A1 300000
  record "$W/b.sqlite" B1 1000
  $BC merge "$W/a.sqlite" "$W/b.sqlite" --out "$W/ab.sqlite" > /dev/null
  $BC export --db "$W/a.sqlite" --out "$W/ref-a" > /dev/null
  $BC export --db "$W/ab.sqlite" --out "$W/ref-b" > /dev/null
  for f in trials.csv frames.csv; do cmp -s "$W/ref-a/$f" "$W/ref-b/$f" && fail "the two references share $f"; done
  $BC export --db "$W/a.sqlite" --out "$W/out" > /dev/null
  now=a seen_a=0 seen_b=0 i=0
  for delay in 0 0.1 0.3 0.6 1.0 poll 1.4 1.8 2.4 3.2 poll; do
    i=$((i + 1))
    src=$([ $((i % 2)) = 1 ] && echo ab || echo a)
    $BC export --db "$W/$src.sqlite" --out "$W/out" > /dev/null 2>&1 &
    pid=$!
    if [ $delay = poll ]; then wait_for "$W/.out.partial-$pid/trials.csv" $pid; else sleep $delay; fi
    kill -9 $pid 2>/dev/null || true
    wait $pid 2>/dev/null || true
    killed="$killed$pid "
    if diff -rq "$W/out" "$W/ref-a" > /dev/null; then now=a seen_a=$((seen_a + 1))
    elif diff -rq "$W/out" "$W/ref-b" > /dev/null; then now=b seen_b=$((seen_b + 1))
    else fail "export killed after $delay s left a folder that is neither export: $(diff -rq "$W/out" "$W/ref-a" | head -3)"
    fi
    for f in $(beside); do [ $f = out ] || ours "$f" out || fail "export killed after $delay s left $f"; done
  done
  mkdir "$W/.out.partial-$(dead_pid)" && : > "$W/.out.old-$(dead_pid)"  # certainly dead ones too
  before=$(($(beside | wc -l) - 1))
  $BC export --db "$W/ab.sqlite" --out "$W/out" > /dev/null 2> "$W/err" || fail "export: $(cat "$W/err")"
  [ "$(beside)" = out ] || fail "left after a successful export: $(beside | tr '\n' ' ')"
  [ "$(grep -c "^export: removed .*, left by an interrupted run" "$W/err")" = "$before" ] ||
    fail "$before leftovers, the export said: $(cat "$W/err")"
  diff -rq "$W/out" "$W/ref-b" > /dev/null || fail "the last export differs from its reference"
  # A folder holding something else is refused, not replaced.
  echo precious > "$W/out/notes.txt"
  if $BC export --db "$W/a.sqlite" --out "$W/out" 2> "$W/err"; then fail "export replaced a folder with notes.txt"; fi
  grep -q "out: holds notes.txt, which this command did not write" "$W/err" || fail "message: $(cat "$W/err")"
  [ "$(cat "$W/out/notes.txt")" = precious ] || fail "notes.txt changed"
  echo "ok: export killed 11 times: the folder was always one whole export ($seen_a x record a, $seen_b x record a+b);" \
       "the next export removed all $before leftovers and said so; a folder of other files is refused" ;;
report)
  # blurcue report killed while its analysis runs: the Python child dies with it, the earlier report stays as it
  # was (or no report appears), and the next report removes the leftovers.
  export MPLCONFIGDIR=$W/mpl
  record "$W/a.sqlite" A1 2000
  report() { $BC report --db "$W/a.sqlite" --out "$W/$1" --bench "$W/no-bench" --boot 20 "${@:2}"; }
  report ref > "$W/out.log" 2> "$W/err" || fail "report: $(cat "$W/err")"
  # The analysis failing (here: a Python that passes report's check, then fails on the script) leaves no report,
  # and nothing beside where it would be; one that is no Python at all is refused before anything is written.
  printf '#!/bin/sh\n[ "$1" = -c ] && exec /usr/bin/python3 "$@"\nexit 1\n' > "$W/failing-python"
  chmod +x "$W/failing-python"
  if report out --python "$W/failing-python" > /dev/null 2> "$W/err"; then fail "a failed analysis passed"; fi
  grep -q "out is unchanged" "$W/err" || fail "message: $(cat "$W/err")"
  [ "$(beside)" = "" ] || fail "a failed analysis left $(beside | tr '\n' ' ')"
  code=0
  report out --python /bin/false > /dev/null 2> "$W/err" || code=$?
  [ $code = 2 ] && grep -q "not a Python 3" "$W/err" || fail "/bin/false as --python: exit $code, $(cat "$W/err")"
  [ "$(beside)" = "" ] || fail "a refused --python left $(beside | tr '\n' ' ')"
  children=0
  # Killed as soon as Python runs with no earlier report; then over an earlier one, as soon as Python runs and
  # once it has written a chart.
  for target in none:python earlier:python earlier:chart; do
    before=${target%%:*} when=${target##*:}
    if [ $before = earlier ] && [ ! -e "$W/out" ]; then
      cp -a "$W/ref" "$W/out"
      state=$(snapshot "$W/out")
    fi
    $BC report --db "$W/a.sqlite" --out "$W/out" --bench "$W/no-bench" --boot 20 > /dev/null 2>&1 &
    pid=$!
    child=
    for _ in $(seq 1 3000); do
      child=$(pgrep -P $pid || true)
      [ -n "$child" ] && [ "$(ps -o comm= -p "$child" 2>/dev/null)" = python3 ] && break
      kill -0 $pid 2>/dev/null || fail "report ended before its analysis started"
      sleep 0.01
    done
    [ -n "$child" ] || fail "no analysis process under report (pid $pid)"
    if [ $when = chart ]; then
      for _ in $(seq 1 3000); do
        ls "$W/.out.partial-$pid/"*.png > /dev/null 2>&1 && break
        kill -0 $pid 2>/dev/null || fail "report ended before its first chart"
        sleep 0.01
      done
    fi
    kill -9 $pid
    wait $pid 2>/dev/null || true
    killed="$killed$pid "
    wait_gone "$child" "the analysis of a report killed at '$when'"
    # Killed with its parent, not ended on its own: an orphaned analysis would have finished its index.html.
    [ ! -e "$W/.out.partial-$pid/index.html" ] || fail "the analysis ran on after report was killed at '$when'"
    children=$((children + 1))
    if [ $before = earlier ]; then
      [ "$(snapshot "$W/out")" = "$state" ] || fail "report killed at '$when' changed the earlier report"
    else
      [ ! -e "$W/out" ] || fail "report killed at '$when' left a report where there was none"
    fi
    for f in $(beside); do [ $f = out ] || ours "$f" out || fail "report killed at '$when' left $f"; done
  done
  mkdir -p "$W/.out.partial-$(dead_pid)/tables"  # a certainly dead one too
  before=$(($(beside | wc -l) - 1))
  report out > /dev/null 2> "$W/err" || fail "report: $(cat "$W/err")"
  [ "$(beside)" = out ] || fail "left after a successful report: $(beside | tr '\n' ' ')"
  [ "$(grep -c "^report: removed .*, left by an interrupted run" "$W/err")" = "$before" ] ||
    fail "$before leftovers, the report said: $(cat "$W/err")"
  [ -s "$W/out/index.html" ] && [ -s "$W/out/tables/trials.csv" ] || fail "the new report is incomplete"
  [ "$(snapshot "$W/out")" != "$state" ] || fail "the new report did not replace the earlier one"
  grep -q "partial" "$W/out/index.html" && fail "index.html names the folder it was built in"
  grep -q "trials: $W/out/tables/trials.csv" "$W/out/index.html" || fail "index.html does not name its tables"
  echo "ok: report killed $children times: its analysis died with it every time, the earlier report stayed as it" \
       "was (and none appeared where there was none); a failed analysis left nothing; the next report" \
       "removed all $before leftovers" ;;
*) fail "unknown case $CASE" ;;
esac
