#!/bin/bash
# blurcue live end to end on a 60-frame ground-truth take (synth-take; tracked by track; drawn by ar for comparison):
#   make      the take, its track folder and ar's CSV of a ball (the fixture the other cases read)
#   window    played at 30 fps through `live --window` under an Xvfb of its own: tests/live_check.py holds the log whole,
#             every pose within 0.1 % depth of the truth and the ball's radius within 1 % of ar's; TIMING=1 also holds
#             the real-time bounds (dropped <= 5 %, latency median <= 33 ms, p95 <= 50 ms), which are printed otherwise;
#             then Escape pressed in the window (xdotool) ends a run, and so does the window closed (WM_DELETE_WINDOW,
#             tests/close_window.py): exit 0, one line, the log whole
#   headless  the same headless (EGL): the video ends, one clear line, exit 0, the log whole; a video cut in half:
#             one line naming it, exit 3, the log of the frames before the damage whole
#   nocamera  a camera that is not there: exit 3, one line naming the device, and a log of no frames written whole
#   refusals  a --log live may not replace (one's own files, another tool's frames, an input's folder: exit 2; a file:
#             exit 3), and a --preload of more frames than it may hold: refused at once, before a frame is decoded
# Usage: live_test.sh CASE BLURCUE DIR
set -u
CASE=$1 BC=$2 W=$3
. "$(dirname "$0")/lib.sh"
T=$W/take
LIVE=(--camera "$T/camera.json" --track "$W/track" --ball 87.5,125 --exposure-ms 30)

case $CASE in
make)
  rm -rf "$W" && mkdir -p "$W"
  "$BC" synth-take --out "$T" --frames 60 --supersample 2 --quiet || fail "synth-take failed"
  "$BC" track "$T/take.avi" --camera "$T/camera.json" --out "$W/track" --quiet || fail "track failed"
  "$BC" ar "$T/take.avi" --track "$W/track" --ball 87.5,125 --exposure-ms 30 --out "$W/ar.avi" --frames "$W/ar-frames" --quiet ||
    fail "ar failed"
  [ "$(wc -l < "$W/ar.csv")" -eq 61 ] || fail "ar.csv: not 60 frames: $(wc -l < "$W/ar.csv") lines"
  echo "ok: live_test make: a 60-frame take, tracked, and ar's ball" ;;
window)
  rm -rf "$W/window" && mkdir -p "$W/window"
  W=$W/window start_xvfb
  # --preload: the take decoded before the clock starts and delivered from memory, as a camera hands over decoded
  # frames (decoding FFV1 costs ~17 ms of CPU a frame, which no camera asks of this computer); the Escape and close
  # runs below, and the headless case, decode as they play.
  "$BC" live "$T/take.avi" "${LIVE[@]}" --window --fps 30 --preload --log "$W/window/log" --save-frame 30 \
    > "$W/window/out" 2> "$W/window/err" || fail "live --window: exit $?: $(cat "$W/window/err")"
  grep -q "^live: --preload: 60 frames (158 MB) decoded in .* s before the start; decoding is not timed$" "$W/window/err" ||
    fail "live --preload did not say what it decoded: $(cat "$W/window/err")"
  grep -q "in a window (vsync)" "$W/window/err" || fail "live did not say it showed a window: $(cat "$W/window/err")"
  grep -q "take.avi ended after 60 frames" "$W/window/out" || fail "live's end: $(cat "$W/window/out")"
  cat "$W/window/out"
  $PY "$(dirname "$0")/live_check.py" "$W/window/log" "$T" "$W/ar.csv" 60 --preloaded ${TIMING:+--timing} ||
    fail "live_check.py (window)"
  # Frame 30, or the first shown after it when 30 was dropped.
  saved=$(cd "$W/window/log" && ls frame-*.png 2> /dev/null)
  n=${saved#frame-}; n=${n%.png}
  [ -n "$saved" ] && [ "$(echo "$saved" | wc -l)" = 1 ] && [ $((10#$n)) -ge 30 ] ||
    fail "--save-frame 30 wrote: $saved"
  # The frame live showed is ar's frame of the same number, pixel for pixel: the photo untouched outside the ball, the ball's pixels
  # within a few levels (the pose tracked live may differ from track's in its last digits), and as much ball drawn.
  $PY - "$W/window/log/$saved" "$W/ar-frames/$saved" "$T/$saved" <<'PYEOF' || fail "$saved"
import sys
import numpy as np
from PIL import Image
live, ar, photo = (np.asarray(Image.open(p).convert("RGB"), dtype=float) for p in sys.argv[1:4])
ball = np.abs(ar - photo).sum(axis=2) > 3
assert ball.sum() > 500, f"ar drew only {ball.sum()} pixels"
d = np.abs(live - ar)
assert d[~ball].max() <= 1, f"live changed the photo outside the ball by {d[~ball].max()}"
assert d[ball].mean() <= 0.5 and d[ball].max() <= 16, f"ball pixels: mean {d[ball].mean():.3f}, max {d[ball].max()}"
signal_live, signal_ar = np.abs(live - photo)[ball].sum(), np.abs(ar - photo)[ball].sum()
assert abs(signal_live / signal_ar - 1) <= 0.01, (signal_live, signal_ar)
print(f"{sys.argv[1].split('/')[-1]}: live's ball = ar's over {ball.sum()} px: mean {d[ball].mean():.3f} levels, max {d[ball].max():.0f}")
PYEOF
  # Escape ends a run: the take at 10 fps (6 s), Escape pressed in the window once it shows frames; exit 0, the log
  # whole.
  "$BC" live "$T/take.avi" "${LIVE[@]}" --window --fps 10 --log "$W/window/escape" > "$W/window/escape.out" \
    2> "$W/window/escape.err" &
  pid=$!
  # The title says "- showing" once the first frame is on screen; Escape half a second after that.
  wid=$(timeout 60 xdotool search --sync --name "blurcue live: .* - showing" | head -1)
  [ -n "$wid" ] || fail "the live window never said it was showing a frame"
  sleep 0.5
  xdotool windowfocus --sync "$wid" key Escape || fail "xdotool could not press Escape in the window"
  wait $pid || fail "live --window, Escape: exit $?: $(cat "$W/window/escape.err")"
  head -1 "$W/window/escape.out" | grep -q "^Escape pressed$" || fail "Escape: $(cat "$W/window/escape.out")"
  shown=$(( $(wc -l < "$W/window/escape/live.csv") - 1 ))
  [ $shown -ge 1 ] && [ $shown -lt 55 ] && grep -q "\"ended\": \"Escape pressed\"" "$W/window/escape/summary.json" ||
    fail "Escape's log: $shown rows, $(cat "$W/window/escape/summary.json")"
  # The window closed as a window manager's close button closes it (WM_DELETE_WINDOW, tests/close_window.py): the
  # run ends with one line saying so, exit 0, the log whole.
  "$BC" live "$T/take.avi" "${LIVE[@]}" --window --fps 10 --log "$W/window/closed" > "$W/window/closed.out" \
    2> "$W/window/closed.err" &
  pid=$!
  wid=$(timeout 60 xdotool search --sync --name "blurcue live: .* - showing" | head -1)
  [ -n "$wid" ] || fail "the live window (to close) never said it was showing a frame"
  sleep 0.5
  $PY "$(dirname "$0")/close_window.py" "$wid" || fail "could not ask the window to close"
  wait $pid || fail "live --window, closed: exit $?: $(cat "$W/window/closed.err")"
  head -1 "$W/window/closed.out" | grep -q "^the window was closed$" || fail "closed: $(cat "$W/window/closed.out")"
  shown=$(( $(wc -l < "$W/window/closed/live.csv") - 1 ))
  [ $shown -ge 1 ] && [ $shown -lt 55 ] && grep -q "\"frames_shown\": $shown," "$W/window/closed/summary.json" &&
    grep -q "\"ended\": \"the window was closed\"" "$W/window/closed/summary.json" ||
    fail "the closed window's log: $shown rows, $(cat "$W/window/closed/summary.json")"
  echo "ok: live_test window" ;;
headless)
  rm -rf "$W/headless"
  "$BC" live "$T/take.avi" "${LIVE[@]}" --log "$W/headless" > "$W/headless.out" 2> "$W/headless.err"
  code=$?
  [ $code = 0 ] || fail "live headless: exit $code: $(cat "$W/headless.err")"
  head -1 "$W/headless.out" | grep -q "^$T/take.avi ended after 60 frames$" ||
    fail "the video's end is not one clear first line: $(cat "$W/headless.out")"
  grep -q "^[0-9]* frames shown, [0-9]* dropped" "$W/headless.out" || fail "no summary line: $(cat "$W/headless.out")"
  grep -q '"ended": ".*take.avi ended after 60 frames"' "$W/headless/summary.json" ||
    fail "summary.json does not say how the run ended: $(cat "$W/headless/summary.json")"
  $PY "$(dirname "$0")/live_check.py" "$W/headless" "$T" "$W/ar.csv" 60 || fail "live_check.py (headless)"
  # Without --measure-sections no frame measures a section, and none takes time for it (it logged 0.002 ms a frame).
  awk -F, 'NR > 1 && ($15 != 0 || $16 != "0.000") { bad++ } END { exit bad > 0 }' "$W/headless/live.csv" ||
    fail "measure_ms or sections not 0 without --measure-sections: $(cut -d, -f15,16 "$W/headless/live.csv" | sort | uniq -c)"
  # A video cut short: the frames before the damage are shown, then one line naming the video, exit 3, the log whole.
  head -c $(( $(stat -c %s "$T/take.avi") / 2 )) "$T/take.avi" > "$W/cut.avi"
  rm -rf "$W/cut"
  "$BC" live "$W/cut.avi" "${LIVE[@]}" --log "$W/cut" > "$W/cut.out" 2> "$W/cut.err"
  code=$?
  [ $code = 3 ] && [ "$(grep -c '^blurcue: ' "$W/cut.err")" = 1 ] &&
    grep -q "^blurcue: $W/cut.avi: damaged or truncated: frame [0-9]* of the 60 .*; the log of the [0-9]* frames shown is whole in $W/cut$" "$W/cut.err" ||
    fail "a cut video: exit $code, stderr: $(cat "$W/cut.err")"
  # Said once: the error on stderr, not its end line on stdout besides (stdout: the summary and where the log is).
  ! grep -q "damaged or truncated" "$W/cut.out" && grep -q "^[0-9]* frames shown, " "$W/cut.out" &&
    grep -q "^wrote $W/cut " "$W/cut.out" || fail "a cut video: the error said twice, or no summary: $(cat "$W/cut.out")"
  shown=$(( $(wc -l < "$W/cut/live.csv") - 1 ))
  [ $shown -gt 5 ] && grep -q "\"frames_shown\": $shown," "$W/cut/summary.json" ||
    fail "the cut video's log: $shown rows, $(cat "$W/cut/summary.json")"
  # The same with --preload: the damage is found before the start, the frames before it are played, then the same
  # line and exit 3.
  rm -rf "$W/cut-preload"
  "$BC" live "$W/cut.avi" "${LIVE[@]}" --preload --log "$W/cut-preload" > "$W/cut-preload.out" 2> "$W/cut-preload.err"
  code=$?
  [ $code = 3 ] && [ "$(grep -c '^blurcue: ' "$W/cut-preload.err")" = 1 ] &&
    grep -q "^blurcue: $W/cut.avi: damaged or truncated: frame [0-9]* of the 60 .*; the log of the [0-9]* frames shown is whole in $W/cut-preload$" "$W/cut-preload.err" ||
    fail "a cut video, --preload: exit $code, stderr: $(cat "$W/cut-preload.err")"
  preloaded=$(grep -o '"preloaded_frames": [0-9]*' "$W/cut-preload/summary.json" | grep -o '[0-9]*$')
  shown=$(( $(wc -l < "$W/cut-preload/live.csv") - 1 ))
  [ "${preloaded:-0}" -gt 5 ] && [ $shown -le "$preloaded" ] && [ $shown -gt 5 ] ||
    fail "the cut video's log, --preload: $shown rows, $(cat "$W/cut-preload/summary.json")"
  echo "ok: live_test headless" ;;
nocamera)
  rm -rf "$W/nocamera"
  "$BC" live /dev/video97 "${LIVE[@]}" --log "$W/nocamera" > "$W/nocamera.out" 2> "$W/nocamera.err"
  code=$?
  [ $code = 3 ] && [ "$(wc -l < "$W/nocamera.err")" = 1 ] &&
    grep -q "^blurcue: /dev/video97: no camera there" "$W/nocamera.err" ||
    fail "a missing camera: exit $code, stderr: $(cat "$W/nocamera.err")"
  [ "$(cat "$W/nocamera/live.csv" | wc -l)" = 1 ] || fail "the log of no frames is not a header alone"
  grep -q '"frames_shown": 0' "$W/nocamera/summary.json" || fail "summary.json: $(cat "$W/nocamera/summary.json")"
  # --preload is for a file: a camera decodes its own frames (a usage error before the camera is looked for).
  "$BC" live /dev/video97 "${LIVE[@]}" --preload --log "$W/nocamera-preload" > /dev/null 2> "$W/nocamera-preload.err"
  code=$?
  [ $code = 2 ] && [ "$(wc -l < "$W/nocamera-preload.err")" = 1 ] &&
    grep -q "^blurcue: --preload: /dev/video97 is a camera" "$W/nocamera-preload.err" ||
    fail "--preload with a camera: exit $code, stderr: $(cat "$W/nocamera-preload.err")"
  echo "ok: live_test nocamera: $(cat "$W/nocamera.err")" ;;
refusals)
  # Refused before the first frame, each in one line: --log DIR that live may not replace for what it holds - one's
  # own files, another tool's frames, an input's folder - is one usage error, exit 2 (one's own files were exit 3 and
  # an input's folder exit 2); a --log that is a file (a path of the wrong kind) is exit 3, as for every command.
  R=$W/refusals
  rm -rf "$R" && mkdir -p "$R/own" "$R/frames"
  echo "my notes" > "$R/own/notes.txt"
  cp "$T/frame-0000.png" "$R/frames/frame-0000.png"
  echo "a file" > "$R/file"
  refused() {  # refused CODE TEXT LOG_DIR
    "$BC" live "$T/take.avi" "${LIVE[@]}" --log "$3" > "$R/out" 2> "$R/err"
    code=$?
    [ $code = "$1" ] && [ "$(wc -l < "$R/err")" = 1 ] && grep -q -- "$2" "$R/err" ||
      fail "--log $3: exit $code (wanted $1 and '$2'): $(cat "$R/err")"
  }
  refused 2 "^blurcue: --log $R/own: holds notes.txt, which this command did not write" "$R/own"
  refused 2 "^blurcue: --log $R/frames: holds no live.csv: not a log live wrote" "$R/frames"
  refused 2 "^blurcue: --log $T: holds the input" "$T"
  refused 3 "^blurcue: --log $R/file: " "$R/file"
  [ "$(cat "$R/own/notes.txt")" = "my notes" ] && [ -f "$R/frames/frame-0000.png" ] || fail "a refused --log was changed"
  # --preload of more than it may hold: the frames are counted and refused at once, in round numbers, before one is
  # decoded: these 800 "frames" are no images, so decoding the first would have ended the run on a damaged frame
  # (exit 3) - as it did, after decoding up to 2000 MB where the frames were real.
  mkdir -p "$R/seq"
  for i in $(seq 0 799); do printf 'not a PNG' > "$R/seq/$(printf 'frame-%04d.png' "$i")"; done
  "$BC" live "$R/seq/frame-%04d.png" "${LIVE[@]}" --preload --log "$R/seq-log" > "$R/out" 2> "$R/err"
  code=$?
  [ $code = 2 ] && [ "$(wc -l < "$R/err")" = 1 ] &&
    grep -qx "blurcue: $R/seq/frame-%04d.png: --preload would hold its 800 frames decoded, 2.6 MB each (2105 MB): more than the 2000 MB it may hold (760 frames); give --frames 760, or leave --preload out" "$R/err" ||
    fail "--preload of 800 frames: exit $code: $(cat "$R/err")"
  [ ! -e "$R/seq-log" ] || fail "--preload refused, yet a log was written"
  echo "ok: live_test refusals" ;;
*) fail "unknown case $CASE" ;;
esac
