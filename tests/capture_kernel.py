#!/usr/bin/env python3
"""capture_kernel.py BLURRED SHARP [--tolerance-px 0.03 --tolerance-rel 0.03 --min-r 0.25
                                   --streak-tolerance-px 0.3 --streak-tolerance-rel 0.05]

The blur a captured frame shows, found without any of blurcue's code: for every object of every trial-NNNN.json
in BLURRED, the kernel that maps the same trial's frame in SHARP (its unblurred twin, captured with blur 0 over a
flat background) onto the blurred frame is solved by linear least squares, tap by tap, in linear light (sRGB
decoded as IEC 61966-2-1 says), over the object and a margin around it. Its radius is the DESIGN.md one: 2 x the
standard deviation of the kernel's marginal (the line-spread function across an edge), the mean of the x and y
variances. Nothing is assumed of the kernel's shape, so a Gaussian and a pillbox are measured alike, and nothing is
fitted at whole-pixel samples of a formula (a Gaussian sampled at whole pixels keeps too little variance below
1 px: r 0.81 sampled has the variance of r 0.58).

A moving object (a record with a non-zero motion_screen_px) leaves a streak: the kernel's covariance is then taken
apart along its principal axes (numpy's eigen decomposition, nothing of the record's direction), the across variance
giving r (2 x its std) and the along variance's excess over it the streak, L = sqrt(12 (var_along - var_across)) (a
segment of length L has variance L^2 / 12); its direction is the principal axis.

An object drawn by the per-pixel plan (each pixel blurred for its own depth) has its visible surface's radii in its
record, r_range_screen_px [nearest, farthest]: one kernel solved over it mixes them, so its r is judged against that
range, not its centre's r_screen_px.

Prints one line per object and exits 1 when an object whose recorded r_screen_px is at least --min-r is off by more
than max(tolerance-px, tolerance-rel x r) (outside its range by more than that at the range's nearer end), a streak's length is off by more than max(streak-tolerance-px,
streak-tolerance-rel x L) or its direction by more than the angle that tolerance subtends at its end, or when an
object of the record is not in the frame.
"""
import argparse
import glob
import json
import math
import os
import sys

import numpy as np
from PIL import Image


def _srgb_decode(v):
    return np.where(v <= 0.04045, v / 12.92, ((v + 0.055) / 1.055) ** 2.4)


# The decoding of each of the 256 byte values, worked out once by the same formula: looking a frame's bytes up in it
# gives the same numbers, bit for bit, as decoding every pixel (a frame is 3 x 1.4 million pixels, the capture tests
# read hundreds of frames).
_SRGB_TO_LINEAR = _srgb_decode(np.arange(256, dtype=np.float64) / 255.0)


def linear(path):
    return _SRGB_TO_LINEAR[np.asarray(Image.open(path).convert("RGB"), dtype=np.uint8)]


def solve_kernel(sharp, blurred, box, h):
    """Least-squares taps k[dy, dx], |dx|, |dy| <= h, with blurred(p) = sum k sharp(p - d) over box (x0, y0, x1, y1)."""
    x0, y0, x1, y1 = box
    rows, rhs = [], []
    offsets = [(dy, dx) for dy in range(-h, h + 1) for dx in range(-h, h + 1)]
    for c in range(3):
        s = sharp[:, :, c]
        cols = [s[y0 - dy:y1 - dy, x0 - dx:x1 - dx].ravel() for dy, dx in offsets]
        rows.append(np.stack(cols, axis=1))
        rhs.append(blurred[y0:y1, x0:x1, c].ravel())
    a, b = np.concatenate(rows), np.concatenate(rhs)
    k, *_ = np.linalg.lstsq(a, b, rcond=None)
    return k.reshape(2 * h + 1, 2 * h + 1)


def object_box(o, h, width, height):
    """The box (x0, y0, x1, y1) the kernel of half-width h is solved over: the object's outline and a margin, kept h
    px inside the frame. Too small (under 4 h a side) when the object is not in the frame."""
    xs = [p[0] for p in o["outline_px"]]
    ys = [p[1] for p in o["outline_px"]]
    margin = h + 2
    return (max(h, int(min(xs)) - margin), max(h, int(min(ys)) - margin),
            min(width - h, int(math.ceil(max(xs))) + margin), min(height - h, int(math.ceil(max(ys))) + margin))


def kernel_radius(k):
    h = k.shape[0] // 2
    t = np.arange(-h, h + 1, dtype=np.float64)
    total = k.sum()
    variances = []
    for marginal in (k.sum(axis=0), k.sum(axis=1)):
        mean = (marginal * t).sum() / total
        variances.append((marginal * (t - mean) ** 2).sum() / total)
    return 2 * math.sqrt(max(0.0, sum(variances) / 2)), total


def kernel_streak(k):
    """r (2 x the std across), the streak's length and its direction (radians, image x right, y down, mod pi)."""
    h = k.shape[0] // 2
    t = np.arange(-h, h + 1, dtype=np.float64)
    total = k.sum()
    xs, ys = np.meshgrid(t, t)
    mx, my = (k * xs).sum() / total, (k * ys).sum() / total
    dx, dy = xs - mx, ys - my
    cov = np.array([[(k * dx * dx).sum(), (k * dx * dy).sum()], [(k * dx * dy).sum(), (k * dy * dy).sum()]]) / total
    values, vectors = np.linalg.eigh(cov)  # ascending
    across, along = values
    direction = math.atan2(vectors[1, 1], vectors[0, 1]) % math.pi
    return 2 * math.sqrt(max(0.0, across)), math.sqrt(12 * max(0.0, along - across)), direction, total


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[1], formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("blurred")
    ap.add_argument("sharp")
    ap.add_argument("--tolerance-px", type=float, default=0.03)
    ap.add_argument("--tolerance-rel", type=float, default=0.03)
    ap.add_argument("--min-r", type=float, default=0.25)
    ap.add_argument("--streak-tolerance-px", type=float, default=0.3)
    ap.add_argument("--streak-tolerance-rel", type=float, default=0.05)
    args = ap.parse_args()
    trials = sorted(glob.glob(os.path.join(args.blurred, "trial-*.json")))
    if not trials:
        sys.exit(f"capture_kernel: no trial-*.json in {args.blurred}")
    bad = checked = 0
    worst = 0.0
    for path in trials:
        name = os.path.basename(path)[:-5]
        frame = json.load(open(path))
        blurred = linear(os.path.join(args.blurred, name + ".png"))
        sharp = linear(os.path.join(args.sharp, name + ".png"))
        if blurred.shape != sharp.shape:
            print(f"BAD {name}: frame sizes differ {blurred.shape} vs {sharp.shape}")
            bad += 1
            continue
        height, width = blurred.shape[:2]
        for o in frame["objects"]:
            r_rec = o["r_screen_px"]
            lo, hi = o.get("r_range_screen_px", [r_rec, r_rec])
            m_rec = o.get("motion_screen_px", [0, 0])
            l_rec = math.hypot(*m_rec)
            h = max(3, math.ceil(1.6 * max(r_rec, hi) + l_rec / 2) + 2)
            box = object_box(o, h, width, height)
            if box[2] - box[0] < 4 * h or box[3] - box[1] < 4 * h:
                print(f"BAD {name} {o['side']}: the object is not in the frame (box {box})")
                bad += 1
                continue
            k = solve_kernel(sharp, blurred, box, h)
            if l_rec > 0:
                r, length, direction, total = kernel_streak(k)
            else:
                r, total = kernel_radius(k)
            # Against the recorded radius, or the nearer end of the recorded range (0 inside it).
            near = min(max(r, lo), hi) if "r_range_screen_px" in o else r_rec
            err = r - near
            limit = max(args.tolerance_px, args.tolerance_rel * near)
            judged = r_rec >= args.min_r
            off = judged and abs(err) > limit
            if judged:
                checked += 1
                worst = max(worst, abs(err) / limit)
            streak = ""
            if l_rec > 0:
                l_err = length - l_rec
                l_limit = max(args.streak_tolerance_px, args.streak_tolerance_rel * l_rec)
                rec_direction = math.atan2(m_rec[1], m_rec[0]) % math.pi
                d_err = (direction - rec_direction + math.pi / 2) % math.pi - math.pi / 2
                d_limit = math.atan2(l_limit, l_rec / 2)
                l_off = abs(l_err) > l_limit or abs(d_err) > d_limit
                off = off or l_off
                checked += 1
                worst = max(worst, abs(l_err) / l_limit, abs(d_err) / d_limit)
                streak = (f"; streak recorded {l_rec:.4f} px at {math.degrees(rec_direction):.2f} deg, shown {length:.4f} "
                          f"at {math.degrees(direction):.2f} deg (error {l_err:+.4f} px, limit {l_limit:.3f}; "
                          f"{math.degrees(d_err):+.2f} deg, limit {math.degrees(d_limit):.2f})")
            bad += off
            drawn = f" (per pixel {lo:.4f}-{hi:.4f})" if "r_range_screen_px" in o else ""
            print(f"{'BAD ' if off else ''}{name} {o['side']} {o['kernel']}: recorded r {r_rec:.4f} screen px{drawn}, "
                  f"shown {r:.4f} (error {err:+.4f}, limit {limit:.3f}{'' if judged else ', below --min-r: not judged'}), "
                  f"kernel sum {total:.4f}{streak}")
    print(f"{checked} objects judged, {bad} off; the largest error is {worst:.2f} of its limit")
    sys.exit(1 if bad or not checked else 0)


if __name__ == "__main__":
    main()
