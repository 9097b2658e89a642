#!/usr/bin/env bash
# An output replaces only what its own command wrote: every command that writes, pointed by an adversary at what an
# experimenter owns - a protocol where a log, a calib.json, a CSV or an image goes; one's own face.png, real photos,
# frames, calib-NNNN.json, plan.csv or trials.csv in a folder it writes into - is refused before any work, exit 3,
# one line naming the option and the path, and every file there is byte-identical afterwards (sha256 of the whole
# folder). Then what each command wrote itself is replaced on a rerun. Usage: outputs_own_test.sh BLURCUE BUILD_DIR
# (BUILD_DIR/cli-test holds the CLI tests' scene, calib.json and protocols/).
set -euo pipefail
BC=$1 T=$2/cli-test W=$2/outputs-own L=$2/outputs-own-logs
rm -rf "$W" "$L" && mkdir -p "$W" "$L"
source "$(dirname "$0")/lib.sh"
cd "$W"

P1=$T/protocols/test1-static-grids.json
cp "$P1" protocol.json
cp "$T/scene/scene.png" photo.png
cp "$T/calib.json" their-calib.json
$BC synth-take --out take --frames 2 --supersample 1 --quiet
$BC run "$P1" --participant p1 --db study.sqlite --observer sim --stop-after 1 > /dev/null 2>&1
mkdir own-stimuli && cp photo.png own-stimuli/face.png
mkdir real-photos && cp photo.png real-photos/face-1m.png
mkdir own-frames && cp photo.png own-frames/frame-00000.png
mkdir own-shots && cp photo.png own-shots/trial-0001.png
mkdir own-calibs && cp "$T/calib.json" own-calibs/calib-0000.json
mkdir own-plan && echo "n,power" > own-plan/plan.csv
mkdir own-tables && echo "participant,answer" > own-tables/trials.csv
echo "not a video" > notes.avi
# Every file's bytes; SQLite's -shm and an empty -wal (a refused run opened the record and wrote nothing) aside.
snapshot() { find . -type f ! -name '*-shm' ! \( -name '*-wal' -size 0 \) -print0 | sort -z | xargs -0 sha256sum; }
before=$(snapshot)

cases=0
EXPECT_TIMEOUT=60  # expect: tests/lib.sh
ANIM=(animate --calib "$T/calib.json" --background "$T/scene/scene.png" --from-edge 1 --to-edge 2 --speed-cm-s 100)
# Files of another kind at a file output (each was replaced, exit 0).
expect 3 "--log protocol.json: exists and is not a log animate wrote (it begins \"{\")" "${ANIM[@]}" --log protocol.json --video a.avi
expect 3 "--video notes.avi: exists and is not a video (an AVI) (it begins \"not a video\")" "${ANIM[@]}" --video notes.avi
expect 3 "--out protocol.json: exists and is not a calib.json calibrate wrote" calibrate "$T/scene/scene.png" --camera "$T/scene/camera.json" --out protocol.json
expect 3 "--out protocol.json: exists and is not a camera.json" camera "$T/scene/scene.png" --focal-length-mm 21 --f-number 5.6 --sensor-mm 23.4 15.6 --out protocol.json
# A protocol and a calib.json both name a focal length: the camera.json reader tells them apart.
expect 3 "--out their-calib.json: exists and is not a camera.json" camera "$T/scene/scene.png" --focal-length-mm 21 --f-number 5.6 --sensor-mm 23.4 15.6 --out their-calib.json
expect 3 "--out protocol.json: exists and is not a CSV bench plan wrote" bench plan --quick --out protocol.json
expect 3 "--out protocol.json: exists and is not a CSV bench procedures wrote" bench procedures --quick --out protocol.json
cp protocol.json sheet.png
before=$(snapshot)
expect 3 "--out sheet.png: exists and is not an image of the kind its name says" preview "$P1" --out sheet.png
expect 3 "--out sheet.png: exists and is not an image of the kind its name says" blur photo.png --radius-px 2 --out sheet.png
expect 3 "--out sheet.png: exists and is not an image of the kind its name says" render --calib "$T/calib.json" --background "$T/scene/scene.png" --out sheet.png
# One's own files in a folder an output writes into, or replaces whole by the names of its files (each was
# replaced, exit 0).
expect 3 "--out own-stimuli: holds face.png, which make-stimuli did not write" make-stimuli --out own-stimuli
expect 3 "--out real-photos: holds face-1m.png, which synth-pictures did not write" synth-pictures --camera "$T/scene/camera.json" --distances-m 1 2 --out real-photos
expect 3 "--frames own-frames: holds no animate-frames.txt: not frames animate drew" "${ANIM[@]}" --frames own-frames
expect 3 "--out own-calibs: holds no track.csv: not a take track wrote" track take/take.avi --camera take/camera.json --out own-calibs
expect 3 "--out own-plan: holds no plan.json: not a plan blurcue plan wrote" plan "$P1" --out own-plan --no-chart
expect 3 "--out own-tables: holds no codebook.csv: not tables export wrote" export --db study.sqlite --out own-tables
expect 3 "own-shots: --capture: holds 'trial-0001.png' and no trial-NNNN.json: images, not a capture" run "$P1" --participant p2 --db study.sqlite --observer sim --stop-after 1 --capture own-shots
[ "$(snapshot)" = "$before" ] || fail "a refused command changed a file: $(diff <(echo "$before") <(snapshot) | head -5)"
left=$(ls -A | grep -Ev '^(protocol\.json|photo\.png|their-calib\.json|take|study\.sqlite(-wal|-shm)?|own-.*|real-photos|notes\.avi|sheet\.png)$' || true)
[ -z "$left" ] || fail "a refused command left: $left"

# Small mends, one line each: a card raised 1 m (behind the camera) is blamed on the field that raised it (it was
# /sides/right, the blur source); a missing file is one line with its hint (the hint was a second line); a repeated
# distance is refused (it said "wrote 1 photos"); a display width no display has is refused (it wrote a 1 x 1 image).
$PY - "$P1" "$T" <<'PYEOF'
import json, sys
p = json.load(open(sys.argv[1]))
for k in ("background", "board_free", "calib"):
    p["scene"][k] = sys.argv[2] + "/" + p["scene"][k].replace("../", "", 1)
high = json.loads(json.dumps(p)); high["content"]["height_mm"] = 1000
json.dump(high, open("high.json", "w"), indent=1)
missing = json.loads(json.dumps(p)); missing["scene"]["background"] = "no-such-photo.png"
json.dump(missing, open("missing.json", "w"), indent=1)
PYEOF
expect 3 "high.json: /content/height_mm: is 1000 mm: places the grid at u = " validate high.json
expect 3 "missing.json: /scene/background: no such file" validate missing.json
grep -qF "('blurcue init DIR --from EXAMPLE' makes" "$L/err.log" || fail "the missing file's hint is not on its line"
expect 2 "--distances-m 1 is given twice" synth-pictures --camera "$T/scene/camera.json" --distances-m 1 1 --out twice
expect 2 "distances 1 and 1.0000001 m both name face-1m.png" synth-pictures --camera "$T/scene/camera.json" --distances-m 1 1.0000001 --out twice
expect 2 "--display-width: must be 0 (the photo's own width) or a display's width, 320 to 16384 px" render --calib "$T/calib.json" --background "$T/scene/scene.png" --display-width 1 --out tiny.png
[ ! -e twice ] && [ ! -e tiny.png ] || fail "a refused synth-pictures or render wrote"
$BC synth-pictures --camera "$T/scene/camera.json" --distances-m 1 --out one > "$L/out.log" 2>&1 || fail "synth-pictures 1 m"
grep -q "wrote 1 photo (" "$L/out.log" || fail "one photo is not said as one: $(cat "$L/out.log")"

# What a command wrote itself it replaces: a second run over the first, for each kind.
for i in 1 2; do
  $BC make-stimuli --out stimuli > /dev/null || fail "make-stimuli over its own folder (run $i)"
  $BC synth-pictures --camera "$T/scene/camera.json" --distances-m 1 --out pictures > /dev/null || fail "synth-pictures (run $i)"
  $BC "${ANIM[@]}" --log anim.csv --frames frames --video anim.avi > /dev/null 2>&1 || fail "animate over its own outputs (run $i)"
  $BC calibrate "$T/scene/scene.png" --camera "$T/scene/camera.json" --out calib.json > /dev/null 2>&1 || fail "calibrate (run $i)"
  $BC bench procedures --quick --out procedures.csv > /dev/null 2>&1 || fail "bench procedures (run $i)"
  $BC blur photo.png --radius-px 2 --out blurred.png > /dev/null 2>&1 || fail "blur (run $i)"
  $BC track take/take.avi --camera take/camera.json --out track --quiet || fail "track (run $i)"
  $BC export --db study.sqlite --out tables > /dev/null 2>&1 || fail "export (run $i)"
done
[ -f frames/animate-frames.txt ] && [ -f frames/frame-00000.png ] || fail "animate --frames wrote no marker or frames"
grep -q "face.png" stimuli/make-stimuli.txt || fail "make-stimuli.txt does not list face.png"
# One of its own files changed by hand is someone's now: refused, left as it is.
cp photo.png stimuli/grid.png
expect 3 "--out stimuli: holds grid.png, which make-stimuli did not write (changed since make-stimuli wrote it" make-stimuli --out stimuli
cmp -s photo.png stimuli/grid.png || fail "make-stimuli replaced a grid.png changed by hand"
echo "ok: $cases refusals, each one line and nothing changed; every command's own outputs replaced on a rerun"
