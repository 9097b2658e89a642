#!/usr/bin/env python3
"""ar_check.py WORKDIR

Checks what `blurcue ar` drew into a ground-truth take (tests/ar_test.sh makes WORKDIR) against truth it did not
compute, with nothing of blurcue's code:

1. Place: every frame's ball (CSV screen_x/y_px) against its centre projected through the truth pose
   (take/truth-NNNN.json) with the pinhole camera of take/camera.json: within 0.5 px.
2. Defocus: the CSV's r_px for the ball against the thin-lens r of the take's true lens (truth-NNNN.json: focus,
   aperture, pixel pitch, lens floor) at the ball centre's true depth, r = sqrt(R^2 + 4 f^2), R = D F |u - u0| /
   (2 u (u0 - F) pitch): within 3 %.
3. The written frames (white-card and black-card runs, blurred and sharp): in linear light (sRGB decoded as IEC
   61966-2-1 says), white minus black is the card's blurred coverage alone (an unlit white card adds C x A = A; the
   ball, the photo and everything else cancel). The kernel mapping the sharp coverage onto the blurred one is solved
   by linear least squares, tap by tap, and taken apart along its principal axes (numpy's eigen decomposition):
   r = 2 x the across std, streak L = sqrt(12 (var_along - var_across)) and its direction; these against the CSV's
   r_px and motion within max(0.3 px, 5 %). The sharp coverage's centroid against the centroid of the card's
   silhouette, the quadrilateral of its corners projected through the truth pose (shoelace formula): within 0.3 px.

Exits 1 naming every check that fails.
"""
import csv
import json
import math
import os
import sys

import numpy as np
from PIL import Image

W = sys.argv[1]
FAILS = []


def check(ok, text):
    print(("ok   " if ok else "FAIL ") + text)
    if not ok:
        FAILS.append(text)


def linear(path):
    v = np.asarray(Image.open(path).convert("L" if False else "RGB"), dtype=np.float64) / 255.0
    v = np.where(v <= 0.04045, v / 12.92, ((v + 0.055) / 1.055) ** 2.4)
    return v.mean(axis=2)


def rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


cam = json.load(open(f"{W}/take/camera.json"))
pitch = cam["sensor_width_mm"] / cam["image_width_px"]
fpx = cam["focal_length_mm"] / pitch
K = np.array([[fpx, 0, cam["image_width_px"] / 2], [0, fpx, cam["image_height_px"] / 2], [0, 0, 1]])
objects = json.load(open(f"{W}/white.json"))["objects"]
ball = next(o for o in objects if o["kind"] == "ball")
card = next(o for o in objects if o["kind"] == "card")


def truth(frame):
    t = json.load(open(f"{W}/take/truth-{frame:04d}.json"))
    return t, np.array(t["pose"]["rotation"]), np.array(t["pose"]["tvec"])


def project(R, t, p):
    c = R @ np.asarray(p, dtype=float) + t
    q = K @ c
    return q[:2] / q[2], c[2]


def thin_lens_r(t, u):
    F, D, u0 = cam["focal_length_mm"], t["aperture_mm"], t["focus_mm"]
    R = D * F * abs(u - u0) / (2 * u * (u0 - F) * t["pixel_pitch_mm"])
    return math.sqrt(R * R + 4 * t["floor_sigma_applied_px"] ** 2)


drawn = rows(f"{W}/white.csv")
frames = sorted({int(r["frame"]) for r in drawn})
check(frames == list(range(len(frames))) and len(frames) >= 3, f"white.csv has frames {frames}")

# 1 and 2: the ball, every frame.
worst_px, worst_rel = 0.0, 0.0
for r in drawn:
    if r["object"] != ball.get("name", "ball1"):
        continue
    t, R, tv = truth(int(r["frame"]))
    p, u = project(R, tv, [ball["x_mm"], ball["y_mm"], ball.get("radius_mm", 10)])
    d = math.hypot(float(r["screen_x_px"]) - p[0], float(r["screen_y_px"]) - p[1])
    worst_px = max(worst_px, d)
    rel = abs(float(r["r_px"]) - thin_lens_r(t, u)) / thin_lens_r(t, u)
    worst_rel = max(worst_rel, rel)
    print(f"     frame {r['frame']}: ball at ({r['screen_x_px']}, {r['screen_y_px']}) px, truth "
          f"({p[0]:.4f}, {p[1]:.4f}); depth {r['depth_mm']} mm, truth {u:.3f}; r {r['r_px']} px, thin lens "
          f"{thin_lens_r(t, u):.4f} px")
check(worst_px <= 0.5, f"ball's screen position: worst {worst_px:.4f} px from the truth pose's projection (<= 0.5)")
check(worst_rel <= 0.03, f"ball's r_px: worst {100 * worst_rel:.2f} % from the true lens's thin-lens r (<= 3 %)")


# 3: the card on the written frames.
def coverage(tag, frame):
    name = f"frame-{frame:04d}.png"
    return linear(f"{W}/{tag}-white/{name}") - linear(f"{W}/{tag}-black/{name}")


def solve_kernel(sharp, blurred, box, h):
    x0, y0, x1, y1 = box
    offsets = [(dy, dx) for dy in range(-h, h + 1) for dx in range(-h, h + 1)]
    a = np.stack([sharp[y0 - dy:y1 - dy, x0 - dx:x1 - dx].ravel() for dy, dx in offsets], axis=1)
    k, *_ = np.linalg.lstsq(a, blurred[y0:y1, x0:x1].ravel(), rcond=None)
    return k.reshape(2 * h + 1, 2 * h + 1)


def centroid(a):
    ys, xs = np.mgrid[0:a.shape[0], 0:a.shape[1]]
    return np.array([(a * xs).sum(), (a * ys).sum()]) / a.sum()


def polygon_centroid(pts):
    x, y = pts[:, 0], pts[:, 1]
    x1, y1 = np.roll(x, -1), np.roll(y, -1)
    cross = x * y1 - x1 * y
    area = cross.sum() / 2
    return np.array([((x + x1) * cross).sum(), ((y + y1) * cross).sum()]) / (6 * area)


card_rows = {int(r["frame"]): r for r in drawn if r["object"] == card.get("name", "card1")}
w, h = card["width_mm"], card["height_mm"]
corners = [[card["x_mm"] + sx * w / 2, card["y_mm"], z] for sx, z in ((-1, h), (1, h), (1, 0), (-1, 0))]
for frame in frames:
    r = card_rows[frame]
    if r["status"] == "lost":
        continue
    sharp, blurred = coverage("sharp", frame), coverage("blur", frame)
    _, R, tv = truth(frame)
    quad = np.array([project(R, tv, c)[0] for c in corners])
    x0, y0 = np.floor(quad.min(axis=0)).astype(int) - 12
    x1, y1 = np.ceil(quad.max(axis=0)).astype(int) + 13
    c_sharp = centroid(sharp[y0:y1, x0:x1]) + [x0, y0]
    c_true = polygon_centroid(quad)
    off = np.linalg.norm(c_sharp - c_true)
    check(off <= 0.3, f"frame {frame}: card's drawn centroid ({c_sharp[0]:.3f}, {c_sharp[1]:.3f}) px is {off:.3f} px "
                      f"from its true silhouette's ({c_true[0]:.3f}, {c_true[1]:.3f}) (<= 0.3)")
    m = np.array([float(r["motion_x_px"]), float(r["motion_y_px"])])
    L = np.linalg.norm(m)
    hk = int(math.ceil(L / 2 + 2 * float(r["r_px"]) + 2))
    k = solve_kernel(sharp, blurred, (x0 + hk, y0 + hk, x1 - hk, y1 - hk), hk)
    k /= k.sum()
    ys, xs = np.mgrid[-hk:hk + 1, -hk:hk + 1]
    mx, my = (k * xs).sum(), (k * ys).sum()
    cov = np.array([[(k * (xs - mx) ** 2).sum(), (k * (xs - mx) * (ys - my)).sum()],
                    [(k * (xs - mx) * (ys - my)).sum(), (k * (ys - my) ** 2).sum()]])
    vals, vecs = np.linalg.eigh(cov)
    across, along = vals[0], vals[1]
    r_measured = 2 * math.sqrt(max(across, 0))
    L_measured = math.sqrt(max(12 * (along - across), 0))
    axis = vecs[:, 1]
    r_csv = float(r["r_px"])
    tol_r = max(0.3, 0.05 * r_csv)
    check(abs(r_measured - r_csv) <= tol_r,
          f"frame {frame}: card's r on the frames {r_measured:.3f} px, CSV {r_csv:.3f} (within {tol_r:.2f})")
    tol_l = max(0.3, 0.05 * L)
    check(abs(L_measured - L) <= tol_l,
          f"frame {frame}: card's streak on the frames {L_measured:.3f} px, CSV {L:.3f} (within {tol_l:.2f})")
    if L > 1:
        angle = math.degrees(math.acos(min(1.0, abs(axis @ m) / L)))
        limit = math.degrees(math.atan2(tol_l, L / 2))
        check(angle <= limit, f"frame {frame}: streak direction {angle:.2f} deg off the CSV's (<= {limit:.2f})")
    check(math.hypot(mx, my) <= 0.3, f"frame {frame}: the kernel's centre at ({mx:.3f}, {my:.3f}) px (streak centred)")

if FAILS:
    print(f"{len(FAILS)} checks failed")
    sys.exit(1)
print("ok: ar_check")
