#!/usr/bin/python3
"""blurcue calibrate on synth-scene scenes against their truth, section by section (issue 42: tests/phase_tests.cmake,
level scenes; tests/turned_tests.cmake, turned boards and large blur).

  phase_check.py BLURCUE DIR --expect filtered|physical [--max-flagged N] [--max-bias F] [--min-measured F]
                 [--fitted-p90 F] [--sections-only] [--max-off N] [--no-phase-check]

DIR holds scene.png, camera.json and truth.json from `blurcue synth-scene` (level camera: every board edge runs along
the pixel rows; with --yaw-deg, across them). The truth is synth's: each section's r_px from the kernels it applied, the post-sampling filter's
taps' second moment included (truth.json post_filter.variance_px2), computed without the measurement code.

Prints every section (reading / truth, '*' flagged phase_limited, '!' a reading off the target unflagged) and the
figures, and exits 1 when a target is missed:
  --expect filtered (the image filtered after sampling): each section's r_px within max(0.05 px, 10 %) of the truth or
      flagged phase_limited; the fitted model (r_fitted_px) within median 2 %, p90 5 % of the truth over every section;
  --expect physical (optics before the pixel aperture): measured r_px median <= 2 %, p90 <= 5 % over the measured
      sections, the fitted model the same over every section, and at most --max-flagged sections flagged.
--max-bias F: also the signed median of the measured sections' (r_px - truth) / truth within +-F (a bias that the
      median of |error| hides under its 2 % target: a turned board's readings once sat +0.7-0.9 % high).
--min-measured F: at least this share of the sections measured (usable), e.g. 0.95 (issue 42: focus in front of the
      board, r up to 8 px).
--fitted-p90 F: with --expect filtered, the fitted model's p90 target F in place of 5 % (where it is known to break:
      sharpening that cancels most of the optics' blur near focus, docs/independent-truth.md).
--undetermined-covers: with --expect filtered, every section whose fitted model misses max(0.05 px, 5 %) must lie within
      the depths calib.json's model.undetermined names (where calibrate says the model is not determined
      within 5 %: a mask that cancels most of the optics' blur near focus); none named counts as no depth.
--max-off N: with --expect filtered, at most N sections off max(0.05 px, 10 %) unflagged in place of 0 (a known miss,
      named where the test is defined; every such section is still printed).
--sections-only: with --expect filtered, the per-section rule alone (a mask that cancels the whole second moment near
      focus, truth 0 px on a third of the sections: no thin lens bends to that).
A section whose truth is under 0.05 px (a mask that cancels the blur's whole second moment) is held to the 0.05 px
and counted at 0.05 px in the relative figures.
--no-phase-check runs calibrate with it (the readings before issue 42): a test that the targets catch what the flag
fixes. Exit 2 when blurcue itself fails.
"""
import argparse
import json
import os
import subprocess
import sys

import numpy as np


def pct(v):
    return "%.1f %%" % (100 * v)


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("blurcue")
    p.add_argument("dir")
    p.add_argument("--expect", choices=("filtered", "physical"), required=True)
    p.add_argument("--max-flagged", type=int, default=0)
    p.add_argument("--max-bias", type=float)
    p.add_argument("--min-measured", type=float)
    p.add_argument("--fitted-p90", type=float, default=0.05)
    p.add_argument("--sections-only", action="store_true")
    p.add_argument("--undetermined-covers", action="store_true")
    p.add_argument("--max-off", type=int, default=0)
    p.add_argument("--no-phase-check", action="store_true")
    a = p.parse_args()
    # Beside the scene's folder, not in it: synth-scene replaces its folder whole and refuses one holding other files.
    out = os.path.normpath(a.dir) + "-calib-%s%s.json" % (a.expect, "-unchecked" if a.no_phase_check else "")
    cmd = [a.blurcue, "calibrate", os.path.join(a.dir, "scene.png"), "--camera", os.path.join(a.dir, "camera.json"),
           "--out", out]
    if a.no_phase_check:
        cmd.append("--no-phase-check")
    run = subprocess.run(cmd, capture_output=True, text=True)
    if run.returncode != 0:
        print("blurcue failed (exit %d): %s %s" % (run.returncode, run.stdout.strip(), run.stderr.strip()))
        return 2
    for line in run.stdout.splitlines():
        if line.startswith(("the model is fitted", "phase check")) or line.endswith("pooled by the fit"):
            print(line)
    calib = json.load(open(out))
    truth = json.load(open(os.path.join(a.dir, "truth.json")))
    true = {(s["edge"], s["section"]): s["r_px"] for s in truth["sections"]}
    post = truth.get("post_filter")
    print("%s: %s; post-sampling filter %s" % (a.dir, "phase check off" if a.no_phase_check else "phase check on",
                                              "none" if not post else "%s std %.2f px, amount %.2f, taps' variance "
                                              "%.4f px^2" % (post["kind"], post["sigma_px"], post["amount"],
                                                             post["variance_px2"])))
    measured, signed, fitted, off, flagged, uncovered = [], [], [], [], 0, []
    undetermined = calib["model"].get("undetermined")
    u_lo, u_hi = undetermined["u_mm"] if undetermined else (1, 0)
    if undetermined:
        print("calibrate: %s" % undetermined["why"])
    for e in calib["edges"]:
        row = []
        y = e["sections"][len(e["sections"]) // 2]["image_px"][0][1]
        for s in e["sections"]:
            t = true[(e["index"], s["index"])]
            tr = max(t, 0.05)  # the relative figures' denominator (a truth near 0: the rule's 0.05 px)
            fitted.append(abs(s["r_fitted_px"] - t) / tr)
            if abs(s["r_fitted_px"] - t) > max(0.05, 0.05 * t) and not u_lo <= s["u_mm"] <= u_hi:
                uncovered.append((e["index"], s["index"], s["r_fitted_px"], t, s["u_mm"]))
            phase_limited = "phase_limited" in (s.get("flags") or [])
            flagged += phase_limited
            mark = " "
            if s["ok"]:
                measured.append(abs(s["r_px"] - t) / tr)
                signed.append((s["r_px"] - t) / tr)
                if abs(s["r_px"] - t) > max(0.05, 0.10 * t):
                    off.append((e["index"], s["index"], s["r_px"], t))
                    mark = "!"
            elif phase_limited:
                mark = "*"
            else:
                mark = "-"
            row.append("%4.2f/%4.2f%s" % (s["r_px"], t, mark))
        print("edge %2d (row %7.2f): %s" % (e["index"], y, " ".join(row)))
    n = len(fitted)
    mm, mp = (float(np.median(measured)), float(np.percentile(measured, 90, method="lower"))) if measured else (1, 1)
    fm, fp = float(np.median(fitted)), float(np.percentile(fitted, 90, method="lower"))
    print("measured r_px: %d of %d sections, median %s, p90 %s; %d flagged phase_limited; %d off max(0.05 px, 10 %%) "
          "unflagged" % (len(measured), n, pct(mm), pct(mp), flagged, len(off)))
    bias = float(np.median(signed)) if signed else 1
    print("fitted r_fitted_px over all %d sections: median %s, p90 %s" % (n, pct(fm), pct(fp)))
    print("measured r_px signed median (bias) %+.2f %%" % (100 * bias))
    missed = []
    if a.expect == "filtered":
        for edge, section, r, t in off:
            line = "edge %d section %d reads %.3f px for %.3f px, unflagged" % (edge, section, r, t)
            if len(off) > a.max_off:
                missed.append(line)
            else:
                print("allowed (--max-off %d): %s" % (a.max_off, line))
    else:
        if mm > 0.02 or mp > 0.05:
            missed.append("measured r median %s, p90 %s (target <= 2 %%, <= 5 %%)" % (pct(mm), pct(mp)))
        if flagged > a.max_flagged:
            missed.append("%d sections flagged phase_limited (at most %d)" % (flagged, a.max_flagged))
    if a.undetermined_covers:
        for edge, section, r, t, u in uncovered:
            missed.append("edge %d section %d (u %.0f mm): the model predicts %.3f px for %.3f px, outside the depths "
                          "calibrate calls not determined within 5 %%" % (edge, section, u, r, t))
    if a.min_measured is not None and len(measured) < a.min_measured * n:
        missed.append("%d of %d sections measured (at least %.0f %%)" % (len(measured), n, 100 * a.min_measured))
    if a.max_bias is not None and abs(bias) > a.max_bias:
        missed.append("measured r bias %+.2f %% (target within +-%.2f %%)" % (100 * bias, 100 * a.max_bias))
    if (fm > 0.02 or fp > a.fitted_p90) and not a.sections_only:
        missed.append("fitted r median %s, p90 %s (target <= 2 %%, <= %s)" % (pct(fm), pct(fp), pct(a.fitted_p90)))
    for m in missed:
        print("target missed: " + m)
    if not missed:
        print("ok: %s targets met" % a.expect)
    return 1 if missed else 0


if __name__ == "__main__":
    sys.exit(main())
