#!/bin/bash
# blurcue ar end to end on a ground-truth take (synth-take, tracked by track): a ball and a standing card drawn in
# every frame, checked against the truth by tests/ar_check.py (numpy, nothing of blurcue's code); the video written;
# a truncated input ends with exit 3 and keeps the frames drawn; bad names and values are one line, exit 2 or 3.
# Usage: ar_test.sh BLURCUE WORKDIR
set -u
BC=$1
W=$2
. "$(dirname "$0")/lib.sh"
rm -rf "$W" && mkdir -p "$W"

"$BC" synth-take --out "$W/take" --frames 4 --supersample 2 --quiet || fail "synth-take failed"
[ -f "$W/take/take.avi" ] || fail "synth-take wrote no take.avi"
"$BC" track "$W/take/take.avi" --camera "$W/take/camera.json" --out "$W/track" --quiet || fail "track failed"

# A white and a black card (unlit: white minus black in linear light is the card's coverage alone), and a ball.
$PY - "$W" <<'PYEOF' || fail "could not write the test's textures"
import json, sys
import numpy as np
from PIL import Image
w = sys.argv[1]
for name, v in (("white", 255), ("black", 0)):
    Image.fromarray(np.full((32, 32, 3), v, np.uint8)).save(f"{w}/{name}.png")
    json.dump({"objects": [{"kind": "ball", "x_mm": 50, "y_mm": 125, "radius_mm": 10},
                           {"kind": "card", "x_mm": 125, "y_mm": 75, "width_mm": 30, "height_mm": 20,
                            "texture": f"{w}/{name}.png"}]}, open(f"{w}/{name}.json", "w"))
PYEOF

# Blurred (the take's lens model, a 20 ms exposure) and sharp (no blur, no motion), each with both cards.
for colour in white black; do
  "$BC" ar "$W/take/take.avi" --track "$W/track" --objects "$W/$colour.json" --exposure-ms 20 \
    --out "$W/$colour.avi" --frames "$W/blur-$colour" > "$W/ar-$colour.out" 2> "$W/ar-$colour.err" ||
    fail "ar ($colour) failed: $(cat "$W/ar-$colour.err")"
  "$BC" ar "$W/take/take.avi" --track "$W/track" --objects "$W/$colour.json" --exposure-ms 0 --blur none \
    --out "$W/sharp-$colour.avi" --frames "$W/sharp-$colour" --quiet || fail "ar --blur none ($colour) failed"
done
grep -q "^4 frames: 4 with objects, 0 without" "$W/ar-white.out" || fail "ar: $(cat "$W/ar-white.out")"
grep -q "exposure 20 ms (given)" "$W/ar-white.err" || fail "ar did not state its exposure: $(cat "$W/ar-white.err")"
[ "$(wc -l < "$W/white.csv")" -eq 9 ] || fail "white.csv: not 4 frames x 2 objects: $(cat "$W/white.csv")"
head -1 "$W/white.csv" | grep -q "^frame,time_s,status,object,screen_x_px,screen_y_px,depth_mm,r_px,floor_sigma_px,motion_x_px,motion_y_px$" ||
  fail "white.csv header: $(head -1 "$W/white.csv")"
# The AVI holds 4 frames (its RIFF header's frame count, read without OpenCV).
$PY - "$W/white.avi" <<'PYEOF' || fail "white.avi is not a 4-frame AVI"
import struct, sys
data = open(sys.argv[1], "rb").read()
assert data[:4] == b"RIFF" and data[8:12] == b"AVI ", data[:12]
i = data.index(b"avih")
frames = struct.unpack("<I", data[i + 8 + 16:i + 8 + 20])[0]
assert frames == 4, frames
print("white.avi: RIFF AVI, 4 frames")
PYEOF
$PY "$(dirname "$0")/ar_check.py" "$W" || fail "ar_check.py"

# The default exposure is the camera's (synth-take's camera.json says 0: each frame rendered at one instant), stated.
"$BC" ar "$W/take/take.avi" --track "$W/track" --ball 50,125 --out "$W/default.avi" > /dev/null 2> "$W/default.err" ||
  fail "ar with defaults: $(cat "$W/default.err")"
grep -q "exposure 0 ms (the camera's exposure_ms, as tracked)" "$W/default.err" ||
  fail "default exposure: $(cat "$W/default.err")"
# A camera whose exposure is unknown (no exposure_ms): the video's own rate sets it (30 fps: half the interval), stated.
rm -rf "$W/track-unknown" && cp -r "$W/track" "$W/track-unknown"
$PY - "$W/track-unknown" <<'PYEOF'
import glob, json, sys
for path in glob.glob(sys.argv[1] + "/calib-*.json"):
    calib = json.load(open(path))
    del calib["camera"]["exposure_ms"]
    json.dump(calib, open(path, "w"))
PYEOF
"$BC" ar "$W/take/take.avi" --track "$W/track-unknown" --ball 50,125 --out "$W/default-rate.avi" > /dev/null \
  2> "$W/default-rate.err" || fail "ar with defaults, exposure unknown: $(cat "$W/default-rate.err")"
grep -q "exposure 16.6667 ms (the camera's exposure is unknown: half the frame interval of the video's 30 fps" \
  "$W/default-rate.err" || fail "default exposure from the rate: $(cat "$W/default-rate.err")"
# An object outside the photo in every frame (a slip of millimetres: 5000 for 50; behind the camera): refused before
# anything is written, naming the option.
for ball in 5000,125 87.5,-400; do
  rm -f "$W/off.avi"
  "$BC" ar "$W/take/take.avi" --track "$W/track" --ball $ball --out "$W/off.avi" > /dev/null 2> "$W/off.err"
  code=$?
  [ $code = 3 ] && [ "$(wc -l < "$W/off.err")" = 1 ] && grep -q "^blurcue: --ball '$ball': ball1 at .* lies outside the photo in every frame" \
    "$W/off.err" && [ ! -e "$W/off.avi" ] || fail "a ball at $ball, outside every frame: exit $code $(cat "$W/off.err")"
done
# An exposure longer than a frame of the take: a usage error (exit 2), nothing drawn for minutes.
"$BC" ar "$W/take/take.avi" --track "$W/track" --ball 50,125 --exposure-ms 300 --out "$W/long-option.avi" > /dev/null \
  2> "$W/long-option.err"
code=$?
[ $code = 2 ] && grep -q "^blurcue: --exposure-ms 300: longer than a frame of the take (33.33 ms at 30 fps)" \
  "$W/long-option.err" || fail "--exposure-ms 300: exit $code $(cat "$W/long-option.err")"
# A camera whose exposure is longer than a frame of the take (a photo's camera.json, 500 ms): refused, not streaked.
rm -rf "$W/track-long" && cp -r "$W/track" "$W/track-long"
$PY - "$W/track-long" <<'PYEOF'
import glob, json, sys
for path in glob.glob(sys.argv[1] + "/calib-*.json"):
    calib = json.load(open(path))
    calib["camera"]["exposure_ms"] = 500
    json.dump(calib, open(path, "w"))
PYEOF
"$BC" ar "$W/take/take.avi" --track "$W/track-long" --ball 50,125 --out "$W/long.avi" > /dev/null 2> "$W/long.err"
code=$?
[ $code = 3 ] && grep -q "track-long: the camera.s exposure_ms: is 500 ms, longer than a frame of the take (33.33 ms at 30 fps)" \
  "$W/long.err" || fail "a camera exposure longer than a frame: exit $code $(cat "$W/long.err")"

# Truncated input: exit 3, one line naming the file, and the frames before it kept (video and CSV).
size=$(stat -c %s "$W/take/take.avi")
head -c $((size * 60 / 100)) "$W/take/take.avi" > "$W/truncated.avi"
"$BC" ar "$W/truncated.avi" --track "$W/track" --ball 50,125 --out "$W/trunc.avi" --quiet > "$W/trunc.out" 2> "$W/trunc.err"
code=$?
[ $code -eq 3 ] || fail "truncated input: exit $code, expected 3: $(cat "$W/trunc.err")"
[ "$(wc -l < "$W/trunc.err")" -eq 1 ] || fail "truncated input: not one line: $(cat "$W/trunc.err")"
grep -q "truncated.avi: damaged or truncated: frame [0-9] .* frames before it are in .*trunc.avi" "$W/trunc.err" ||
  fail "truncated input: $(cat "$W/trunc.err")"
kept=$(($(wc -l < "$W/trunc.csv") - 1))
[ $kept -ge 1 ] && [ $kept -lt 4 ] || fail "truncated input: $kept CSV rows kept"
$PY - "$W/trunc.avi" "$kept" <<'PYEOF' || fail "trunc.avi does not hold the frames drawn"
import struct, sys
data = open(sys.argv[1], "rb").read()
i = data.index(b"avih")
frames = struct.unpack("<I", data[i + 8 + 16:i + 8 + 20])[0]
assert frames == int(sys.argv[2]), (frames, sys.argv[2])
PYEOF
echo "truncated input: exit 3, $kept frames kept: $(cat "$W/trunc.err")"

# A lost frame (frame 2 marked lost, its calibration gone): written as it is, without objects, and flagged.
mkdir -p "$W/losttrack" && cp "$W/track/"* "$W/losttrack/" && rm "$W/losttrack/calib-0002.json"
sed -i '4s/^\([^,]*,[^,]*\),[a-z]*,/\1,lost,/' "$W/losttrack/track.csv"
"$BC" ar "$W/take/take.avi" --track "$W/losttrack" --ball 50,125 --out "$W/lost.avi" --frames "$W/lost" > "$W/lost.out" \
  2>&1 || fail "ar with a lost frame: $(cat "$W/lost.out")"
grep -q "^4 frames: 3 with objects, 1 without" "$W/lost.out" || fail "lost frame: $(cat "$W/lost.out")"
grep -q "^2,0.066667,lost,,,,,,,,$" "$W/lost.csv" || fail "lost frame's CSV row: $(cat "$W/lost.csv")"
$PY - "$W" <<'PYEOF' || fail "the lost frame is not the input frame"
import sys
import numpy as np
from PIL import Image
w = sys.argv[1]
a = np.asarray(Image.open(f"{w}/lost/frame-0002.png").convert("RGB"))
b = np.asarray(Image.open(f"{w}/take/frame-0002.png").convert("RGB"))
assert (a == b).all(), int((a != b).sum())
print("lost frame 2: written as it is")
PYEOF

# A study on the video (issue 27 item 4, first step): a protocol whose scene is the take and its track folder is
# validated and previewed through the same loading code as run (a trial shows the take's first frame with a pose).
cat > "$W/video-study.json" <<'JSONEOF'
{"name": "video-ball", "version": 1, "scene": {"video": "take/take.avi", "track": "track"},
 "content": {"type": "ball"}, "layout": "single", "task": "yes_no",
 "factors": {"edge": [3, 6], "blur": [{"object": "fitted"}, {"object": "none"}]},
 "responses": {"yes": "Y", "no": "N"}}
JSONEOF
"$BC" validate "$W/video-study.json" > "$W/validate.out" 2>&1 || fail "validate of a video study: $(cat "$W/validate.out")"
"$BC" preview "$W/video-study.json" --out "$W/video-preview.png" > "$W/preview.out" 2>&1 ||
  fail "preview of a video study: $(cat "$W/preview.out")"
[ -s "$W/video-preview.png" ] || fail "preview wrote no sheet"
"$BC" run "$W/video-study.json" --participant P1 --db "$W/video.sqlite" --observer sim > "$W/run.out" 2>&1 ||
  fail "run of a video study: $(cat "$W/run.out")"
grep -q "4 of 4 trials answered" "$W/run.out" || fail "run of a video study: $(cat "$W/run.out")"
$PY - "$W/video-study.json" "$W/bad-study.json" <<'PYEOF'
import json, sys
p = json.load(open(sys.argv[1]))
p["scene"]["background"] = "take/frame-0000.png"
json.dump(p, open(sys.argv[2], "w"))
PYEOF
"$BC" validate "$W/bad-study.json" > "$W/bad.out" 2>&1
[ $? -eq 3 ] || fail "a video scene with a background: not exit 3: $(cat "$W/bad.out")"
grep -q "/scene/background.*is not read with a video scene" "$W/bad.out" || fail "video + background: $(cat "$W/bad.out")"
sed 's|"track": "track"|"track": "no-such"|' "$W/video-study.json" > "$W/notrack.json"
"$BC" validate "$W/notrack.json" > "$W/notrack.out" 2>&1
[ $? -eq 3 ] && grep -q "/scene/track.*no such file.*no-such/track.csv" "$W/notrack.out" ||
  fail "a missing track folder: $(cat "$W/notrack.out")"
echo "video study: validate, preview and a simulated run accept it; a background beside it and a missing track folder are named"

# Names and values: one line, exit 2 (usage) or 3 (a file).
expect() {  # expect CODE PATTERN ARGS...
  local want=$1 pattern=$2
  shift 2
  "$BC" ar "$@" > "$W/e.out" 2> "$W/e.err"
  local got=$?
  [ $got -eq "$want" ] || fail "ar $*: exit $got, expected $want: $(cat "$W/e.err")"
  [ "$(wc -l < "$W/e.err")" -eq 1 ] || fail "ar $*: not one line: $(cat "$W/e.err")"
  grep -q -- "$pattern" "$W/e.err" || fail "ar $*: expected '$pattern': $(cat "$W/e.err")"
}
A=("$W/take/take.avi" --track "$W/track" --out "$W/e.avi")
expect 2 "did you mean fitted" "${A[@]}" --ball 1,2 --blur fited
expect 2 "no objects" "${A[@]}"
expect 2 "\--ball '1,x': expected X,Y\[,RADIUS\]" "${A[@]}" --ball 1,x
expect 2 "\--out .*must end in .avi" "$W/take/take.avi" --track "$W/track" --out "$W/e.mp4" --ball 1,2
echo '{"objects": [{"kind": "ball", "x_mm": 1, "y_mm": 2, "radus_mm": 3}]}' > "$W/typo.json"
expect 3 "typo.json: /objects/0/radus_mm: unknown key for a ball (did you mean radius_mm?)" "${A[@]}" --objects "$W/typo.json"
echo '{"objects": [{"kind": "bal", "x_mm": 1, "y_mm": 2}]}' > "$W/kind.json"
expect 3 "/objects/0/kind: must be \"ball\" or \"card\", got \"bal\" (did you mean ball?)" "${A[@]}" --objects "$W/kind.json"
expect 3 "no-such/track.csv\|no-such: no such folder" "$W/take/take.avi" --track "$W/no-such" --out "$W/e.avi" --ball 1,2
mkdir -p "$W/badtrack" && cp "$W/track/"* "$W/badtrack/" && sed -i '3s/^\([^,]*,[^,]*\),[a-z]*,/\1,trackd,/' "$W/badtrack/track.csv"
expect 3 "track.csv: line 3, status: must be found, tracked or lost, got 'trackd' (did you mean tracked?)" \
  "$W/take/take.avi" --track "$W/badtrack" --out "$W/e.avi" --ball 1,2
echo "ok: ar_test"
