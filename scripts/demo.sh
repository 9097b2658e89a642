#!/usr/bin/env bash
# The main job: set up, make a ground-truth scene (the thesis's set-up), calibrate it, and compare the measured,
# estimated and true blur of every edge. Everything lands in results/demo/.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
BC=build/src/cli/blurcue
OUT=results/demo
mkdir -p "$OUT"
$BC synth-scene --out "$OUT/scene" --seed 7 --noise 0.004
$BC calibrate "$OUT/scene/scene.png" --camera "$OUT/scene/camera.json" --truth "$OUT/scene/truth.json" \
    --out "$OUT/calib.json"
