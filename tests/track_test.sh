#!/bin/bash
# blurcue synth-take and blurcue track end to end: a small ground-truth take tracked from its image sequence and its
# video; a truncated video and a sequence with a missing frame end with exit 3, one line naming the file and the
# frame, and keep what was tracked before it; a bad pattern and an unknown option are usage errors.
# Usage: track_test.sh BLURCUE WORKDIR
set -u
BC=$1
W=$2
. "$(dirname "$0")/lib.sh"
rm -rf "$W" && mkdir -p "$W"

"$BC" synth-take --out "$W/take" --frames 6 --supersample 2 --noise 0.004 --quiet || fail "synth-take failed"
for i in 0 1 2 3 4 5; do
  [ -f "$W/take/frame-000$i.png" ] && [ -f "$W/take/truth-000$i.json" ] || fail "synth-take: frame $i missing"
done
[ -f "$W/take/camera.json" ] && [ -f "$W/take/take.json" ] || fail "synth-take: camera.json / take.json missing"
# Its camera says how the frames were exposed: each at one instant (0 ms), what `ar` defaults to.
grep -q '"exposure_ms": 0' "$W/take/camera.json" || fail "synth-take: camera.json lacks exposure_ms 0"
# A path along which the board leaves the view: refused before any frame is written (exit 2 naming the options,
# one line).
"$BC" synth-take --out "$W/take-out-of-view" --frames 6 --supersample 2 --to-u-mm 40 --quiet 2> "$W/out-of-view.err"
code=$?
[ $code = 2 ] && [ "$(wc -l < "$W/out-of-view.err")" = 1 ] && grep -q "^blurcue: --from-u-mm/--to-u-mm: board not fully in view" "$W/out-of-view.err" \
  || fail "a path out of view: exit $code $(cat "$W/out-of-view.err")"
[ ! -e "$W/take-out-of-view/frame-0000.png" ] || fail "a path out of view: frame 0 written before the refusal"

# The sequence: every frame with a pose; track.csv has a header and one row per frame.
"$BC" track "$W/take/frame-%04d.png" --camera "$W/take/camera.json" --out "$W/track" > "$W/track.out" 2> "$W/track.err" ||
  fail "track of the sequence failed: $(cat "$W/track.err")"
grep -q "6 frames: .* 0 lost" "$W/track.out" || fail "track: frames lost: $(cat "$W/track.out")"
[ "$(wc -l < "$W/track/track.csv")" -eq 7 ] || fail "track.csv: not 6 rows: $(cat "$W/track/track.csv")"
head -1 "$W/track/track.csv" | grep -q "^frame,time_s,status,reprojection_error_px," || fail "track.csv header"
for i in 0 1 2 3 4 5; do [ -f "$W/track/calib-000$i.json" ] || fail "calib-000$i.json missing"; done
# A tracked frame's calibration is calibrate's format, and `calibrate --truth`'s comparison reads the same truth file.
$PY - "$W" <<'PYEOF' || fail "calib-0003.json against truth-0003.json"
import json, sys
w = sys.argv[1]
c = json.load(open(f"{w}/track/calib-0003.json"))
t = json.load(open(f"{w}/take/truth-0003.json"))
assert c["format"] == "blurcue-calib" and c["frame"] == 3, c.get("format")
assert len(c["edges"]) == 11 and all(len(e["sections"]) == 7 for e in c["edges"])
true = {(s["edge"], s["section"]): s for s in t["sections"]}
for e in c["edges"]:
    for s in e["sections"]:
        tu = true[(e["index"], s["index"])]["u_mm"]
        assert abs(s["u_mm"] - tu) / tu < 1e-3, (e["index"], s["index"], s["u_mm"], tu)
print("calib-0003.json: depths within 0.1 % of truth-0003.json")
PYEOF

# The take's lens model (focus 450 mm inside the board, floor std 0.35 px) predicts every section of every frame:
# r_fitted_px against the truth files, median <= 2 %, p90 <= 5 % a frame (with this noise the measured r_px alone
# is 3-5 % / 5-12 %; the one model of the take averages it out).
$PY - "$W" <<'PYEOF' || fail "r_fitted_px against the truth"
import json, sys
w = sys.argv[1]
for i in range(6):
    c = json.load(open(f"{w}/track/calib-{i:04d}.json"))
    t = json.load(open(f"{w}/take/truth-{i:04d}.json"))
    true = {(s["edge"], s["section"]): s["r_px"] for s in t["sections"]}
    rel = sorted(abs(s["r_fitted_px"] - true[(e["index"], s["index"])]) / true[(e["index"], s["index"])]
                 for e in c["edges"] for s in e["sections"])
    median, p90 = rel[len(rel) // 2], rel[min(len(rel) - 1, len(rel) * 9 // 10)]
    assert median <= 0.02 and p90 <= 0.05, (i, median, p90, c["model"])
m = c["model"]
assert m["kind"] == "thin_lens+floor" and abs(m["focus_mm"] - 450) < 0.02 * 450, m
print(f"r_fitted_px within 2 % median / 5 % p90 on every frame; take model focus {m['focus_mm']:.1f} mm")
PYEOF

# The video synth-take writes beside the frames (a take without it fails: its checks would silently not run).
[ -f "$W/take/take.avi" ] || fail "synth-take wrote no take.avi: the video checks cannot run"
"$BC" track "$W/take/take.avi" --camera "$W/take/camera.json" --out "$W/track-video" > "$W/video.out" 2>&1 ||
  fail "track of the video failed: $(cat "$W/video.out")"
grep -q "6 frames: .* 0 lost" "$W/video.out" || fail "track video: $(cat "$W/video.out")"

# Truncated: the first 55 % of the bytes. Exit 3, one line naming the file, and the frames before it written.
size=$(stat -c %s "$W/take/take.avi")
head -c $((size * 55 / 100)) "$W/take/take.avi" > "$W/truncated.avi"
"$BC" track "$W/truncated.avi" --camera "$W/take/camera.json" --out "$W/track-truncated" --quiet \
  > "$W/trunc.out" 2> "$W/trunc.err"
code=$?
[ $code -eq 3 ] || fail "truncated video: exit $code, expected 3: $(cat "$W/trunc.err")"
[ "$(wc -l < "$W/trunc.err")" -eq 1 ] || fail "truncated video: not one line on stderr: $(cat "$W/trunc.err")"
grep -q "truncated.avi: damaged or truncated: frame [0-9]" "$W/trunc.err" || fail "truncated video: $(cat "$W/trunc.err")"
rows=$(($(wc -l < "$W/track-truncated/track.csv") - 1))
[ $rows -ge 1 ] && [ $rows -lt 6 ] || fail "truncated video: $rows rows kept"
[ -f "$W/track-truncated/calib-0000.json" ] || fail "truncated video: calib-0000.json not kept"
echo "truncated video: exit 3, $rows frames kept: $(cat "$W/trunc.err")"

# A file that is not a video: one line, exit 3 (no backend's warnings before it).
echo "not a video" > "$W/garbage.avi"
"$BC" track "$W/garbage.avi" --camera "$W/take/camera.json" --out "$W/x" 2> "$W/garbage.err"
code=$?
[ $code -eq 3 ] && [ "$(wc -l < "$W/garbage.err")" -eq 1 ] && grep -q "garbage.avi: OpenCV's videoio (FFmpeg) cannot open it" "$W/garbage.err" ||
  fail "not a video: exit $code: $(cat "$W/garbage.err")"

# A missing frame inside a sequence.
mkdir -p "$W/gap" && cp "$W/take/frame-000"[0-5].png "$W/gap/" && rm "$W/gap/frame-0003.png"
"$BC" track "$W/gap/frame-%04d.png" --camera "$W/take/camera.json" --out "$W/track-gap" --quiet > /dev/null 2> "$W/gap.err"
code=$?
[ $code -eq 3 ] || fail "missing frame: exit $code, expected 3: $(cat "$W/gap.err")"
[ "$(wc -l < "$W/gap.err")" -eq 1 ] || fail "missing frame: not one line on stderr: $(cat "$W/gap.err")"
grep -q "frame-0003.png: frame 3 is missing but .*frame-0004.png exists" "$W/gap.err" || fail "missing frame: $(cat "$W/gap.err")"
[ "$(wc -l < "$W/track-gap/track.csv")" -eq 4 ] || fail "missing frame: the 3 frames before it not kept"
[ -f "$W/track-gap/calib-0002.json" ] || fail "missing frame: calib-0002.json not kept"

# A damaged frame file inside a sequence.
mkdir -p "$W/bad" && cp "$W/take/frame-000"[0-2].png "$W/bad/" && echo "not a png" > "$W/bad/frame-0001.png"
"$BC" track "$W/bad/frame-%04d.png" --camera "$W/take/camera.json" --out "$W/track-bad" --quiet > /dev/null 2> "$W/bad.err"
code=$?
[ $code -eq 3 ] && [ "$(wc -l < "$W/bad.err")" -eq 1 ] && grep -q "frame-0001.png" "$W/bad.err" ||
  fail "damaged frame: exit $code: $(cat "$W/bad.err")"
[ "$(wc -l < "$W/track-bad/track.csv")" -eq 2 ] || fail "damaged frame: frame 0 not kept"

# Usage errors: a pattern without one integer conversion, an unknown option.
"$BC" track "$W/take/frame-%s.png" --camera "$W/take/camera.json" --out "$W/x" 2> "$W/usage.err"
code=$?
[ $code -eq 2 ] && grep -q "must hold exactly one frame-number conversion" "$W/usage.err" ||
  fail "bad pattern: exit $code: $(cat "$W/usage.err")"
"$BC" track "$W/take/frame-%04d.png" --camera "$W/take/camera.json" --out "$W/x" --max-track-eror-px 1 2> "$W/usage.err"
code=$?
[ $code -eq 2 ] || fail "unknown option: exit $code: $(cat "$W/usage.err")"
"$BC" track "$W/nothing/frame-%04d.png" --camera "$W/take/camera.json" --out "$W/x" 2> "$W/usage.err"
code=$?
[ $code -eq 3 ] && grep -q "no first frame" "$W/usage.err" || fail "no frames: exit $code: $(cat "$W/usage.err")"
echo "ok: track"
