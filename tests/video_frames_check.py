#!/usr/bin/env python3
"""A study on video, frame by frame, against the take's truth (tests/video_study_test.sh, case frames).

usage: video_frames_check.py TAKE_DIR EXPORT_DIR CAPTURE_DIR EXPOSURE_MS [STIMULUS_S]

STIMULUS_S: the protocol's timing.stimulus_ms in seconds (absent: shown until the answer, the take as it plays once).

TAKE_DIR is what `blurcue synth-take` wrote (take.json: per-frame time and true pose; truth-NNNN.json: the lens and
floor applied); EXPORT_DIR what `blurcue export` wrote for a simulated session of protocols/video-ball-depth.json
(trials.csv, frames.csv); CAPTURE_DIR its `--capture` folder. Worked here from the truth alone, not from blurcue's code:
- which take frame each display frame shows: frame floor(t x fps) of the take, the last one held past its end;
- each ball's centre (the protocol's geometry: over column 3 or 5 of the board, at its edge's y, one radius above the
  board) projected through the true pose: the capture's centre at the trial's first frame within 0.5 photo px;
- the blur r of a `fitted` side: the thin lens of the truth (aperture, focal length, focus) at the centre's true depth,
  with the applied floor, r^2 = r_defocus^2 + (2 floor)^2 (r = 2 x the LSF's std): within 3 %; a `none` side: 0.
  With an exposure, r is the width the frame is drawn with across the streak, which a streak between pixel centres
  makes up to 1 px (the bilinear spreading of a sample has a variance of at most 1/4 px^2 across): a `fitted` side
  from 3 % below the truth to the larger of 3 % above it and 1 px, a `none` side at most 1 px;
- the motion streak: the centre's projection at the neighbouring true poses (central difference; one-sided at the
  ends) over their time apart, times the exposure: within max(0.3 px, 5 %).
- each trial's declared radius (trials.csv) of a fitted side, and each side's declared streak: the truth above
  averaged over the take's frames, each weighted by its time on screen in the stimulus (frame k from k / fps, the
  last one held to the stimulus's end): the radius within 3 %, the streak within max(0.3 px, 5 %). Display frames
  after the stimulus (no take frame: the answer screen) show no ball.
"""
import csv
import glob
import json
import math
import os
import sys

import numpy as np

take_dir, export_dir, capture_dir, exposure_ms = sys.argv[1], sys.argv[2], sys.argv[3], float(sys.argv[4])
stimulus_s = float(sys.argv[5]) if len(sys.argv) > 5 else None
take = json.load(open(os.path.join(take_dir, "take.json")))
truth = json.load(open(os.path.join(take_dir, "truth-0000.json")))
fps = take["fps"]
frames = take["per_frame"]
cam = truth["camera"]
pitch = truth["pixel_pitch_mm"]
f_mm, aperture, focus = cam["focal_length_mm"], truth["aperture_mm"], truth["focus_mm"]
floor = truth["floor_sigma_applied_px"]
square = truth["board"]["square_mm"]
radius_mm = 10.0
fpx = f_mm / pitch
cx, cy = cam["image_width_px"] / 2, cam["image_height_px"] / 2  # blurcue's and the generator's principal point


def camera_point(k, p):
    pose = frames[k]["pose"]
    return np.array(pose["rotation"]) @ np.array(p) + np.array(pose["tvec"])


def project(k, p):
    c = camera_point(k, p)
    return np.array([fpx * c[0] / c[2] + cx, fpx * c[1] / c[2] + cy])


def r_true(k, p):
    z = camera_point(k, p)[2]
    diameter_mm = aperture * f_mm / (focus - f_mm) * abs(z - focus) / z  # the blur circle on the sensor
    defocus = diameter_mm / 2 / pitch  # a disc's radius: 2 x its LSF's std
    return math.hypot(defocus, 2 * floor)


def streak_true(k, p):
    a, b = max(0, k - 1), min(len(frames) - 1, k + 1)
    dt = frames[b]["time_s"] - frames[a]["time_s"]
    return (project(b, p) - project(a, p)) / dt * exposure_ms / 1000


def rows(name):
    with open(os.path.join(export_dir, name), newline="") as f:
        return list(csv.DictReader(f))


trials = {int(t["trial_index"]): t for t in rows("trials.csv")}
failures, checked = [], {"r": 0, "none": 0, "motion": 0, "frames": 0, "centre": 0}
worst = {"r": 0.0, "motion": 0.0, "centre": 0.0}
checked["after"] = 0
for fr in rows("frames.csv"):
    t = trials[int(fr["trial_index"])]
    where = f"trial {fr['trial_index']} frame {fr['frame_index']}"
    time_s = float(fr["flip_time_s"])
    if fr["take_status"] == "":  # after the stimulus: the answer screen, no take frame and no ball
        checked["after"] += 1
        if stimulus_s is None or time_s < stimulus_s - 1e-6:
            failures.append(f"{where}: no take frame at {time_s} s, within the stimulus")
        continue
    expect = min(len(frames) - 1, int(math.floor(time_s * fps + 1e-6)))
    held = math.floor(time_s * fps + 1e-6) > len(frames) - 1
    if int(fr["take_frame"]) != expect or (fr["take_status"] == "held") != held:
        failures.append(f"{where}: at {time_s} s shows take frame {fr['take_frame']} ({fr['take_status']}), "
                        f"expected {expect}{' held' if held else ''}")
    checked["frames"] += 1
    k = expect
    y = (int(t["edge"]) - 1) * square
    for side, section in (("left", 3), ("right", 5)):
        source = t[f"{side}_source"]
        centre = [(section - 0.5) * square, y, radius_mm]
        r = float(fr[f"r_{side}_px"])
        if source == "none":
            checked["none"] += 1
            if not (r == 0 if exposure_ms == 0 else 0 <= r <= 1.001):  # the float kernel: 1 + 5e-5 seen
                failures.append(f"{where} {side}: r {r}, expected {'0' if exposure_ms == 0 else '<= 1 px'} (none)")
        elif source == "fitted":
            checked["r"] += 1
            want = r_true(k, centre)
            high = want * 1.03 if exposure_ms == 0 else max(want * 1.03, 1.0)
            err = abs(r - want) / want if exposure_ms == 0 else max(0.0, want * 0.97 - r, r - high) / want
            worst["r"] = max(worst["r"], err)
            if not (want * 0.97 <= r <= high):
                failures.append(f"{where} {side}: r {r:.4f} px, truth {want:.4f} px (allowed {want * 0.97:.4f}-"
                                f"{high:.4f})")
        m = np.array([float(fr[f"motion_{side}_x_px"]), float(fr[f"motion_{side}_y_px"])])
        want_m = streak_true(k, centre)
        err = np.linalg.norm(m - want_m)
        tolerance = max(0.3, 0.05 * np.linalg.norm(want_m))
        worst["motion"] = max(worst["motion"], err / tolerance)
        checked["motion"] += 1
        if err > tolerance:
            failures.append(f"{where} {side}: streak {m.round(3)} px, truth {want_m.round(3)} px")

# Each trial's declared radius (trials.csv) of a fitted side, and its declared streak: the truth averaged over the
# take's frames, each weighted by its time on screen while the stimulus is (until the answer: the take plays once).
window = stimulus_s if stimulus_s is not None else len(frames) / fps
weights = [max(0.0, (window if k == len(frames) - 1 else min(window, (k + 1) / fps)) - k / fps)
           for k in range(len(frames))]
weights = [w / sum(weights) for w in weights]
scales = [json.load(open(p))["screen_px_per_photo_px"] for p in glob.glob(os.path.join(capture_dir, "trial-*.json"))]
checked["declared"], worst["declared"], checked["declared_motion"], worst["declared_motion"] = 0, 0.0, 0, 0.0
for t in trials.values():
    y = (int(t["edge"]) - 1) * square
    for side, section in (("left", 3), ("right", 5)):
        centre = [(section - 0.5) * square, y, radius_mm]
        if scales and exposure_ms > 0 and t[f"{side}_source"] != "":
            want_m = sum(w * streak_true(k, centre) for k, w in enumerate(weights))
            m = np.array([float(t[f"motion_{side}_x_screen_px"]), float(t[f"motion_{side}_y_screen_px"])]) / scales[0]
            tolerance = max(0.3, 0.05 * np.linalg.norm(want_m))
            worst["declared_motion"] = max(worst["declared_motion"], np.linalg.norm(m - want_m) / tolerance)
            checked["declared_motion"] += 1
            if np.linalg.norm(m - want_m) > tolerance:
                failures.append(f"trial {t['trial_index']} {side}: declared streak {m.round(3)} photo px, the "
                                f"take's true mean {want_m.round(3)}")
        if t[f"{side}_source"] != "fitted":
            continue
        want = sum(w * r_true(k, centre) for k, w in enumerate(weights))
        err = abs(float(t[f"r_{side}_px"]) - want) / want
        worst["declared"] = max(worst["declared"], err)
        checked["declared"] += 1
        if err > 0.03:
            failures.append(f"trial {t['trial_index']} {side}: declared r {t[f'r_{side}_px']} px, the take's true "
                            f"mean {want:.4f} px")

# The capture of each trial's first frame: where each ball is drawn (screen px back to photo px).
for path in sorted(glob.glob(os.path.join(capture_dir, "trial-*.json"))):
    c = json.load(open(path))
    t = trials[c["trial_index"]]
    k = c["take_frame"]
    scale = c["screen_px_per_photo_px"]
    x0, y0 = c["photo_rect_px"][0], c["photo_rect_px"][1]
    for o in c["objects"]:
        section = 3 if o["side"] == "left" else 5
        centre = [(section - 0.5) * square, (int(t["edge"]) - 1) * square, radius_mm]
        drawn = np.array([(o["center_px"][0] - x0 + 0.5) / scale - 0.5, (o["center_px"][1] - y0 + 0.5) / scale - 0.5])
        err = np.linalg.norm(drawn - project(k, centre))
        worst["centre"] = max(worst["centre"], err)
        checked["centre"] += 1
        if err > 0.5:
            failures.append(f"{os.path.basename(path)} {o['side']}: drawn at {drawn.round(2)} photo px, truth "
                            f"{project(k, centre).round(2)}")

print(f"checked {checked['frames']} frames: {checked['r']} fitted radii (worst {100 * worst['r']:.2f} %), "
      f"{checked['none']} unblurred sides, {checked['motion']} streaks (worst {worst['motion']:.2f} of the tolerance), "
      f"{checked['centre']} captured centres (worst {worst['centre']:.3f} photo px), {checked['declared']} trials' "
      f"declared radii against the take's mean (worst {100 * worst['declared']:.2f} %), "
      f"{checked['declared_motion']} declared streaks (worst {worst['declared_motion']:.2f} of the tolerance), "
      f"{checked['after']} frames after the stimulus")
if not checked["r"] or not checked["motion"] or not checked["centre"] or not checked["declared"]:
    failures.append("nothing to check")
if exposure_ms > 0 and not checked["declared_motion"]:
    failures.append("no declared streak to check")
for f in failures[:20]:
    print("FAIL:", f)
sys.exit(1 if failures else 0)
