#!/usr/bin/env bash
# The main job: set up, make a ground-truth scene (the thesis's set-up), calibrate it, render stimuli from it, run
# the thesis's test 1 and test 2 with simulated observers into an SQLite record, export the tables and write the
# report. Everything lands in results/demo/.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
BC=build/src/cli/blurcue
OUT=results/demo
mkdir -p "$OUT"
$BC synth-scene --out "$OUT/scene" --seed 7 --noise 0.004
$BC calibrate "$OUT/scene/scene.png" --camera "$OUT/scene/camera.json" --truth "$OUT/scene/truth.json" \
    --out "$OUT/calib.json"
# Stimuli from that calibration: one ball at edge 9 with the estimated blur, and the moving-ball pattern 3 of the
# thesis's Table 5.1 (estimated | none at 3 cm/s) as a video with its per-frame log.
$BC render --calib "$OUT/calib.json" --background "$OUT/scene/scene.png" --object ball --at-edge 9 \
    --blur estimated --out "$OUT/ball-edge9-estimated.png"
$BC animate --calib "$OUT/calib.json" --background "$OUT/scene/scene.png" --left estimated --right none \
    --speed-cm-s 3 --fps 30 --video "$OUT/pattern3.avi" --log "$OUT/pattern3-frames.csv"
# The studies: the shipped protocols (they point at this scene), checked by eye first, then run by simulated
# observers - 6 participants of test 1 and 4 of test 2, each with their own recorded seed - into one record.
# A fresh record each time: a demo run twice must not meet its own earlier sessions.
$BC preview protocols/test1-static-grids.json --out "$OUT/preview-test1.png"
rm -f "$OUT/study.sqlite" "$OUT/study.sqlite-wal" "$OUT/study.sqlite-shm"
for i in 1 2 3 4 5 6; do
  $BC run protocols/test1-static-grids.json --participant "P$i" --db "$OUT/study.sqlite" --observer sim
done
for i in 1 2 3 4; do
  $BC run protocols/test2-moving-balls.json --participant "P$i" --db "$OUT/study.sqlite" --observer sim
done
$BC report --db "$OUT/study.sqlite" --out "$OUT/report"
echo "demo: results in $OUT/ (calib.json, ball-edge9-estimated.png, pattern3.avi, study.sqlite, report/index.html)"
