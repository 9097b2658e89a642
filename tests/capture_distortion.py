#!/usr/bin/env python3
"""capture_distortion.py place CALIB [Z_MM]  |  capture_distortion.py check CALIB DIST DIST_TWIN FLAT FLAT_TWIN [--db DB --tolerance-px 0.03 --tolerance-rel 0.03]

A virtual object's blur under lens distortion, found on captured frames without any of blurcue's code.

place: the levels that put the centres (Z_MM over the table: 0 for a card lying on it, half its height for one
standing) of a two-trial protocol's cards at the photo's principal point (trial 1's left card),
near a photo corner (trial 2's right card) and at the two places that sharing a y_mm makes (trial 1's right, trial
2's left): prints y_mm levels, left_x_mm and right_x_mm as JSON. CALIB's camera (its dist_coeffs) and pose, the
distortion undone by a fixed-point iteration of OpenCV's formula written here, the ray cut with the board's plane.

check: DIST holds the trial-NNNN.json / .png a `run --capture` wrote with CALIB (its camera with dist_coeffs), FLAT
the same protocol with the same calibration without them; DIST_TWIN and FLAT_TWIN each run's unblurred twin (blur 0,
the same geometry). For every object, the kernel that maps the twin onto the frame (tests/capture_kernel.py's least
squares, numpy only) gives the drawn blur's radius along x and y: 2 x the standard deviation of its x and y
marginals (the profile across a vertical and a horizontal edge), and across the two diagonals (its covariance along
(1, +-1) / sqrt(2)), which with x and y pin the ellipse's tilt too. The prediction is the Jacobian's: with J the
distortion map's Jacobian at the object's ideal (undistorted) place, by central finite differences of the formula
here, and r the object's round radius without distortion (FLAT's record, where the photo is the pinhole image), an
elliptical PSF of covariance r^2 / 4 J J^T has r_x = r |J row 0|, r_y = r |J row 1| and r_n = r |J^T n| across
a unit normal n. Exits 1 when a measured
radius is off the prediction by more than max(tolerance-px, tolerance-rel x r), when the distorted record's
r_x_screen_px / r_y_screen_px are, or when the object at the principal point (J = I there) is not round or not the
size it was without distortion, or when FLAT's own blur along x or y is not its record, within the same tolerance.
The round radius the trial JSON's r_screen_px and the
record (--db: the trials' r_left_px / r_right_px in photo px and their factors' r_*_screen_px) give must be r
sqrt(det J), the geometric mean of the principal radii (docs/distortion.md), within the same tolerance.
"""
import argparse
import glob
import json
import math
import os
import sqlite3
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from capture_kernel import linear, object_box, solve_kernel  # noqa: E402  (test code: numpy least squares, nothing of blurcue's)


def intrinsics(camera):
    """fx, fy, cx, cy of a camera.json (camera_matrix, else focal length over the pixel pitch, centre at W / 2, H / 2)."""
    if "camera_matrix" in camera:
        k = np.asarray(camera["camera_matrix"], dtype=float).reshape(-1)
        return k[0], k[4], k[2], k[5]
    pitch = camera["sensor_width_mm"] / camera["image_width_px"]
    f = camera["focal_length_mm"] / pitch
    return f, f, camera["image_width_px"] / 2.0, camera["image_height_px"] / 2.0


def distort_normalized(x, y, d):
    """OpenCV's radial + tangential model (k1 k2 p1 p2 [k3]) on normalized coordinates; d padded with zeros."""
    k1, k2, p1, p2, k3 = (list(d) + [0.0] * 5)[:5]
    if any(v != 0 for v in list(d)[5:]):
        raise SystemExit("capture_distortion: only k1 k2 p1 p2 k3 are written here")
    r2 = x * x + y * y
    radial = 1 + k1 * r2 + k2 * r2 * r2 + k3 * r2 ** 3
    return (x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x),
            y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y)


class Lens:
    def __init__(self, camera):
        self.fx, self.fy, self.cx, self.cy = intrinsics(camera)
        self.d = camera.get("dist_coeffs", [])

    def photo_of_ideal(self, u, v):
        x, y = distort_normalized((u - self.cx) / self.fx, (v - self.cy) / self.fy, self.d)
        return self.fx * x + self.cx, self.fy * y + self.cy

    def ideal_of_photo(self, u, v):
        """The ideal pixel the map sends to photo pixel (u, v): fixed-point iteration on the formula."""
        xd, yd = (u - self.cx) / self.fx, (v - self.cy) / self.fy
        x, y = xd, yd
        for _ in range(200):
            fx_, fy_ = distort_normalized(x, y, self.d)
            x, y = x + (xd - fx_), y + (yd - fy_)
        fx_, fy_ = distort_normalized(x, y, self.d)
        if math.hypot(fx_ - xd, fy_ - yd) > 1e-10:
            raise SystemExit(f"capture_distortion: photo pixel ({u}, {v}) is not undone by the iteration")
        return self.fx * x + self.cx, self.fy * y + self.cy

    def jacobian(self, u, v, h=1e-3):
        """d photo px / d ideal px at ideal pixel (u, v), central differences of step h px."""
        j = np.zeros((2, 2))
        for c, (du, dv) in enumerate(((h, 0), (0, h))):
            a = np.array(self.photo_of_ideal(u + du, v + dv))
            b = np.array(self.photo_of_ideal(u - du, v - dv))
            j[:, c] = (a - b) / (2 * h)
        return j


def rodrigues(rvec):
    r = np.asarray(rvec, dtype=float)
    theta = np.linalg.norm(r)
    if theta == 0:
        return np.eye(3)
    k = r / theta
    kx = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + math.sin(theta) * kx + (1 - math.cos(theta)) * kx @ kx


def board_point_of_photo(calib, u, v, z_mm=0.0):
    """The point (x, y mm) at height z_mm over the board's plane that photo pixel (u, v) sees."""
    lens = Lens(calib["camera"])
    ui, vi = lens.ideal_of_photo(u, v)
    ray = np.array([(ui - lens.cx) / lens.fx, (vi - lens.cy) / lens.fy, 1.0])
    rot = rodrigues(calib["pose"]["rvec"])
    t = np.asarray(calib["pose"]["tvec"], dtype=float)
    # camera point s ray = rot p + t: p = rot^T (s ray - t), its z = z_mm fixes s.
    rt = rot.T
    s = (z_mm + (rt @ t)[2]) / (rt @ ray)[2]
    p = rt @ (s * ray - t)
    return p[0], p[1]


def place(calib_path, z_mm):
    calib = json.load(open(calib_path))
    cam = calib["camera"]
    lens = Lens(cam)
    w, h = cam["image_width_px"], cam["image_height_px"]
    xc, yc = board_point_of_photo(calib, lens.cx, lens.cy, z_mm)
    # Across: towards the photo's right edge at the principal point's height; along: towards its top (the far side
    # of the table). Trial 2's right card, at both, is near the top right corner; every card stays in the photo with
    # and without the distortion (a barrel photo sees more of the table).
    xk, _ = board_point_of_photo(calib, 0.88 * w, lens.cy, z_mm)
    _, yk = board_point_of_photo(calib, lens.cx, 0.2 * h, z_mm)
    print(json.dumps({"y_mm": [round(yc, 2), round(yk, 2)], "left_x_mm": [round(xc, 2)], "right_x_mm": [round(xk, 2)]}))


def marginal_radii(k):
    """2 x the std of the kernel's x and y marginals, and its xy covariance (px^2)."""
    n = k.shape[0] // 2
    t = np.arange(-n, n + 1, dtype=float)
    total = k.sum()
    xs, ys = np.meshgrid(t, t)
    mx, my = (k * xs).sum() / total, (k * ys).sum() / total
    vxx = (k * (xs - mx) ** 2).sum() / total
    vyy = (k * (ys - my) ** 2).sum() / total
    vxy = (k * (xs - mx) * (ys - my)).sum() / total
    return 2 * math.sqrt(max(vxx, 0)), 2 * math.sqrt(max(vyy, 0)), vxy, total


def measure(blurred_dir, sharp_dir, name, o, r_hint):
    blurred = linear(os.path.join(blurred_dir, name + ".png"))
    sharp = linear(os.path.join(sharp_dir, name + ".png"))
    height, width = blurred.shape[:2]
    h = max(3, math.ceil(1.6 * r_hint) + 2)
    box = object_box(o, h, width, height)
    if box[2] - box[0] < 4 * h or box[3] - box[1] < 4 * h:
        raise SystemExit(f"BAD {name} {o['side']}: the object is not in the frame (box {box})")
    return marginal_radii(solve_kernel(sharp, blurred, box, h))


def screen_to_photo(frame, p):
    """A screen px of the frame back to the photo's px (the view: screen = s (photo + 0.5) - 0.5 + offset)."""
    s = frame["screen_px_per_photo_px"]
    x0, y0 = frame["photo_rect_px"][:2]
    return (p[0] - x0 + 0.5) / s - 0.5, (p[1] - y0 + 0.5) / s - 0.5


def check(args):
    calib = json.load(open(args.calib))
    lens = Lens(calib["camera"])
    if not lens.d or all(v == 0 for v in lens.d):
        raise SystemExit(f"capture_distortion: {args.calib} has no dist_coeffs")
    trials = sorted(glob.glob(os.path.join(args.dist, "trial-*.json")))
    if not trials:
        raise SystemExit(f"capture_distortion: no trial-*.json in {args.dist}")
    bad = checked = 0
    worst = 0.0
    centre_seen = False
    db = sqlite3.connect(args.db) if args.db else None
    for path in trials:
        name = os.path.basename(path)[:-5]
        frame = json.load(open(path))
        flat = json.load(open(os.path.join(args.flat, name + ".json")))
        for o in frame["objects"]:
            o0 = next(f for f in flat["objects"] if f["side"] == o["side"])
            r0 = o0["r_screen_px"]  # the round radius without distortion (J = I)
            ui, vi = lens.ideal_of_photo(*screen_to_photo(frame, o["center_px"]))
            j = lens.jacobian(ui, vi)
            pred_x, pred_y = r0 * np.linalg.norm(j[0]), r0 * np.linalg.norm(j[1])
            # Across the diagonals (edges at 45 degrees): 2 sqrt(n^T C n), n = (1, +-1) / sqrt(2); the measured ones
            # from the kernel's covariance. With x and y they pin all three terms of the ellipse, its tilt included.
            pred_d = [r0 * np.linalg.norm(j.T @ np.array([1.0, sign]) / math.sqrt(2)) for sign in (1, -1)]
            rx, ry, vxy, total = measure(args.dist, args.dist_twin, name, o, max(pred_x, pred_y))
            mean_var = (rx * rx + ry * ry) / 8
            rd = [2 * math.sqrt(max(0.0, mean_var + sign * vxy)) for sign in (1, -1)]
            fx, fy, _, _ = measure(args.flat, args.flat_twin, name, o0, r0)
            rho = math.hypot((ui - lens.cx) / lens.fx, (vi - lens.cy) / lens.fy)
            at_centre = math.hypot(ui - lens.cx, vi - lens.cy) < 1
            centre_seen |= at_centre

            def judge(label, value, want, scale):
                nonlocal bad, checked, worst
                limit = max(args.tolerance_px, args.tolerance_rel * scale)
                off = abs(value - want) > limit
                checked += 1
                bad += off
                worst = max(worst, abs(value - want) / limit)
                return f"{'BAD ' if off else ''}{label} {value:.4f} vs {want:.4f} (limit {limit:.3f})"

            # The round radius the record gives: the geometric mean of the principal radii, r sqrt(det J).
            stretch = math.sqrt(abs(np.linalg.det(j)))
            parts = [judge("shown r_x", rx, pred_x, pred_x), judge("shown r_y", ry, pred_y, pred_y),
                     judge("shown r across (1, 1)", rd[0], pred_d[0], pred_d[0]),
                     judge("shown r across (1, -1)", rd[1], pred_d[1], pred_d[1]),
                     judge("recorded r_x", o["r_x_screen_px"], pred_x, pred_x),
                     judge("recorded r_y", o["r_y_screen_px"], pred_y, pred_y),
                     judge("recorded round r", o["r_screen_px"], r0 * stretch, r0 * stretch)]
            if args.db:
                row = db.execute(f"SELECT r_{o['side']}_px, factors FROM trials WHERE trial_index = ?",
                                 (frame["trial_index"],)).fetchone()
                want = o0["r_camera_px"] * stretch
                parts += [judge("record's photo px", row[0], want, want),
                          judge("record's screen px", json.loads(row[1])[f"r_{o['side']}_screen_px"], r0 * stretch,
                                r0 * stretch)]
            parts += [judge("flat r_x", fx, r0, r0), judge("flat r_y", fy, r0, r0)]
            if at_centre:
                parts += [judge("centre r_x - r_y", rx - ry, 0, r0), judge("centre r_x vs flat", rx, fx, fx),
                          judge("centre r_y vs flat", ry, fy, fy)]
            print(f"{name} {o['side']} {o['kernel']}: ideal ({ui:.1f}, {vi:.1f}) px, rho {rho:.3f}, "
                  f"|J rows| {np.linalg.norm(j[0]):.4f} {np.linalg.norm(j[1]):.4f}, r without distortion {r0:.4f}; "
                  + "; ".join(parts) + f"; kernel sum {total:.4f}")
    if not centre_seen:
        print("BAD no object at the principal point")
        bad += 1
    print(f"{checked} radii judged, {bad} off; the largest error is {worst:.2f} of its limit")
    return 1 if bad else 0


def main():
    if len(sys.argv) in (3, 4) and sys.argv[1] == "place":
        place(sys.argv[2], float(sys.argv[3]) if len(sys.argv) == 4 else 0.0)
        return 0
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[1])
    ap.add_argument("mode", choices=["check"])
    ap.add_argument("calib")
    ap.add_argument("dist")
    ap.add_argument("dist_twin")
    ap.add_argument("flat")
    ap.add_argument("flat_twin")
    ap.add_argument("--db", help="the distorted run's SQLite record: its trials' round radii are checked too")
    ap.add_argument("--tolerance-px", type=float, default=0.03)
    ap.add_argument("--tolerance-rel", type=float, default=0.03)
    return check(ap.parse_args())


if __name__ == "__main__":
    sys.exit(main())
