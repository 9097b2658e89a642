#!/usr/bin/env bash
# blurcue display check in a real window on an X server of its own: usage display_test.sh BLURCUE DIR
set -euo pipefail
BC=$1 W=$2/display-check
DATA=$(cd "$(dirname "$0")/data" && pwd)
rm -rf "$W" && mkdir -p "$W"
source "$(dirname "$0")/lib.sh"
start_xvfb
# The lab's 1280 x 1024 monitor (376 mm wide at 570 mm): 2 * 570 * tan(0.5 deg) / (376 / 1280) = 33.87 px/deg.
$BC display check --profile "$DATA/lab-monitor.json" --fullscreen --frames 30 --screenshot "$W/check.png" > "$W/out" \
  || fail "check: $(cat "$W/out")"
grep -q "lab 1: 1280 x 1024 px window, 33.87 px per degree at 570 mm" "$W/out" || fail "geometry: $(cat "$W/out")"
grep -Eq "flip interval over 30 flips: median [0-9.]+ ms" "$W/out" || fail "timing: $(cat "$W/out")"
# Xvfb has no vsync: the check must say it measured nothing rather than report a refresh rate.
grep -q "NOT MEASURED: the flips are not paced by a refresh" "$W/out" || fail "Xvfb reported as a refresh: $(cat "$W/out")"
[ -s "$W/check.png" ] || fail "no screenshot"
# A profile whose resolution is not the monitor's, full screen: exit 3 naming both.
set +e; $BC display check --fullscreen --frames 10 2> "$W/err"; code=$?; set -e
[ $code = 3 ] && grep -q "the default profile: the monitor shows 1280 x 1024 px, the profile says 1920 x 1080" "$W/err" \
  || fail "resolution mismatch: exit $code $(cat "$W/err")"
# A broken profile: every problem named with the file and the field.
echo '{"width_px": 1280, "height_px": 1024, "distance_mm": 0}' > "$W/bad.json"
set +e; $BC display check --profile "$W/bad.json" 2> "$W/err"; code=$?; set -e
[ $code = 3 ] && grep -q "bad.json: /distance_mm: must be in \[100, 20000\] mm, got 0" "$W/err" || fail "bad profile: $(cat "$W/err")"
# A session whose window cannot be the protocol's display size (full screen on this 1280 x 1024 screen, the protocol
# says 1280 x 720) is refused before anything is recorded: the record would state another scale than the one shown.
/usr/bin/python3 - "$2/protocols/test1-static-grids.json" "$2/protocols/test1-fullscreen.json" <<'PYEOF'
import json, sys
p = json.load(open(sys.argv[1]))
p["display"]["fullscreen"] = True
json.dump(p, open(sys.argv[2], "w"))
PYEOF
set +e; $BC run "$2/protocols/test1-fullscreen.json" --participant P1 --db "$W/fs.sqlite" --observer sim --window 2> "$W/err"; code=$?; set -e
[ $code = 3 ] && grep -q "test1-fullscreen.json: /display: the window opened at 1280 x 1024 px, the protocol's display says 1280 x 720 px" "$W/err" \
  || fail "window of another size: exit $code $(cat "$W/err")"
[ ! -e "$W/fs.sqlite" ] || fail "the refused session created its record"
echo "ok: display check shows the profile's geometry, refuses a wrong resolution and says Xvfb has no refresh to measure"
