#!/usr/bin/python3
"""blurcue calibrate / track held against the independent generator's truth (tests/indep_scene.py).

  indep_check.py calibrate BLURCUE DIR [--what all|pose|blur]  DIR: scene.png, camera.json, truth.json
  indep_check.py track BLURCUE DIR [--what all|pose|blur]      DIR: frame-%04d.png, camera.json, truth-%04d.json

blurcue's output goes to DIR/calib-WHAT.json or DIR/track-WHAT/ (so two checks of one scene may run at once).

Prints every figure (pose, depth error, measured r_px and fitted r_fitted_px: median and p90 of |error| / truth over
every section with an edge, per frame for a take) and exits 1 when a target is missed:
  --what pose: board found (every frame tracked or found), section depths within 0.1 % of the truth;
  --what blur: issue 25 (still): median <= 2 %, p90 <= 5 % for measured and fitted r (a section flagged
               phase_limited counts with its reading; at most 10 such, issue 42);
               issue 27 (take): every frame's measured r median <= 3 %, p90 <= 8 %;
  --what fitted (take): the take's lens model's r per frame, median <= 3 %, p90 <= 8 % (as for measured r);
  --what all: pose and blur.
Exit 2 when blurcue itself fails (its message is printed), 1 when a target is missed.
"""
import argparse
import csv
import json
import os
import subprocess
import sys

import numpy as np


def rel_errors(calib, truth):
    """|r - r_true| / r_true per section for measured (r_px) and fitted (r_fitted_px) r; max relative depth error;
    the number of sections with an edge: every section of the board (issue 25: "over every section with an edge").
    A section calibrate leaves unmeasured ('crowded', with crowded_why, or any other flag) counts as missed."""
    true = {(s["edge"], s["section"]): s for s in truth["sections"]}
    measured, fitted, depth = [], [], 0.0
    for e in calib["edges"]:
        for s in e["sections"]:
            t = true[(e["index"], s["index"])]
            depth = max(depth, abs(s["u_mm"] - t["u_mm"]) / t["u_mm"])
            # phase_limited (issue 42): measured, but the PSF families that fit alike leave its value open by more than
            # 8 %; its reading (the chosen family's) counts, and the flag is counted apart (phase_limited()).
            if (s.get("ok") or phase_limited(s)) and s.get("r_px") is not None:
                measured.append(abs(s["r_px"] - t["r_px"]) / t["r_px"])
            if s.get("r_fitted_px") is not None:
                fitted.append(abs(s["r_fitted_px"] - t["r_px"]) / t["r_px"])
    return np.array(measured), np.array(fitted), depth, len(true)


# Physically rendered scenes (optics before the pixel aperture) may leave a few level sections' PSF family open; more
# would be the check misreading physical optics as filtered (none is flagged on these scenes today; with 0.05 px bins
# the distorted one flagged 9 of 77, all read within 3 %).
MAX_PHASE_LIMITED = 10


def phase_limited(section):
    return "phase_limited" in (section.get("flags") or [])


def summary(errs):
    if len(errs) == 0:
        return None, None
    return float(np.median(errs)), float(np.percentile(errs, 90, method="lower"))


def pct(v):
    return "not determined" if v is None else "%.1f %%" % (100 * v)


def run(cmd):
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        print("blurcue failed (exit %d): %s %s" % (p.returncode, p.stdout.strip(), p.stderr.strip()))
        sys.exit(2)
    return p.stdout


def check_calibrate(args):
    d = args.dir
    # --truth as well: calibrate reads the generator's truth.json itself (a format it did not write).
    run([args.blurcue, "calibrate", os.path.join(d, "scene.png"), "--camera", os.path.join(d, "camera.json"),
         "--out", os.path.join(d, "calib-%s.json" % args.what), "--truth", os.path.join(d, "truth.json"), "--quiet"])
    calib = json.load(open(os.path.join(d, "calib-%s.json" % args.what)))
    truth = json.load(open(os.path.join(d, "truth.json")))
    m, f, depth, n = rel_errors(calib, truth)
    (mm, mp), (fm, fp) = summary(m), summary(f)
    r_true = [s["r_px"] for s in truth["sections"]]
    across = sum("neighbours" in (s.get("flags") or []) for e in calib["edges"] for s in e["sections"])
    print("%s: %s, floor %.2f px, focus %.0f mm, r %.2f-%.2f px; %d of %d sections measured (%d across their "
          "neighbouring edges)" % (d, truth["psf"], truth["options"]["floor_sigma_px"], truth["focus_mm"], min(r_true),
                                   max(r_true), len(m), n, across))
    flagged = 0
    for e in calib["edges"]:
        for s in e["sections"]:
            if phase_limited(s):
                flagged += 1
            elif not s.get("ok"):
                print("  edge %d section %d not measured: %s %s" % (e["index"], s["index"], s.get("flags"),
                                                                  s.get("crowded_why", "")))
    print("  %d sections flagged phase_limited (measured; left out of the lens fit, which predicts them)" % flagged)
    print("  depth error max %.4f %%" % (100 * depth))
    print("  measured r_px:      median %s, p90 %s" % (pct(mm), pct(mp)))
    print("  fitted r_fitted_px: median %s, p90 %s" % (pct(fm), pct(fp)))
    missed = []
    if args.what in ("pose", "all") and depth > 0.001:
        missed.append("depth error %.3f %% > 0.1 %%" % (100 * depth))
    if args.what in ("blur", "all"):
        for name, med, p90 in (("measured", mm, mp), ("fitted", fm, fp)):
            if med is None or med > 0.02 or p90 > 0.05:
                missed.append("%s r: median %s, p90 %s (target <= 2 %%, <= 5 %%)" % (name, pct(med), pct(p90)))
        if len(m) < n:
            missed.append("%d of %d sections unmeasured" % (n - len(m), n))
        if flagged > MAX_PHASE_LIMITED:
            missed.append("%d sections flagged phase_limited (at most %d on physically rendered optics)" %
                          (flagged, MAX_PHASE_LIMITED))
    return missed


def check_track(args):
    d = args.dir
    out = os.path.join(d, "track-" + args.what)
    run([args.blurcue, "track", os.path.join(d, "frame-%04d.png"), "--camera", os.path.join(d, "camera.json"),
         "--out", out, "--quiet"])
    rows = list(csv.DictReader(open(os.path.join(out, "track.csv"))))
    missed = []
    worst_med = worst_p90 = worst_depth = 0.0
    print("frame status   depth-err  measured r: median  p90    fitted r: median  p90")
    for row in rows:
        i = int(row["frame"])
        truth = json.load(open(os.path.join(d, "truth-%04d.json" % i)))
        if row["status"] == "lost":
            missed.append("frame %d lost" % i)
            print("%5d %-8s" % (i, row["status"]))
            continue
        calib = json.load(open(os.path.join(out, "calib-%04d.json" % i)))
        m, f, depth, n = rel_errors(calib, truth)
        (mm, mp), (fm, fp) = summary(m), summary(f)
        print("%5d %-8s %8.4f %%  %16s %8s %16s %8s" % (i, row["status"], 100 * depth, pct(mm), pct(mp), pct(fm),
                                                        pct(fp)))
        worst_depth = max(worst_depth, depth)
        if args.what in ("pose", "all") and depth > 0.001:
            missed.append("frame %d: depth error %.3f %%" % (i, 100 * depth))
        if args.what == "fitted" and (fm is None or fm > 0.03 or fp > 0.08):
            missed.append("frame %d: fitted r median %s, p90 %s (target <= 3 %%, <= 8 %%)" % (i, pct(fm), pct(fp)))
        if args.what in ("blur", "all"):
            if mm is None or mm > 0.03 or mp > 0.08:
                missed.append("frame %d: measured r median %s, p90 %s (target <= 3 %%, <= 8 %%)" % (i, pct(mm),
                                                                                                   pct(mp)))
            worst_med = max(worst_med, 1.0 if mm is None else mm)
            worst_p90 = max(worst_p90, 1.0 if mp is None else mp)
    expected = len([n for n in os.listdir(d) if n.startswith("frame-") and n.endswith(".png")])
    if len(rows) != expected:
        missed.append("%d of %d frames in track.csv" % (len(rows), expected))
    blur = "; worst per-frame measured r median %s, p90 %s" % (pct(worst_med), pct(worst_p90))
    print("%d frames; worst depth error %.4f %%" % (len(rows), 100 * worst_depth) +
          ("" if args.what in ("pose", "fitted") else blur))
    return missed


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("mode", choices=("calibrate", "track"))
    p.add_argument("blurcue")
    p.add_argument("dir")
    p.add_argument("--what", choices=("pose", "blur", "fitted", "all"), default="all")
    args = p.parse_args()
    missed = check_calibrate(args) if args.mode == "calibrate" else check_track(args)
    for m in missed:
        print("target missed: " + m)
    if not missed:
        print("ok: %s %s targets met" % (args.mode, args.what))
    return 1 if missed else 0


if __name__ == "__main__":
    sys.exit(main())
