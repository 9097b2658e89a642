#!/usr/bin/env python3
"""capture_streak_sim.py BLURRED SHARP: is a captured streaked frame what its record says, or is the solve biased?

For every object of BLURRED's trial-NNNN.json (a --capture folder of moving objects) against SHARP (its unblurred
twin): tests/capture_kernel.py's solve on the captured frame, and the same solve on a synthetic frame - the captured
twin convolved in numpy with an independent streak kernel (401 points along the recorded motion, each splatted
bilinearly, then a sampled Gaussian whose width is searched so that the kernel's own across r equals the record's
where it can), quantised to 8-bit sRGB. The synthetic frame's solve minus its kernel's own r is the method's bias
there. NOT a faithful replica: the synthetic frame is made from the rounded twin, so its response carries the
twin's rounding noise and the captured frame's does not (errors in variables bias only the latter); see
docs/blur-kernels.md "Across a streak". A finding, not wired as a test.
"""
import sys, os, json, glob, math
import numpy as np
from scipy.signal import fftconvolve
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import capture_kernel as ck

def srgb_q(v):
    s = np.where(v <= 0.0031308, 12.92 * v, 1.055 * np.clip(v, 0, None) ** (1 / 2.4) - 0.055)
    s = np.round(np.clip(s, 0, 1) * 255).astype(np.uint8)
    return ck._SRGB_TO_LINEAR[s]

def synth_kernel(m, sigma, h, method):
    # A segment from -m/2 to m/2 (401 points), each point splatted bilinearly, then a sampled Gaussian (or disc)
    n = 2 * h + 1
    k = np.zeros((n, n))
    for s in np.linspace(-0.5, 0.5, 401):
        x, y = h + s * m[0], h + s * m[1]
        x0, y0 = int(math.floor(x)), int(math.floor(y))
        fx, fy = x - x0, y - y0
        for dx, dy, w in ((0, 0, (1 - fx) * (1 - fy)), (1, 0, fx * (1 - fy)), (0, 1, (1 - fx) * fy), (1, 1, fx * fy)):
            k[y0 + dy, x0 + dx] += w
    if sigma > 0:
        g = int(math.ceil(4 * sigma)) + 1
        t = np.arange(-g, g + 1)
        g1 = np.exp(-t * t / (2 * sigma * sigma)); g2 = np.outer(g1, g1)
        k = fftconvolve(k, g2 / g2.sum(), mode="same")
    return k / k.sum()

def run(blurred_dir, sharp_dir):
    for path in sorted(glob.glob(os.path.join(blurred_dir, "trial-*.json"))):
        name = os.path.basename(path)[:-5]
        fr = json.load(open(path))
        B = ck.linear(os.path.join(blurred_dir, name + ".png"))
        S = ck.linear(os.path.join(sharp_dir, name + ".png"))
        H, W = B.shape[:2]
        for o in fr["objects"]:
            r_rec = o["r_screen_px"]; m = o["motion_screen_px"]; L = math.hypot(*m)
            h = max(3, math.ceil(1.6 * r_rec + L / 2) + 2)
            box = ck.object_box(o, h, W, H)
            k = ck.solve_kernel(S, B, box, h)
            r_real = ck.kernel_streak(k)[0]
            # synthetic kernel matched to the record's across r by bisection on sigma
            lo, hi = 0.0, max(1.0, r_rec)
            for _ in range(40):
                mid = (lo + hi) / 2
                ks = synth_kernel(m, mid, h + 2, o["kernel"])
                if ck.kernel_streak(ks)[0] < r_rec: lo = mid
                else: hi = mid
            ks = synth_kernel(m, (lo + hi) / 2, h + 2, o["kernel"])
            r_true_s = ck.kernel_streak(ks)[0]
            Ssyn = np.stack([fftconvolve(S[:, :, c], ks, mode="same") for c in range(3)], axis=2)
            Bs = srgb_q(Ssyn)
            k2 = ck.solve_kernel(S, Bs, box, h)
            r_syn = ck.kernel_streak(k2)[0]
            bias = r_syn - r_true_s
            print(f"{name} {o['side']} {o['kernel']}: rec {r_rec:.4f} real-solve {r_real:.4f} (err {r_real-r_rec:+.4f}) "
                  f"synth true {r_true_s:.4f} synth-solve {r_syn:.4f} bias {bias:+.4f} corrected err {r_real-bias-r_rec:+.4f}")

run(sys.argv[1], sys.argv[2])
