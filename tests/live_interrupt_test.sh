#!/bin/bash
# Ctrl-C ends `blurcue live` cleanly (issue 43: "each ends in a clear line and a complete log"), on live_test.sh's
# 60-frame take, SIGINT sent as a terminal's Ctrl-C sends it to the process:
#   play     the take.avi played headless at 10 fps (6 s), SIGINT after 2.5 s
#   preload  the take's PNG frames with --preload, SIGINT as soon as live says it is decoding them (the decoding of
#            60 frames takes about a second): it was killed by the signal there, printing nothing and writing no log
# Either way: exit 0 (the experimenter ended it), the line saying so, and the log whole - live.csv a row per frame
# shown, as summary.json counts them, every row with every field, summary.json saying how the run ended.
# Usage: live_interrupt_test.sh BLURCUE DIR CASE (DIR: live_test.sh's, after its make case)
set -u
BC=$1 W=$2 CASE=$3
. "$(dirname "$0")/lib.sh"
T=$W/take O=$W/interrupt-$CASE
rm -rf "$O" && mkdir -p "$O"
case $CASE in
play) "$BC" live "$T/take.avi" --camera "$T/camera.json" --track "$W/track" --ball 87.5,125 --fps 10 --log "$O/log" \
        > "$O/out" 2> "$O/err" &
      pid=$!
      sleep 2.5 ;;
preload) "$BC" live "$T/frame-%04d.png" --camera "$T/camera.json" --track "$W/track" --ball 87.5,125 --preload \
           --log "$O/log" > "$O/out" 2> "$O/err" &
      pid=$!
      for _ in $(seq 1 1000); do grep -q "decoding .* before the start" "$O/err" && break; sleep 0.01; done
      grep -q "decoding .* before the start" "$O/err" || fail "live never said it was preloading: $(cat "$O/err")" ;;
*) fail "unknown case $CASE" ;;
esac
kill -INT $pid
wait $pid
code=$?
[ $code -eq 0 ] || fail "live after SIGINT: exit $code: $(cat "$O/err")"
grep -q "^interrupted (SIGINT)$" "$O/out" || fail "live did not say it was interrupted: $(cat "$O/out" "$O/err")"
$PY - "$O/log" $CASE <<'PYEOF' || fail "the log after SIGINT"
import csv, json, sys
log, case = sys.argv[1:3]
s = json.load(open(f"{log}/summary.json"))
assert s["ended"] == "interrupted (SIGINT)", s["ended"]
rows = list(csv.reader(open(f"{log}/live.csv")))
header, rows = rows[0], rows[1:]
assert all(len(r) == len(header) and all(r[:3]) for r in rows), "a row of live.csv is not whole"
dropped = sum(int(r[header.index("dropped")]) for r in rows)
assert len(rows) == s["frames_shown"] and dropped <= s["frames_dropped"], (len(rows), dropped, s)
seen = len(rows) + s["frames_dropped"]
if case == "play":
    assert 5 <= seen < 60, f"{seen} frames: SIGINT after 2.5 s of 6 should end it midway"
else:
    assert seen == 0, f"{seen} frames: SIGINT during the preload should end it before the first frame"
    assert s["preloaded_frames"] < 60, f"the preload ended before the signal came ({s['preloaded_frames']} frames)"
print(f"ok: interrupted ({case}) after {seen} of 60 frames, live.csv and summary.json whole")
PYEOF
echo "ok: live_interrupt $CASE"
