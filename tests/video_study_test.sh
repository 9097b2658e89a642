#!/usr/bin/env bash
# The shipped video study (protocols/video-ball-depth.json) on a small take of its own: the take (case take, the
# fixture: synth-take + track into DIR/take and DIR/track, where the session tests' copy of the protocol points),
# validate, a headless simulated session killed -9 and resumed, its report, and bad video scenes.
# usage: video_study_test.sh CASE BLURCUE DIR   (DIR: the CLI tests' folder, holding protocols/ from session_protocols)
set -uo pipefail
BC=$2 DIR=$3
CASE=video_$1  # session_lib.sh makes DIR/session-$CASE afresh: a folder of this script's own
source "$(dirname "$0")/session_lib.sh"
PROTOCOL=$P/video-ball-depth.json
# The design worked by hand: 3 edges x 3 patterns x 2 (swap_copies) = 18 main trials, and 2 practice trials drawn
# from them.
MAIN=18 PRACTICE=2

case $1 in
take)
  # 4 frames of the demo's set-up (focus inside the board, the camera moving closer and sideways), 2x supersampled.
  rm -rf "$DIR/take" "$DIR/track"
  $BC synth-take --out "$DIR/take" --frames 4 --supersample 2 --noise 0.004 --seed 7 --from-u-mm 320 --to-u-mm 280 \
    --focus-mm 340 --from-lateral-mm -15 --to-lateral-mm 15 --quiet || fail "synth-take"
  $BC track "$DIR/take/take.avi" --camera "$DIR/take/camera.json" --out "$DIR/track" --quiet || fail "track"
  [ "$(($(wc -l < "$DIR/track/track.csv") - 1))" = 4 ] || fail "track.csv: $(cat "$DIR/track/track.csv")"
  echo "ok: a 4-frame take in $DIR/take, tracked into $DIR/track" ;;
validate)
  $BC validate "$PROTOCOL" > "$W/out" 2>&1 || fail "validate: $(cat "$W/out")"
  grep -q "^ok: $((MAIN + PRACTICE)) trials for participant P1" "$W/out" || fail "validate: $(cat "$W/out")"
  grep -q "practice $PRACTICE, main $MAIN (forced_choice, swap_copies)" "$W/out" || fail "validate: $(cat "$W/out")"
  $BC preview "$PROTOCOL" --out "$W/sheet.png" > "$W/preview" 2>&1 || fail "preview: $(cat "$W/preview")"
  grep -q "$MAIN distinct stimuli of $((MAIN + PRACTICE)) trials" "$W/preview" || fail "preview: $(cat "$W/preview")"
  [ -s "$W/sheet.png" ] || fail "preview wrote no sheet"
  # Without content.exposure_ms a ball on video takes the take's camera's exposure (synth-take's camera.json: 0), or
  # half a frame where the camera states none (30 fps: 16.67 ms), and validate says which; the trials record it.
  rm -rf "$W/track-unknown" && cp -r "$DIR/track" "$W/track-unknown"
  $PY - "$PROTOCOL" "$W" "$W/track-unknown" <<'PYEOF' || fail "could not write the protocols without exposure"
import glob, json, os, sys
p = json.load(open(sys.argv[1]))
del p["content"]["exposure_ms"]
d = os.path.dirname(os.path.abspath(sys.argv[1]))
p["scene"] = {k: os.path.normpath(os.path.join(d, v)) for k, v in p["scene"].items()}
json.dump(p, open(os.path.join(sys.argv[2], "no-exposure.json"), "w"), indent=1)
for path in glob.glob(sys.argv[3] + "/calib-*.json"):
    calib = json.load(open(path))
    del calib["camera"]["exposure_ms"]
    json.dump(calib, open(path, "w"))
p["scene"]["track"] = sys.argv[3]
json.dump(p, open(os.path.join(sys.argv[2], "unknown-exposure.json"), "w"), indent=1)
PYEOF
  $BC validate "$W/no-exposure.json" > "$W/no-exposure.out" 2>&1 || fail "validate: $(cat "$W/no-exposure.out")"
  grep -q "^  take: 4 frames at 30 fps; exposure 0 ms (the take's camera.json exposure_ms)" "$W/no-exposure.out" ||
    fail "the camera's exposure: $(cat "$W/no-exposure.out")"
  $BC validate "$W/unknown-exposure.json" > "$W/unknown.out" 2>&1 || fail "validate: $(cat "$W/unknown.out")"
  grep -q "^  take: 4 frames at 30 fps; exposure 16.667 ms (half a frame: the take's camera states no exposure_ms" \
    "$W/unknown.out" || fail "half a frame: $(cat "$W/unknown.out")"
  $BC run "$W/unknown-exposure.json" --participant E1 --db "$W/e.sqlite" --observer sim > /dev/null 2>&1 || fail "run"
  $BC export --db "$W/e.sqlite" --out "$W/e-tables" > /dev/null || fail "export"
  [ "$($PY -c 'import csv, sys; print(sorted({round(float(r["exposure_ms"]), 3) for r in csv.DictReader(open(sys.argv[1]))}))' \
      "$W/e-tables/trials.csv")" = "[16.667]" ] || fail "the trials' exposure is not half a frame"
  echo "ok: video-ball-depth validates ($((MAIN + PRACTICE)) trials) and previews; without an exposure it takes the camera's, or half a frame" ;;
kill9)
  # A headless simulated session killed -9 mid-way, then resumed: every planned trial answered exactly once. A
  # simulated session answers a trial in milliseconds, so it runs in slices of ~2 ms between SIGSTOPs and the record
  # is read while it is stopped: it is killed after its first answers, far from its last.
  $BC run "$PROTOCOL" --participant K1 --db "$W/s.sqlite" --observer sim > "$W/out" 2>&1 &
  pid=$!
  kill -STOP $pid
  for _ in $(seq 1 3000); do
    n=$(sql "$W/s.sqlite" "SELECT count(*) FROM responses" 2>/dev/null || echo 0)
    [ "${n:-0}" -ge 1 ] && break
    kill -CONT $pid; sleep 0.002; kill -STOP $pid 2>/dev/null || break
  done
  kill -9 $pid; wait $pid 2>/dev/null
  answered=$(sql "$W/s.sqlite" "SELECT count(*) FROM responses")
  [ "$answered" -ge 1 ] && [ "$answered" -lt $((MAIN + PRACTICE)) ] ||
    fail "killed after $answered answers, expected mid-session: $(tail -2 "$W/out")"
  [ "$(sql "$W/s.sqlite" "SELECT status FROM sessions")" = running ] || fail "killed: the session is not resumable"
  integrity "$W/s.sqlite"
  $BC run "$PROTOCOL" --participant K1 --db "$W/s.sqlite" --observer sim --resume > "$W/resume" 2>&1 ||
    fail "resume: $(tail -2 "$W/resume")"
  grep -q "$((MAIN + PRACTICE)) of $((MAIN + PRACTICE)) trials answered" "$W/resume" || fail "resume: $(tail -2 "$W/resume")"
  [ "$(sql "$W/s.sqlite" "SELECT count(*), status FROM sessions")" = "1|completed" ] || fail "not one completed session"
  # One trial row per planned trial, indices 0..19, each answered once.
  [ "$(sql "$W/s.sqlite" "SELECT count(*), count(DISTINCT trial_index), min(trial_index), max(trial_index) FROM trials")" \
    = "$((MAIN + PRACTICE))|$((MAIN + PRACTICE))|0|$((MAIN + PRACTICE - 1))" ] || fail "trials: $(sql "$W/s.sqlite" \
    "SELECT count(*), count(DISTINCT trial_index) FROM trials")"
  [ "$(sql "$W/s.sqlite" "SELECT count(*), count(DISTINCT trial_id) FROM responses")" = \
    "$((MAIN + PRACTICE))|$((MAIN + PRACTICE))" ] || fail "responses: not one per trial"
  # The main trials are the design's crossing, each once: 3 edges x 3 patterns x swapped 0/1.
  sql "$W/s.sqlite" "SELECT json_extract(factors, '$.edge'), json_extract(factors, '$.pattern.id'),
                      json_extract(factors, '$.swapped') FROM trials WHERE json_extract(factors, '$.practice') = 0" |
    sort > "$W/main"
  for e in 3 6 9; do for p in 1 2 3; do for s in 0 1; do echo "$e|$p|$s"; done; done; done | sort > "$W/planned"
  diff "$W/planned" "$W/main" > "$W/diff" || fail "main trials are not the design's crossing once each: $(cat "$W/diff")"
  # Each answered trial's frames once, from frame 0 without a gap, each showing a frame of the take while the stimulus
  # is (timing.stimulus_ms: none after it, on the answer screen): the frames of the trial the kill interrupted were
  # not recorded (they go with its answer), and the resumed trial's start at 0.
  [ "$(sql "$W/s.sqlite" "SELECT count(*) FROM (SELECT trial_id, count(*) AS n, max(frame_index) AS m FROM frames
        GROUP BY trial_id) WHERE n <> m + 1")" = 0 ] || fail "a trial's frames have a gap or a duplicate"
  [ "$(sql "$W/s.sqlite" "SELECT count(DISTINCT trial_id) FROM frames")" = $((MAIN + PRACTICE)) ] ||
    fail "frames: not every answered trial has its frames"
  stimulus_s=$($PY -c 'import json, sys; print(json.load(open(sys.argv[1]))["timing"]["stimulus_ms"] / 1000)' "$PROTOCOL")
  [ "$(sql "$W/s.sqlite" "SELECT count(*) FROM frames WHERE (take_frame IS NULL OR take_status IS NULL)
                          AND flip_time_s < $stimulus_s - 1e-6")" = 0 ] || fail "stimulus frames without their take frame"
  [ "$(sql "$W/s.sqlite" "SELECT count(*) FROM frames WHERE take_frame IS NOT NULL AND flip_time_s >= $stimulus_s")" = 0 ] ||
    fail "a take frame after the stimulus"
  integrity "$W/s.sqlite"
  echo "ok: killed -9 after $answered answers, resumed: $((MAIN + PRACTICE)) planned trials, each answered once" ;;
frames)
  # Frame by frame against the take's truth (tests/video_frames_check.py): the take frame each display frame shows,
  # each fitted ball's blur at its true depth (3 %), each ball's streak from the true poses (max(0.3 px, 5 %)) and the
  # captured centres at the true pose. Twice: the shipped protocol (no exposure: its take was rendered with an
  # instantaneous shutter), and a copy with content.exposure_ms 16.7 for the streaks.
  for exposure in 0 16.7; do
    $PY - "$PROTOCOL" "$W/exposed-$exposure.json" "$exposure" <<'PYEOF' || fail "could not write the protocol's copy"
import json, os, sys
p = json.load(open(sys.argv[1]))
p["content"]["exposure_ms"] = float(sys.argv[3])
d = os.path.dirname(os.path.abspath(sys.argv[1]))
p["scene"] = {k: os.path.normpath(os.path.join(d, v)) for k, v in p["scene"].items()}
json.dump(p, open(sys.argv[2], "w"), indent=1)
PYEOF
    $BC run "$W/exposed-$exposure.json" --participant F1 --db "$W/s-$exposure.sqlite" --observer sim \
        --capture "$W/capture-$exposure" > "$W/out" 2>&1 || fail "run: $(tail -2 "$W/out")"
    $BC export --db "$W/s-$exposure.sqlite" --out "$W/export-$exposure" > "$W/export.out" 2>&1 ||
      fail "export: $(cat "$W/export.out")"
    stimulus_s=$($PY -c 'import json, sys; v = json.load(open(sys.argv[1]))["timing"]["stimulus_ms"]; print(v / 1000 if isinstance(v, (int, float)) else "")' "$PROTOCOL")
    $PY "$(dirname "$0")/video_frames_check.py" "$DIR/take" "$W/export-$exposure" "$W/capture-$exposure" $exposure \
        $stimulus_s > "$W/check-$exposure" 2>&1 || fail "exposure $exposure ms: $(cat "$W/check-$exposure")"
  done
  echo "ok: every frame of simulated sessions on video against the take's truth: no exposure: $(cat "$W/check-0");" \
       "16.7 ms: $(cat "$W/check-16.7")" ;;
report)
  # Three simulated observers, then the report (from DIR, so the take's track folder is found as the protocols see it).
  for id in R1 R2 R3; do
    $BC run "$PROTOCOL" --participant $id --db "$W/s.sqlite" --observer sim > /dev/null 2>&1 || fail "run $id"
  done
  (cd "$DIR" && MPLCONFIGDIR=$W/mpl $BC report --db "$W/s.sqlite" --out "$W/report" --bench "$W/no-bench" --boot 20) \
    > "$W/out" 2> "$W/err" || fail "report exit $?: $(tail -3 "$W/err")"
  if grep -q "Traceback" "$W/err"; then fail "report: $(cat "$W/err")"; fi
  index=$W/report/index.html
  grep -q "study video-ball-depth" "$index" || fail "the report has no section for video-ball-depth"
  # Analysed as any forced choice: its conditions (edge x pattern), 3 participants.
  grep -q "video-ball-depth-simulated-conditions" "$index" || fail "no conditions table for video-ball-depth"
  grep -q "3 participants" "$index" || fail "the report does not count 3 participants"
  # Its scene is described as a video: the take as the protocol names it, its 4 frames at 30 fps (the fixture's, by
  # construction) and the protocol's exposure (none: the take was rendered with an instantaneous shutter).
  grep -q "scene: a tracked video: take ../take/take.avi, track folder ../track" "$index" ||
    fail "the report does not describe the scene as a video: $(grep -o 'scene: [^<]*' "$index")"
  grep -q "4 frames at 30 fps" "$index" || fail "the take's frames: $(grep -o 'scene: [^<]*' "$index")"
  grep -q "exposure 0 ms (no motion blur)" "$index" || fail "the exposure: $(grep -o 'scene: [^<]*' "$index")"
  echo "ok: the report analyses video-ball-depth and describes its scene: $(grep -o 'scene: [^<;]*' "$index")" ;;
procedure)
  # A staircase on the take (the blur gain one ball needs to look more blurred, at rest at edge 6; both sides fitted):
  # each trial's test side is (1 + level) x the other side (its own reference, at the same depth), the trial's radii
  # being the take's average over the frames it shows (worked here from trials.csv: the level, the test side and the
  # two radii), and the staircase moves.
  $PY - "$PROTOCOL" "$W/staircase.json" <<'PYEOF' || fail "could not write the staircase protocol"
import json, sys
p = json.load(open(sys.argv[1]))
p["name"] = "video-staircase"
for key in ("factors", "counterbalance", "practice", "repetitions"):
    p.pop(key, None)
p["responses"]["cant_tell"] = None
p["blocks"] = [{"name": "staircase", "factors": {"edge": [6], "pattern": [{"id": 1, "left": "fitted", "right": "fitted"}]},
                "procedure": {"type": "staircase", "variable": "relative_difference", "reference": "fitted",
                              "trials": 12, "start": 1.0, "min": 0.02, "max": 3, "up": 1, "down": 2,
                              "steps": [0.4, 0.2, 0.1]}}]
json.dump(p, open(sys.argv[2], "w"), indent=1)
PYEOF
  $BC validate "$W/staircase.json" > "$W/validate" 2>&1 || fail "validate: $(cat "$W/validate")"
  $BC run "$W/staircase.json" --participant S1 --db "$W/s.sqlite" --observer sim > "$W/out" 2>&1 ||
    fail "run: $(tail -3 "$W/out")"
  $BC export --db "$W/s.sqlite" --out "$W/tables" > /dev/null || fail "export"
  $PY - "$W/tables/trials.csv" <<'PYEOF' || fail "staircase on video"
import csv, sys
rows = [r for r in csv.DictReader(open(sys.argv[1])) if r["status"] == "answered"]
assert len(rows) == 12, len(rows)
levels = set()
for r in rows:
    level = float(r["level"])
    levels.add(level)
    test, ref = (r["r_left_px"], r["r_right_px"]) if r["test_side"] == "left" else (r["r_right_px"], r["r_left_px"])
    ratio = float(test) / float(ref)
    # The two balls lie at one depth (edge 6, columns 3 and 5), a fraction of a millimetre apart as the camera moves
    # sideways: their fitted radii differ by ~1e-4 of themselves.
    assert abs(ratio - (1 + level)) < 1e-3 * (1 + level), (r["trial_index"], level, ratio)
assert len(levels) >= 3, levels
print(f"12 staircase trials on video, levels {sorted(levels)}: each test side (1 + level) x its reference")
PYEOF
  echo "ok: a staircase on video: the test side is (1 + level) x the reference, averaged over the take" ;;
rolling)
  # A ball rolling on the take (edge 1 to 6 at 10 cm/s, shown for 133 ms; no exposure: under a streak frames.csv's r
  # is the width drawn across it, case frames checks streaks): each trial's declared radius (trials.csv) is what its
  # frames drew (frames.csv), averaged over the time each frame is on screen while the stimulus is - worked here from
  # the two tables alone. (Each frame's radius of the whole run, as
  # declared before, was 18 % off on a fast run: the ball crosses only part of its run while the take plays.)
  $PY - "$PROTOCOL" "$W/rolling.json" <<'PYEOF' || fail "could not write the rolling protocol"
import json, sys
p = json.load(open(sys.argv[1]))
p["name"] = "video-rolling"
p["factors"] = {"pattern": [{"id": 1, "left": "fitted", "right": "measured", "speed_cm_s": 10, "from_edge": 1,
                             "to_edge": 6}]}
p["practice"]["count"] = 0
p["timing"]["stimulus_ms"] = 133
p["content"]["exposure_ms"] = 0
json.dump(p, open(sys.argv[2], "w"), indent=1)
PYEOF
  # The simulated clock at 240 fps: the frames sample the ball's run finely (at the take's 30 fps each frame holds
  # the ball where it was at the frame's flip, 2 % below its average on screen here).
  $BC run "$W/rolling.json" --participant R1 --db "$W/s.sqlite" --observer sim --sim-fps 240 > "$W/out" 2>&1 ||
    fail "run: $(tail -3 "$W/out")"
  $BC export --db "$W/s.sqlite" --out "$W/tables" > /dev/null || fail "export"
  $PY - "$W/tables" 0.133 <<'PYEOF' > "$W/check" || fail "rolling ball on video: $(cat "$W/check")"
import csv, math, sys
d, stimulus = sys.argv[1], float(sys.argv[2])
trials = {int(t["trial_index"]): t for t in csv.DictReader(open(f"{d}/trials.csv"))}
frames = {}
for f in csv.DictReader(open(f"{d}/frames.csv")):
    if f["take_status"]:
        frames.setdefault(int(f["trial_index"]), []).append(f)
worst = {"r": 0.0, "motion": 0.0}
for i, t in trials.items():
    fs = sorted(frames[i], key=lambda f: float(f["flip_time_s"]))
    times = [float(f["flip_time_s"]) for f in fs] + [stimulus]
    w = [b - a for a, b in zip(times, times[1:])]
    for side in ("left", "right"):
        r = sum(wi * float(f[f"r_{side}_px"]) for wi, f in zip(w, fs)) / sum(w)
        err = abs(float(t[f"r_{side}_px"]) - r) / r
        worst["r"] = max(worst["r"], err)
        # The declared average steps a sixteenth of a take frame, the frames an eighth: a measured side's radius jumps
        # where the ball enters the next section (0.33 px here), which either places within its step.
        assert err < 0.015, (i, side, t[f"r_{side}_px"], r)
        assert float(t[f"motion_{side}_x_screen_px"]) == 0 == float(t[f"motion_{side}_y_screen_px"]), t
print(f"{len(trials)} trials: declared radius within {100 * worst['r']:.2f} % of what their frames drew")
PYEOF
  echo "ok: a rolling ball on video: $(cat "$W/check")" ;;
two_takes)
  # One protocol text run on another take (a station that filmed its own: here the same set-up with other sensor
  # noise) is another protocol text: under the same version it is refused naming /recorded_take, under a raised
  # version it runs, and the record keeps the two texts apart.
  $BC synth-take --out "$W/take-b" --frames 4 --supersample 2 --noise 0.004 --seed 8 --from-u-mm 320 --to-u-mm 280 \
    --focus-mm 340 --from-lateral-mm -15 --to-lateral-mm 15 --quiet || fail "synth-take b"
  $BC track "$W/take-b/take.avi" --camera "$W/take-b/camera.json" --out "$W/track-b" --quiet || fail "track b"
  $PY - "$PROTOCOL" "$W" "$DIR" <<'PYEOF' || fail "could not write the protocols"
import json, os, sys
p = json.load(open(sys.argv[1]))
w, d = sys.argv[2], sys.argv[3]
p["scene"] = {"video": os.path.join(d, "take", "take.avi"), "track": os.path.join(d, "track")}
json.dump(p, open(os.path.join(w, "a.json"), "w"), indent=1)
p["scene"] = {"video": os.path.join(w, "take-b", "take.avi"), "track": os.path.join(w, "track-b")}
json.dump(p, open(os.path.join(w, "b.json"), "w"), indent=1)
PYEOF
  # The same text but for the scene's paths: make them one text, as two stations with one protocol file would have.
  mkdir -p "$W/station-a" "$W/station-b"
  ln -sfn "$DIR/take" "$W/station-a/take"; ln -sfn "$DIR/track" "$W/station-a/track"
  ln -sfn "$W/take-b" "$W/station-b/take"; ln -sfn "$W/track-b" "$W/station-b/track"
  $PY - "$W/a.json" "$W/station-a/p.json" "$W/station-b/p.json" <<'PYEOF'
import json, sys
p = json.load(open(sys.argv[1]))
p["scene"] = {"video": "take/take.avi", "track": "track"}
for out in sys.argv[2:]:
    json.dump(p, open(out, "w"), indent=1)
PYEOF
  (cd "$W/station-a" && $BC run p.json --participant A1 --db "$W/s.sqlite" --observer sim > "$W/a.out" 2>&1) ||
    fail "station a: $(tail -2 "$W/a.out")"
  (cd "$W/station-b" && $BC run p.json --participant B1 --db "$W/s.sqlite" --observer sim > "$W/b.out" 2> "$W/b.err")
  code=$?
  [ $code = 3 ] && grep -q "records protocol version 1 with another text (/recorded_take/frames_fnv1a64" "$W/b.err" ||
    fail "another take under version 1: exit $code $(cat "$W/b.err")"
  sed -i 's/"version": 1,/"version": 2,/' "$W/station-b/p.json"
  (cd "$W/station-b" && $BC run p.json --participant B1 --db "$W/s.sqlite" --observer sim > "$W/b2.out" 2>&1) ||
    fail "station b, version 2: $(tail -2 "$W/b2.out")"
  [ "$(sql "$W/s.sqlite" "SELECT count(DISTINCT hash) FROM protocol_versions")" = 2 ] || fail "not two protocol texts"
  echo "ok: another take is another protocol text: refused under one version (/recorded_take), kept apart under two" ;;
bad_scene)
  # One problem, exit 3, naming the field: a missing take, a take of another frame size than its track folder's,
  # an unknown key.
  expect() {  # expect NAME FIELD TEXT: validate and run W/NAME.json
    for cmd in validate run; do
      local args=()
      [ $cmd = run ] && args=(--participant B1 --db "$W/$1.sqlite" --observer sim)
      $BC $cmd "$W/$1.json" "${args[@]}" > "$W/$1.out" 2> "$W/$1.err"
      local code=$?
      [ $code = 3 ] || fail "$cmd $1: exit $code, expected 3: $(cat "$W/$1.err")"
      [ "$(grep -c "$1.json: " "$W/$1.err")" = 1 ] || fail "$cmd $1: not one problem: $(cat "$W/$1.err")"
      grep -q "$1.json: $2: .*$3" "$W/$1.err" || fail "$cmd $1: expected '$2: ...$3': $(cat "$W/$1.err")"
      if grep -q "Traceback\|terminate\|Aborted" "$W/$1.err"; then fail "$cmd $1: $(cat "$W/$1.err")"; fi
    done
  }
  edit() {  # edit NAME PYTHON: W/NAME.json from the shipped protocol's copy, with p (the JSON) changed by PYTHON
    $PY - "$PROTOCOL" "$W/$1.json" "$DIR" "$2" <<'PYEOF'
import json, os, sys
p = json.load(open(sys.argv[1]))
d = sys.argv[3]
p["scene"] = {"video": os.path.join(d, "take", "take.avi"), "track": os.path.join(d, "track")}
exec(sys.argv[4])
json.dump(p, open(sys.argv[2], "w"), indent=1)
PYEOF
  }
  edit missing 'p["scene"]["video"] = os.path.join(d, "take", "tkae.avi")'
  expect missing /scene/video "no such file"
  # The take's frames at half size with the 1148 x 764 take's track folder.
  $PY - "$DIR/take" "$W/half" <<'PYEOF' || fail "could not write the half-size frames"
import glob, os, sys
from PIL import Image
os.makedirs(sys.argv[2], exist_ok=True)
for f in sorted(glob.glob(os.path.join(sys.argv[1], "frame-*.png"))):
    im = Image.open(f)
    im.resize((im.width // 2, im.height // 2)).save(os.path.join(sys.argv[2], os.path.basename(f)))
PYEOF
  edit other_size "p['scene']['video'] = '$W/half/frame-%04d.png'"
  expect other_size /scene/video "frame 0 is 574 x 382 px; the take .*track tracked is 1148 x 764 px (the track of another take?)"
  # The same take's frames in reverse order (same size, other pictures): not the frames that were tracked.
  mkdir -p "$W/reversed" "$W/short"
  n=$(ls "$DIR/take"/frame-*.png | wc -l)
  for ((i = 0; i < n; ++i)); do
    cp "$DIR/take/$(printf 'frame-%04d.png' $((n - 1 - i)))" "$W/reversed/$(printf 'frame-%04d.png' $i)"
    ((i < n - 1)) && cp "$DIR/take/$(printf 'frame-%04d.png' $i)" "$W/short/"
  done
  edit reversed "p['scene']['video'] = '$W/reversed/frame-%04d.png'"
  expect reversed /scene/video "frame 0 is not the frame .*track tracked (its grey levels differ by up to"
  # A video with fewer frames than track.csv lists.
  edit short "p['scene']['video'] = '$W/short/frame-%04d.png'"
  expect short /scene/video "has $((n - 1)) frames (0-$((n - 2))), but .*track/track.csv lists $n (the track of another take?)"
  # A track folder edited by hand: a frame marked lost whose calibration is there; one frame's calibration copied
  # over another's.
  rm -rf "$W/lostedit" "$W/copied" && cp -r "$DIR/track" "$W/lostedit" && cp -r "$DIR/track" "$W/copied"
  sed -i '3s/^\([^,]*,[^,]*\),[a-z]*,/\1,lost,/' "$W/lostedit/track.csv"
  edit lostedit "p['scene']['track'] = '$W/lostedit'"
  expect lostedit /scene/track "track.csv: line 3, status: says frame 1 is lost, but calib-0001.json holds its calibration"
  cp "$W/copied/calib-0001.json" "$W/copied/calib-0002.json"
  edit copied "p['scene']['track'] = '$W/copied'"
  expect copied /scene/track "calib-0002.json: /frame: must be 2, the frame of its row in track.csv, got 1"
  # An exposure longer than a frame of the take (30 fps: 33.33 ms).
  edit long_exposure 'p["content"]["exposure_ms"] = 300'
  expect long_exposure /content/exposure_ms "is 300 ms, longer than a frame of the take (33.33 ms at 30 fps)"
  edit unknown_key 'p["scene"]["tracks"] = p["scene"]["track"]'
  expect unknown_key /scene/tracks 'unknown key (did you mean "track"?)'
  echo "ok: a missing take, a take of another size than its track, its frames reversed, a video shorter than its" \
       "track, a frame marked lost by hand, a calibration copied over another, an unknown key: one problem each, exit 3" ;;
*)
  fail "unknown case $1" ;;
esac
