#!/bin/bash
# Ctrl-C ends `blurcue live` cleanly (issue 43: "each ends in a clear line and a complete log"): the 60-frame take of
# live_test.sh's fixture played headless at 10 fps (6 s), SIGINT sent after 2.5 s, as a terminal's Ctrl-C sends it
# to the process. Exit 0 (the experimenter ended it), one line saying so, and the log whole: live.csv has a row per
# frame shown, as summary.json counts them, every row has every field, summary.json says how the run ended.
# Usage: live_interrupt_test.sh BLURCUE DIR (DIR: live_test.sh's, after its make case)
set -u
BC=$1 W=$2
. "$(dirname "$0")/lib.sh"
T=$W/take O=$W/interrupt
rm -rf "$O" && mkdir -p "$O"
"$BC" live "$T/take.avi" --camera "$T/camera.json" --track "$W/track" --ball 87.5,125 --fps 10 --log "$O/log" \
  > "$O/out" 2> "$O/err" &
pid=$!
sleep 2.5
kill -INT $pid
wait $pid
code=$?
[ $code -eq 0 ] || fail "live after SIGINT: exit $code: $(cat "$O/err")"
grep -q "^interrupted (SIGINT)$" "$O/out" || fail "live did not say it was interrupted: $(cat "$O/out")"
$PY - "$O/log" <<'PYEOF' || fail "the log after SIGINT"
import csv, json, sys
log = sys.argv[1]
s = json.load(open(f"{log}/summary.json"))
assert s["ended"] == "interrupted (SIGINT)", s["ended"]
rows = list(csv.reader(open(f"{log}/live.csv")))
header, rows = rows[0], rows[1:]
assert all(len(r) == len(header) and all(r[:3]) for r in rows), "a row of live.csv is not whole"
dropped = sum(int(r[header.index("dropped")]) for r in rows)
assert len(rows) == s["frames_shown"] and dropped <= s["frames_dropped"], (len(rows), dropped, s)
seen = len(rows) + s["frames_dropped"]
assert 5 <= seen < 60, f"{seen} frames: SIGINT after 2.5 s of 6 should end it midway"
print(f"ok: interrupted after {seen} of 60 frames, live.csv and summary.json whole")
PYEOF
echo "ok: live_interrupt"
