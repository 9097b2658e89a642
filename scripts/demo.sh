#!/usr/bin/env bash
# The main job: set up, make a ground-truth scene (the thesis's set-up), calibrate it, synthesise and track a short
# moving-camera take of it, render stimuli from it, run the thesis's test 1 and test 2 (and the studies beyond it, one
# on the take) with simulated observers into an SQLite record, export the tables and write the report. Everything
# lands in results/demo/.
set -euo pipefail
cd "$(dirname "$0")/.."
[ -n "${BLURCUE_BUILT:-}" ] || scripts/setup.sh  # set by ctest's `demo` test (scripts/test.sh built it)
# BLURCUE_BIN and BLURCUE_RESULTS (ctest's demo test sets both: its own build's binary, a results folder inside that
# build) let two builds run the demo at once; by hand it is build/src/cli/blurcue into results/.
BC=${BLURCUE_BIN:-build/src/cli/blurcue}
RESULTS=${BLURCUE_RESULTS:-results}
OUT=$RESULTS/demo
PROTOCOLS=protocols
mkdir -p "$OUT" "$RESULTS/bench"
if [ "$RESULTS" != results ]; then
  # The shipped protocols point at ../results/demo/ and ../stimuli/: copies that point at this results folder.
  PROTOCOLS=$RESULTS/protocols
  mkdir -p "$PROTOCOLS"
  for p in protocols/*.json; do
    sed -e 's|"\.\./results/demo/|"../demo/|g' -e "s|\"\.\./stimuli/|\"$PWD/stimuli/|g" "$p" > "$PROTOCOLS/$(basename "$p")"
  done
fi
$BC synth-scene --out "$OUT/scene" --seed 7 --noise 0.004
$BC calibrate "$OUT/scene/scene.png" --camera "$OUT/scene/camera.json" --truth "$OUT/scene/truth.json" \
    --out "$OUT/calib.json"
# A moving camera (the thesis's future work, 6.2): a short take of the same set-up with known per-frame truth - the lens
# focused at 340 mm, inside the board, the camera moving 40 mm closer and 30 mm sideways over 5 frames at 30 fps -
# tracked frame by frame: the scene of the example video study (protocols/video-ball-depth.json).
rm -rf "$OUT/take" "$OUT/track"  # a fresh take each time: no frame of an earlier, longer one left behind
$BC synth-take --out "$OUT/take" --frames 5 --supersample 2 --noise 0.004 --seed 7 --from-u-mm 320 --to-u-mm 280 \
    --focus-mm 340 --from-lateral-mm -15 --to-lateral-mm 15 --quiet
$BC track "$OUT/take/take.avi" --camera "$OUT/take/camera.json" --out "$OUT/track" --quiet
# Stimuli from that calibration: one ball at edge 9 with the estimated blur, and the moving-ball pattern 3 of the
# thesis's Table 5.1 (estimated | none at 3 cm/s) as a video with its per-frame log.
$BC render --calib "$OUT/calib.json" --background "$OUT/scene/scene.png" --object ball --at-edge 9 \
    --blur estimated --out "$OUT/ball-edge9-estimated.png"
$BC animate --calib "$OUT/calib.json" --background "$OUT/scene/scene.png" --left estimated --right none \
    --speed-cm-s 3 --fps 30 --video "$OUT/pattern3.avi" --log "$OUT/pattern3-frames.csv"
# The studies: the shipped protocols (they point at this scene, and the depth matching at thin-lens photos of its
# picture at each distance, taken with the camera and focus the protocol names), checked by eye first, then run by simulated
# observers, each participant with their own recorded seed, into one record: 6 through test 1, 4 through test 2,
# 3 through test 3 and 3 through the pre-research depth matching (headless, on a simulated clock). A fresh record each time: a demo run twice must
# not meet its own earlier sessions.
$BC synth-pictures --protocol "$PROTOCOLS/pre-research-depth-matching.json" --out "$OUT/pictures"
$BC preview "$PROTOCOLS/test1-static-grids.json" --out "$OUT/preview-test1.png"
rm -f "$OUT/study.sqlite" "$OUT/study.sqlite-wal" "$OUT/study.sqlite-shm"
run() {  # PROTOCOL PARTICIPANTS...
  local protocol=$1
  shift
  for id in "$@"; do $BC run "$PROTOCOLS/$protocol.json" --participant "$id" --db "$OUT/study.sqlite" --observer sim; done
}
run test1-static-grids P1 P2 P3 P4 P5 P6
run test2-moving-balls P1 P2 P3 P4
run test3-no-board P1 P2 P3
run pre-research-depth-matching P1 P2 P3
# Beyond the thesis: adaptive procedures (QUEST+ on the blur difference a person notices, a staircase on a moving
# ball's relative blur), answered by the simulated observer.
run quest-blur-difference P1 P2
run staircase-ball-gain P1
# Other layouts and tasks: an odd one out of three intervals, one ball answered yes/no and rated, a 2IFC; the report
# analyses each from what its trials declare.
run odd-one-out-grids P1 P2
run yes-no-ball P1 P2
run 2ifc-grids P1 P2
# A study on the take: two balls drawn in its frames, each frame at its own pose and blur (docs/video-studies.md).
run video-ball-depth P1 P2 P3
# One more test-1 session in a real window on the real clock (under Xvfb when there is no screen), answered by the
# simulated observer: its frame timing is the report's display-timing chart.
WINDOW=()
[ -n "${DISPLAY:-}" ] || WINDOW=(xvfb-run -a -s "-screen 0 1280x1024x24")
"${WINDOW[@]}" $BC run "$PROTOCOLS/test1-static-grids.json" --participant W1 --db "$OUT/study.sqlite" --observer sim --window
# Speed against accuracy of every measurement and blur method (quick sweeps), for the report's charts.
$BC bench measure --quick --out "$RESULTS/bench/measure.csv"
$BC bench render --quick --out "$RESULTS/bench/render.csv"
$BC bench record --trials 100 --folder "$RESULTS/bench"   # what a power-loss-safe commit costs per answer
$BC bench procedures --out "$RESULTS/bench/procedures.csv"   # which adaptive procedure to choose (200 runs each, ~15 s)
$BC report --db "$OUT/study.sqlite" --out "$OUT/report" --bench "$RESULTS/bench"
echo "demo: results in $OUT/ (calib.json, ball-edge9-estimated.png, pattern3.avi, take/, track/, study.sqlite, report/index.html)"
