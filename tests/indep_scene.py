#!/usr/bin/python3
"""An independent generator of board scenes and moving-camera takes with known blur (issues 25 and 27).

It shares no code with blurcue (no src/synth, no OpenCV): numpy, scipy and PIL only. The board is written here from
the documented facts of core/board.h: a COLS x ROWS checkerboard of square_mm squares lying on a table, board frame
x along the COLS squares (left to right as the camera sees it), y away from the camera, z up; the square at column 0,
row 0 black; edge k (1 = nearest) is the line y = (k - 1) * square_mm, section j spans x in [(j - 1), j] * square_mm.

Optics (docs/independent-truth.md says why each step is as it is):
  * a pinhole camera with explicit intrinsics (camera_matrix in camera.json; pixel centres at integer coordinates)
    and a thin lens of focal length f, f-number N, focus distance s;
  * the sharp scene on a 1/SS px canvas in the *undistorted* image: board coordinates of each sub-pixel by the
    plane's homography, each board line anti-aliased by a linear ramp one sub-pixel wide across the line (the same
    second moment as the sub-pixel's box);
  * the lens floor: a discrete Gaussian (taps on the sub-pixel grid) over the whole canvas;
  * defocus at each sub-pixel's depth u: thin-lens radius R = D f |u - s| / (u (s - f)) / 2 / pitch, a disc of
    radius R or a Gaussian of std R / 2, made by blurring with a ladder of discrete kernels and mixing, per sub-pixel,
    the two whose variances bracket R^2 / 4 (a mixture's variance is the weighted sum of its parts');
  * radial/tangential distortion as OpenCV's calib3d model (x'' = x' (1 + k1 r^2 + k2 r^4 + k3 r^6) + 2 p1 x'y' +
    p2 (r^2 + 2 x'^2), y'' likewise): the blurred undistorted canvas is sampled at each distorted sub-pixel's
    undistorted position by a cubic B-spline (whose interpolating kernel has zero second moment);
  * the pixel aperture: the mean of SS x SS sub-pixels; vignetting (cos^4 shape, 1 - vignetting at the corner),
    Gaussian read + shot noise in linear light, sRGB encoding to 8 bits, JPEG through PIL.

Truth per section (at its midpoint): r = 2 sqrt(var), var the variance across the edge of the optical LSF applied:
the mixed defocus kernels' and the floor taps' variances computed from the arrays, scaled by the distortion's
stretch across the edge (|J^T n|^2, J the distortion's Jacobian, n the distorted edge's normal); pixel aperture
excluded.

Usage:
  indep_scene.py still --out DIR [options]        DIR/scene.png, camera.json, truth.json
  indep_scene.py take --out DIR [--frames 12]     DIR/frame-%04d.png, truth-%04d.json, camera.json, take.json
"""
import argparse
import io
import json
import math
import os
import sys
import time

import numpy as np
from PIL import Image
from scipy import ndimage, signal
from scipy.spatial.transform import Rotation

GENERATOR = "tests/indep_scene.py"


# ---------------------------------------------------------------------------------------------------------------
# Camera, board, pose.

class Camera:
    """A thin-lens camera with explicit intrinsics; dist = [k1, k2, p1, p2, k3] (OpenCV order)."""

    def __init__(self, width=1148, height=764, focal_mm=21.0, f_number=5.6, sensor_width_mm=23.4, dist=None):
        self.w, self.h = int(width), int(height)
        self.f = float(focal_mm)
        self.n = float(f_number)
        self.pitch = sensor_width_mm / self.w  # mm per px (square pixels)
        self.sensor_w = sensor_width_mm
        self.sensor_h = self.h * self.pitch
        self.fx = self.fy = self.f / self.pitch
        self.cx, self.cy = (self.w - 1) / 2.0, (self.h - 1) / 2.0
        d = list(dist or [])
        self.dist = (d + [0.0] * 5)[:5]

    @property
    def aperture_mm(self):
        return self.f / self.n

    def distorted(self):
        return any(v != 0 for v in self.dist)

    def to_json(self):
        j = {"focal_length_mm": self.f, "f_number": self.n, "sensor_width_mm": self.sensor_w,
             "sensor_height_mm": self.sensor_h, "image_width_px": self.w, "image_height_px": self.h,
             "camera_matrix": [[self.fx, 0.0, self.cx], [0.0, self.fy, self.cy], [0.0, 0.0, 1.0]]}
        if self.distorted():
            j["dist_coeffs"] = list(self.dist)
        return j

    def defocus_r_px(self, u_mm, focus_mm):
        """Thin-lens blur-circle radius in px of the undistorted image for depth u (both sides of focus)."""
        u = np.asarray(u_mm, dtype=np.float64)
        if math.isinf(focus_mm):
            c = self.aperture_mm * self.f / (u - self.f)
        else:
            c = self.aperture_mm * self.f * np.abs(u - focus_mm) / (u * (focus_mm - self.f))
        return c / 2.0 / self.pitch

    # OpenCV's model on normalized coordinates (x', y') -> (x'', y'').
    def distort_norm(self, x, y):
        k1, k2, p1, p2, k3 = self.dist
        r2 = x * x + y * y
        radial = 1 + r2 * (k1 + r2 * (k2 + r2 * k3))
        return (x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x),
                y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y)

    def undistort_norm(self, xd, yd, iterations=40):
        """Inverse of distort_norm by fixed-point iteration (converges for the mild distortions used here)."""
        k1, k2, p1, p2, k3 = self.dist
        x, y = xd.copy(), yd.copy()
        for _ in range(iterations):
            r2 = x * x + y * y
            radial = 1 + r2 * (k1 + r2 * (k2 + r2 * k3))
            x = (xd - 2 * p1 * x * y - p2 * (r2 + 2 * x * x)) / radial
            y = (yd - p1 * (r2 + 2 * y * y) - 2 * p2 * x * y) / radial
        return x, y

    def distorted_px(self, u, v):
        """Undistorted pixel coordinates -> distorted pixel coordinates."""
        xd, yd = self.distort_norm((u - self.cx) / self.fx, (v - self.cy) / self.fy)
        return xd * self.fx + self.cx, yd * self.fy + self.cy


class Board:
    def __init__(self, cols=7, rows=10, square_mm=25.0):
        self.cols, self.rows, self.sq = int(cols), int(rows), float(square_mm)
        self.width, self.length = self.cols * self.sq, self.rows * self.sq


def pose_looking_at(board, tilt_deg, edge1_u_mm, lateral_mm=0.0, roll_deg=0.0):
    """Board -> camera rotation R and translation t (p_cam = R p_board + t), OpenCV's convention.

    The camera is pitched down by tilt from the table (90: looking straight down, the board fronto-parallel), turned
    by roll about its optical axis, its axis through the point `lateral_mm` left of the board's centre (so the board
    appears shifted right by lateral_mm), at the distance that puts edge 1's midpoint at depth edge1_u_mm."""
    th = math.radians(tilt_deg)
    x_cam = np.array([1.0, 0.0, 0.0])
    z_cam = np.array([0.0, math.cos(th), -math.sin(th)])
    y_cam = np.cross(z_cam, x_cam)
    r_tilt = np.vstack([x_cam, y_cam, z_cam])  # rows: camera axes in the board frame
    c, s = math.cos(math.radians(roll_deg)), math.sin(math.radians(roll_deg))
    r_roll = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    R = r_roll @ r_tilt
    aim = np.array([board.width / 2 - lateral_mm, board.length / 2, 0.0])
    edge1_mid = np.array([board.width / 2, 0.0, 0.0])
    d = edge1_u_mm - (edge1_mid - aim) @ R[2]
    centre = aim - d * R[2]
    return R, -R @ centre


# ---------------------------------------------------------------------------------------------------------------
# Kernels (on the sub-pixel grid; variances are per axis, in sub-pixels^2).

def gaussian_taps(sigma_sub):
    if sigma_sub <= 0:
        return np.array([1.0])
    reach = max(1, int(math.ceil(4 * sigma_sub)))
    x = np.arange(-reach, reach + 1, dtype=np.float64)
    k = np.exp(-0.5 * (x / sigma_sub) ** 2)
    return k / k.sum()


def taps_variance(taps):
    x = np.arange(len(taps)) - (len(taps) - 1) / 2
    return float((taps * x * x).sum())


def disc_kernel(radius_sub, oversample=9):
    """A disc of radius `radius_sub` sub-pixels, each cell weighted by its covered area (oversample^2 points)."""
    if radius_sub <= 0:
        return np.ones((1, 1))
    reach = int(math.ceil(radius_sub))
    o = (np.arange(oversample) + 0.5) / oversample - 0.5
    x = np.arange(-reach, reach + 1, dtype=np.float64)
    xx = (x[:, None] + o[None, :]).reshape(-1)
    inside = (xx[:, None] ** 2 + xx[None, :] ** 2) <= radius_sub ** 2
    n = len(x)
    k = inside.reshape(n, oversample, n, oversample).sum(axis=(1, 3)).astype(np.float64)
    return k / k.sum()


def gaussian_kernel2d(sigma_sub):
    t = gaussian_taps(sigma_sub)
    return np.outer(t, t)


def kernel_variance(k):
    """Per-axis variance (across a horizontal edge: along rows) of a centred 2-D kernel, sub-pixels^2."""
    y = np.arange(k.shape[0]) - (k.shape[0] - 1) / 2
    return float((k.sum(axis=1) * y * y).sum())


def blur_ladder(r_max_px, ss, psf):
    """Radii (px) of the kernels mixed for the defocus: 0, 0.1 .. 1 px in 0.1 steps, then 6 % apart."""
    radii = [0.0]
    r = 0.1
    while radii[-1] < r_max_px:
        radii.append(r)
        r = r + 0.1 if r < 0.999 else r * 1.06
    kernels = [disc_kernel(r * ss) if psf == "disc" else gaussian_kernel2d(r * ss / 2) for r in radii]
    variances = np.array([kernel_variance(k) for k in kernels])
    return radii, kernels, variances


def mix_weights(target_var, variances):
    """Index i and weight a of the upper kernel: (1 - a) K_i + a K_{i+1} has variance target_var (clipped)."""
    v = np.clip(target_var, variances[0], variances[-1])
    i = np.clip(np.searchsorted(variances, v, side="right") - 1, 0, len(variances) - 2)
    a = (v - variances[i]) / (variances[i + 1] - variances[i])
    return i, np.clip(a, 0.0, 1.0)


# ---------------------------------------------------------------------------------------------------------------
# Rendering.

def _homography_board(cam, R, t, u, v):
    """Board (X, Y), depth z and dX/du, dX/dv, dY/du, dY/dv for undistorted pixel coords (u: row vector, v: column).

    The ray through (u, v) is d = ((u - cx)/fx, (v - cy)/fy, 1) in the camera frame; in the board frame it leaves
    C = -R^T t along R^T d and meets z = 0 at s = -C_z / (R^T d)_z; the depth (camera z) is s since d_z = 1."""
    Rt = R.T
    C = -Rt @ t
    xn = (u - cam.cx) / cam.fx
    yn = (v - cam.cy) / cam.fy
    db = [Rt[i, 0] * xn + Rt[i, 1] * yn + Rt[i, 2] for i in range(3)]  # broadcast to (rows, cols)
    dz = db[2]
    if np.any(dz >= 0):
        raise ValueError("the view reaches the horizon: some rays miss the table (raise tilt or lower the board)")
    s = -C[2] / dz
    X = C[0] + s * db[0]
    Y = C[1] + s * db[1]
    # Derivatives (per px): s = -C_z / dz, d s / du = C_z Rt[2,0] / (fx dz^2) = -s Rt[2,0] / (fx dz).
    ds_du = -s * Rt[2, 0] / (cam.fx * dz)
    ds_dv = -s * Rt[2, 1] / (cam.fy * dz)
    dX_du = ds_du * db[0] + s * Rt[0, 0] / cam.fx
    dX_dv = ds_dv * db[0] + s * Rt[0, 1] / cam.fy
    dY_du = ds_du * db[1] + s * Rt[1, 0] / cam.fx
    dY_dv = ds_dv * db[1] + s * Rt[1, 1] / cam.fy
    return X, Y, s, (dX_du, dX_dv, dY_du, dY_dv)


def _ramp_sign(coord, grad, n_cells, square, ss):
    """Checker sign (+1 on even cells) of a board coordinate, anti-aliased: a linear ramp 1 sub-px wide across each
    inner line. At the board's outer lines the inside cell's sign is kept (the board's own coverage ramps there)."""
    line = np.clip(np.rint(coord / square), 0, n_cells)
    d_sub = (coord - line * square) / grad * ss  # signed distance from the line in sub-pixels
    sign_right = np.where(line % 2 == 0, 1.0, -1.0)
    ramp = sign_right * np.clip(2 * d_sub, -1.0, 1.0)
    outer_first = np.ones_like(coord)
    outer_last = np.full_like(coord, 1.0 if (n_cells - 1) % 2 == 0 else -1.0)
    return np.where(line == 0, outer_first, np.where(line == n_cells, outer_last, ramp))


def _inside(coord, grad, extent, ss):
    a = np.clip(0.5 + coord / grad * ss, 0.0, 1.0)
    b = np.clip(0.5 + (extent - coord) / grad * ss, 0.0, 1.0)
    return a * b


def render_linear(cam, board, R, t, o):
    """Linear-light image (h x w, float64) and the per-section truth. `o` is a dict of optics and flaws."""
    ss = int(o["ss"])
    focus = float(o["focus_mm"])
    psf = o["psf"]
    floor_taps = gaussian_taps(o["floor_sigma_px"] * ss)
    floor_var_sub = taps_variance(floor_taps)
    floor_reach = len(floor_taps) // 2

    # Where the distorted image's sub-pixels come from in the undistorted image (pixel grid, then interpolated).
    if cam.distorted():
        pu = np.arange(-1, cam.w + 1, dtype=np.float64)
        pv = np.arange(-1, cam.h + 1, dtype=np.float64)
        xu, yu = cam.undistort_norm(((pu - cam.cx) / cam.fx)[None, :] + 0 * pv[:, None],
                                    ((pv - cam.cy) / cam.fy)[:, None] + 0 * pu[None, :])
        und_u, und_v = xu * cam.fx + cam.cx, yu * cam.fy + cam.cy
        lo_u, hi_u, lo_v, hi_v = und_u.min(), und_u.max(), und_v.min(), und_v.max()
    else:
        lo_u, hi_u, lo_v, hi_v = -0.5, cam.w - 0.5, -0.5, cam.h - 0.5

    # A first look at the depths (pixel grid) for the largest radius, hence the ladder and the canvas margin.
    gu = np.linspace(lo_u, hi_u, 64)[None, :]
    gv = np.linspace(lo_v, hi_v, 64)[:, None]
    _, _, z_coarse, _ = _homography_board(cam, R, t, gu, gv)
    r_max = float(np.max(cam.defocus_r_px(z_coarse, focus))) * 1.15 + 0.2
    radii, kernels, variances = blur_ladder(r_max, ss, psf)
    reach = max(k.shape[0] // 2 for k in kernels)
    margin = int(math.ceil((reach + floor_reach) / ss)) + 3  # px

    # The canvas: sub-pixel centres aligned with the image's (u0 + (i + 0.5) / ss, u0 = whole px - 0.5).
    u0 = math.floor(lo_u + 0.5) - 0.5 - margin
    v0 = math.floor(lo_v + 0.5) - 0.5 - margin
    nu = int(math.ceil((hi_u - u0) + margin)) * ss
    nv = int(math.ceil((hi_v - v0) + margin)) * ss
    u = (u0 + (np.arange(nu) + 0.5) / ss)[None, :]
    v = (v0 + (np.arange(nv) + 0.5) / ss)[:, None]
    X, Y, z, (xu_, xv_, yu_, yv_) = _homography_board(cam, R, t, u, v)
    gX = np.hypot(xu_, xv_)  # mm per px across a line of constant X
    gY = np.hypot(yu_, yv_)
    del xu_, xv_, yu_, yv_
    sx = _ramp_sign(X, gX, board.cols, board.sq, ss)
    sy = _ramp_sign(Y, gY, board.rows, board.sq, ss)
    cover = _inside(X, gX, board.width, ss) * _inside(Y, gY, board.length, ss)
    del gX, gY
    board_value = o["black"] * (1 + sx * sy) / 2 + o["white"] * (1 - sx * sy) / 2
    del sx, sy
    # The table: a smooth, low-contrast grain (periods of 40 mm and more) in board coordinates.
    table = o["table"] * (1 + 0.05 * np.sin(2 * np.pi * X / 61 + 0.3 * np.sin(2 * np.pi * Y / 170))
                          + 0.03 * np.sin(2 * np.pi * (0.6 * X + Y) / 230 + 1.0))
    sharp = (cover * board_value + (1 - cover) * table).astype(np.float32)
    del board_value, table, cover, X, Y

    # Floor first: spatially invariant, so it commutes with the gather of the defocus mixture.
    if floor_reach > 0:
        sharp = ndimage.convolve1d(sharp, floor_taps, axis=0, mode="nearest")
        sharp = ndimage.convolve1d(sharp, floor_taps, axis=1, mode="nearest")

    # Defocus: per sub-pixel target variance R^2/4 (disc: radius R; Gaussian: std R/2), mixed from the ladder.
    target = (cam.defocus_r_px(z, focus) * ss) ** 2 / 4.0
    del z
    idx, a = mix_weights(target, variances)
    del target
    out = np.zeros_like(sharp)
    for k, kern in enumerate(kernels):
        # Each level serves up to two bands of rows (either side of focus): convolve each run of rows on its own.
        used = np.nonzero(((idx == k) | (idx == k - 1)).any(axis=1))[0]
        if len(used) == 0:
            continue
        breaks = np.nonzero(np.diff(used) > 1)[0]
        kern32 = kern.astype(np.float32)
        kr = kern.shape[0] // 2
        for r0, r1 in zip(np.r_[used[0], used[breaks + 1]], np.r_[used[breaks] + 1, used[-1] + 1]):
            w = (np.where(idx[r0:r1] == k, 1 - a[r0:r1], 0.0) +
                 np.where(idx[r0:r1] == k - 1, a[r0:r1], 0.0)).astype(np.float32)
            if kr == 0:
                out[r0:r1] += w * sharp[r0:r1]
                continue
            p0, p1 = max(0, r0 - kr), min(sharp.shape[0], r1 + kr)
            blurred = signal.fftconvolve(sharp[p0:p1], kern32, mode="same")
            out[r0:r1] += w * blurred[r0 - p0:r1 - p0]
    del sharp, idx, a

    # To the distorted image's sub-pixels, then the pixel aperture.
    if cam.distorted():
        su = (np.arange(cam.w * ss) + 0.5) / ss - 0.5  # distorted sub-pixel centres, px
        sv = (np.arange(cam.h * ss) + 0.5) / ss - 0.5
        # Undistorted position of each: cubic interpolation of the pixel-grid map (smooth to 1e-5 px).
        qu = (su + 1)[None, :] + 0 * sv[:, None]
        qv = (sv + 1)[:, None] + 0 * su[None, :]
        map_u = ndimage.map_coordinates(und_u, [qv, qu], order=3, mode="nearest")
        map_v = ndimage.map_coordinates(und_v, [qv, qu], order=3, mode="nearest")
        del qu, qv
        sub = ndimage.map_coordinates(out, [(map_v - v0) * ss - 0.5, (map_u - u0) * ss - 0.5], order=3,
                                      mode="nearest")
        del map_u, map_v
    else:
        i0 = int(round((-0.5 - v0) * ss))
        j0 = int(round((-0.5 - u0) * ss))
        sub = out[i0:i0 + cam.h * ss, j0:j0 + cam.w * ss]
    linear = sub.reshape(cam.h, ss, cam.w, ss).mean(axis=(1, 3))

    if o["vignetting"] > 0:
        px = np.arange(cam.w, dtype=np.float64)[None, :] + 0 * np.arange(cam.h)[:, None]
        py = np.arange(cam.h, dtype=np.float64)[:, None] + 0 * np.arange(cam.w)[None, :]
        xn, yn = (px - cam.cx) / cam.fx, (py - cam.cy) / cam.fy
        if cam.distorted():
            xn, yn = cam.undistort_norm(xn, yn)
        cos4 = 1.0 / (1 + xn * xn + yn * yn) ** 2
        corner = cos4.min()
        linear *= 1 - o["vignetting"] * (1 - cos4) / (1 - corner)

    truth = section_truth(cam, board, R, t, focus, variances, floor_var_sub, ss)
    meta = {"blur_levels_px": radii, "floor_sigma_applied_px": math.sqrt(floor_var_sub) / ss,
            "canvas_sub_px": [int(nv), int(nu)], "r_max_px": r_max}
    return linear, truth, meta


def section_truth(cam, board, R, t, focus, variances, floor_var_sub, ss):
    """Per section: depth of its midpoint and r = 2 x the std across the edge of the LSF applied there (px)."""
    out = []
    for e in range(1, board.rows + 2):
        for s in range(1, board.cols + 1):
            y = (e - 1) * board.sq
            ends = np.array([[(s - 1) * board.sq, y, 0.0], [s * board.sq, y, 0.0]])
            mid = np.array([(s - 0.5) * board.sq, y, 0.0])
            pc = R @ mid + t
            u_mm = float(pc[2])
            defocus = float(cam.defocus_r_px(u_mm, focus))
            i, a = mix_weights(np.array([(defocus * ss) ** 2 / 4.0]), variances)
            var_sub = (1 - a[0]) * variances[i[0]] + a[0] * variances[i[0] + 1] + floor_var_sub
            var_px = var_sub / ss ** 2
            if cam.distorted():
                # The LSF's variance across the distorted edge: (|J^T n|^2) x the undistorted one; the canvas's
                # sub-pixel ramp (1 / (12 ss^2) undistorted) is stretched alike while the sub-pixel comb of the
                # pixel aperture ((ss^2 - 1) / (12 ss^2)) is not: their sum differs from the 1/12 removed by
                # (|J^T n|^2 - 1) / (12 ss^2).
                def und_px(p):
                    q = R @ p + t
                    return np.array([cam.fx * q[0] / q[2] + cam.cx, cam.fy * q[1] / q[2] + cam.cy])
                um = und_px(mid)
                h = 1e-3
                J = np.empty((2, 2))
                for k in range(2):
                    dp = np.zeros(2)
                    dp[k] = h
                    plus = np.array(cam.distorted_px(*(um + dp)))
                    minus = np.array(cam.distorted_px(*(um - dp)))
                    J[:, k] = (plus - minus) / (2 * h)
                e_u = und_px(ends[1]) - und_px(ends[0])
                e_d = J @ e_u
                n_d = np.array([-e_d[1], e_d[0]]) / np.hypot(*e_d)
                stretch2 = float(np.sum((J.T @ n_d) ** 2))
                var_px = var_px * stretch2 + (stretch2 - 1) / (12.0 * ss ** 2)
            out.append({"edge": e, "section": s, "u_mm": u_mm, "r_px": 2 * math.sqrt(max(var_px, 0.0)),
                        "defocus_r_px": defocus, "flawed": False})
    return out


# ---------------------------------------------------------------------------------------------------------------
# Sensor, encoding, files.

def srgb_encode8(linear):
    v = np.clip(linear, 0.0, 1.0)
    s = np.where(v <= 0.0031308, 12.92 * v, 1.055 * np.power(v, 1 / 2.4) - 0.055)
    return np.rint(255 * s).astype(np.uint8)


def srgb_decode8(img8):
    s = img8.astype(np.float64) / 255
    return np.where(s <= 0.04045, s / 12.92, ((s + 0.055) / 1.055) ** 2.4)


def finish(linear, o, rng):
    """Noise (read noise of std `noise`, plus shot noise as large at white), sRGB, JPEG: RGB uint8."""
    n = o["noise"]
    if n > 0:
        std = np.sqrt(n * n + n * n * np.clip(linear, 0, None) / o["white"])
        linear = linear + std * rng.standard_normal(linear.shape)
    img = Image.fromarray(srgb_encode8(linear), mode="L").convert("RGB")
    if o["jpeg"] > 0:
        buf = io.BytesIO()
        img.save(buf, format="JPEG", quality=int(o["jpeg"]))
        buf.seek(0)
        img = Image.open(buf).convert("RGB")
    return img


def truth_json(cam, board, R, t, focus, o, sections, meta, extra=None):
    rvec = Rotation.from_matrix(R).as_rotvec()
    j = {"generator": GENERATOR,
         "camera": cam.to_json(),
         "board": {"cols": board.cols, "rows": board.rows, "square_mm": board.sq},
         "pose": {"rvec": [float(x) for x in rvec], "tvec": [float(x) for x in t],
                  "rotation": [[float(x) for x in row] for row in R],
                  "convention": "board frame (mm) -> camera (x right, y down, z forward), OpenCV"},
         "focus_mm": focus if math.isfinite(focus) else None,
         "focus_at_infinity": math.isinf(focus),
         "aperture_mm": cam.aperture_mm, "pixel_pitch_mm": cam.pitch,
         "psf": o["psf"], "options": o,
         "r_unit": "px of the (distorted) image, 2 x std across the edge of the optical LSF applied (defocus kernels "
                   "mixed there and the floor taps, from their arrays; distortion's stretch), pixel area excluded",
         "floor_sigma_applied_px": meta["floor_sigma_applied_px"],
         "blur_levels_px": meta["blur_levels_px"],
         "sections": sections, "flaws": []}
    j.update(extra or {})
    return j


def write_json(path, obj):
    tmp = str(path) + ".tmp"
    with open(tmp, "w") as f:
        json.dump(obj, f, indent=1)
    os.replace(tmp, path)


def optics_options(args):
    return {"ss": args.supersample, "psf": args.psf, "floor_sigma_px": args.floor_sigma_px,
            "focus_mm": float(args.focus_mm), "vignetting": args.vignetting, "noise": args.noise,
            "jpeg": args.jpeg_quality, "white": 0.80, "black": 0.04, "table": 0.30}


def camera_from_args(args):
    dist = [args.k1, args.k2, 0.0, 0.0, 0.0]
    return Camera(args.width, args.height, args.focal_mm, args.f_number, args.sensor_width_mm, dist)


def render_still(args):
    cam, board = camera_from_args(args), Board(args.cols, args.rows, args.square_mm)
    o = optics_options(args)
    R, t = pose_looking_at(board, args.tilt_deg, args.edge1_u_mm, args.lateral_mm, args.roll_deg)
    linear, sections, meta = render_linear(cam, board, R, t, o)
    img = finish(linear, o, np.random.default_rng(args.seed))
    os.makedirs(args.out, exist_ok=True)
    img.save(os.path.join(args.out, "scene.png"))
    write_json(os.path.join(args.out, "camera.json"), cam.to_json())
    write_json(os.path.join(args.out, "truth.json"), truth_json(cam, board, R, t, o["focus_mm"], o, sections, meta))
    return sections


def render_take(args):
    cam, board = camera_from_args(args), Board(args.cols, args.rows, args.square_mm)
    o = optics_options(args)
    os.makedirs(args.out, exist_ok=True)
    write_json(os.path.join(args.out, "camera.json"), cam.to_json())
    per_frame = []
    for i in range(args.frames):
        f = i / (args.frames - 1) if args.frames > 1 else 0.0
        u1 = args.u_start_mm + f * (args.u_end_mm - args.u_start_mm)
        lat = args.lateral_start_mm + f * (args.lateral_end_mm - args.lateral_start_mm)
        R, t = pose_looking_at(board, args.tilt_deg, u1, lat, args.roll_deg)
        t0 = time.time()
        linear, sections, meta = render_linear(cam, board, R, t, o)
        img = finish(linear, o, np.random.default_rng([args.seed, i]))
        img.save(os.path.join(args.out, "frame-%04d.png" % i))
        extra = {"take": {"frame": i, "frames": args.frames, "time_s": i / args.fps, "fps": args.fps}}
        write_json(os.path.join(args.out, "truth-%04d.json" % i),
                   truth_json(cam, board, R, t, o["focus_mm"], o, sections, meta, extra))
        per_frame.append({"frame": i, "edge1_u_mm": u1, "lateral_mm": lat})
        if not args.quiet:
            print("frame %d/%d: edge 1 at %.1f mm, r %.2f-%.2f px (%.1f s)" % (
                i + 1, args.frames, u1, min(s["r_px"] for s in sections), max(s["r_px"] for s in sections),
                time.time() - t0), flush=True)
    write_json(os.path.join(args.out, "take.json"),
               {"generator": GENERATOR, "frames": args.frames, "fps": args.fps, "frame_pattern": "frame-%04d.png",
                "focus_mm": o["focus_mm"], "floor_sigma_px": o["floor_sigma_px"], "per_frame": per_frame})


def parse(argv):
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = p.add_subparsers(dest="what", required=True)
    for name in ("still", "take"):
        q = sub.add_parser(name)
        q.add_argument("--out", required=True)
        q.add_argument("--width", type=int, default=1148)
        q.add_argument("--height", type=int, default=764)
        q.add_argument("--focal-mm", type=float, default=21.0)
        q.add_argument("--f-number", type=float, default=5.6)
        q.add_argument("--sensor-width-mm", type=float, default=23.4)
        q.add_argument("--k1", type=float, default=0.0)
        q.add_argument("--k2", type=float, default=0.0)
        q.add_argument("--cols", type=int, default=7)
        q.add_argument("--rows", type=int, default=10)
        q.add_argument("--square-mm", type=float, default=25.0)
        q.add_argument("--tilt-deg", type=float, default=38.0)
        q.add_argument("--roll-deg", type=float, default=0.0)
        q.add_argument("--psf", choices=("disc", "gaussian"), default="disc")
        q.add_argument("--floor-sigma-px", type=float, default=0.35)
        q.add_argument("--focus-mm", type=float, default=450.0)
        q.add_argument("--vignetting", type=float, default=0.0)
        q.add_argument("--noise", type=float, default=0.0)
        q.add_argument("--jpeg-quality", type=int, default=0)
        q.add_argument("--supersample", type=int, default=4)
        q.add_argument("--seed", type=int, default=1)
        q.add_argument("--quiet", action="store_true")
    s = sub.choices["still"]
    s.add_argument("--edge1-u-mm", type=float, default=342.3)
    s.add_argument("--lateral-mm", type=float, default=0.0)
    k = sub.choices["take"]
    k.add_argument("--frames", type=int, default=12)
    k.add_argument("--fps", type=float, default=30.0)
    k.add_argument("--u-start-mm", type=float, default=440.0)
    k.add_argument("--u-end-mm", type=float, default=360.0)
    k.add_argument("--lateral-start-mm", type=float, default=-25.0)
    k.add_argument("--lateral-end-mm", type=float, default=25.0)
    return p.parse_args(argv)


def keep_freed_memory():
    """Ask glibc to serve large arrays from the heap and keep it (no mmap/munmap per temporary): the canvas's
    100 MB temporaries otherwise cost as much kernel time (page faults) as the arithmetic. Optional: skipped where
    there is no glibc."""
    try:
        import ctypes
        libc = ctypes.CDLL("libc.so.6")
        m_trim_threshold, m_mmap_max = -1, -4
        libc.mallopt(m_mmap_max, 0)
        libc.mallopt(m_trim_threshold, 2 ** 30)
    except (OSError, AttributeError):
        pass


def validate(args):
    """The first option outside what the generator can render, as 'name: must be ..., got value'; None when fine."""
    checks = [("--supersample", args.supersample, 1 <= args.supersample <= 16, "in [1, 16]"),
              ("--tilt-deg", args.tilt_deg, 0 < args.tilt_deg <= 90, "in (0, 90]"),
              ("--focus-mm", args.focus_mm, args.focus_mm > args.focal_mm, "beyond the focal length (or inf)"),
              ("--f-number", args.f_number, args.f_number > 0, "> 0"),
              ("--floor-sigma-px", args.floor_sigma_px, 0 <= args.floor_sigma_px <= 20, "in [0, 20] px"),
              ("--vignetting", args.vignetting, 0 <= args.vignetting <= 0.9, "in [0, 0.9]"),
              ("--noise", args.noise, 0 <= args.noise <= 1, "in [0, 1] (linear units)"),
              ("--jpeg-quality", args.jpeg_quality, 0 <= args.jpeg_quality <= 100, "0 (none) or 1..100"),
              ("--width", args.width, 32 <= args.width <= 20000, "in [32, 20000] px"),
              ("--height", args.height, 32 <= args.height <= 20000, "in [32, 20000] px")]
    if args.what == "take":
        checks.append(("--frames", args.frames, 1 <= args.frames <= 10000, "in [1, 10000]"))
    for name, value, ok, rule in checks:
        if not ok or (isinstance(value, float) and math.isnan(value)):
            return "%s: must be %s, got %s" % (name, rule, value)
    return None


def main(argv):
    keep_freed_memory()
    args = parse(argv)
    problem = validate(args)
    if problem:
        print("indep_scene.py: " + problem, file=sys.stderr)
        return 2
    t0 = time.time()
    try:
        return run(args, t0)
    except ValueError as e:  # a view that cannot be rendered (the horizon in view): one line, exit 3
        print("indep_scene.py: %s" % e, file=sys.stderr)
        return 3


def run(args, t0):
    if args.what == "still":
        sections = render_still(args)
        if not args.quiet:
            print("wrote %s/scene.png: r %.2f-%.2f px (%.1f s)" % (
                args.out, min(s["r_px"] for s in sections), max(s["r_px"] for s in sections), time.time() - t0))
    else:
        render_take(args)
        if not args.quiet:
            print("wrote %d frames to %s (%.1f s)" % (args.frames, args.out, time.time() - t0))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
