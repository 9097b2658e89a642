#!/usr/bin/env python3
"""capture_kernel_sim.py: tests/capture_kernel.py's least-squares method on synthetic frames (numpy and scipy only).

A lit ball (a disc of radius 27 px with a shaded interior) over the test's grey, convolved with a known kernel (a
5.71 px streak at 85 degrees convolved with a Gaussian of r 1.5 px, integrated over each pixel by 8 x 8
supersampling), both frames written as 8-bit sRGB and decoded, then solved and split as capture_kernel.py does.
Without quantisation the solved r across and L equal the true kernel's; with it, a flat disc stays within 1 %,
but a shaded one is off by -2.5 % static and +1.9 to +2.2 % under the streak (errors in variables: the twin's
rounding noise is in the regressors). docs/blur-kernels.md ("Across a streak"). A finding, not wired as a test.
"""
import math
import os
import sys

import numpy as np
from scipy.signal import fftconvolve

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import capture_kernel as ck  # noqa: E402


def kernel(r, length, ang, h, ss=8):
    n = 2 * h + 1
    t = (np.arange(n * ss) - (n * ss - 1) / 2) / ss
    x, y = np.meshgrid(t, t)
    k = np.zeros_like(x)
    sigma = r / 2
    for s in np.linspace(-length / 2, length / 2, 401):
        k += np.exp(-((x - s * math.cos(ang)) ** 2 + (y - s * math.sin(ang)) ** 2) / (2 * sigma * sigma))
    k = k.reshape(n, ss, n, ss).sum(axis=(1, 3))
    return k / k.sum()


def quantise(v):
    s = np.where(v <= 0.0031308, 12.92 * v, 1.055 * np.clip(v, 0, None) ** (1 / 2.4) - 0.055)
    s = np.round(np.clip(s, 0, 1) * 255) / 255
    return np.where(s <= 0.04045, s / 12.92, ((s + 0.055) / 1.055) ** 2.4)


def main():
    r, length, ang, radius = 1.5, 5.7146, math.radians(85), 27.0
    h0 = max(3, math.ceil(1.6 * r + length / 2) + 2)
    size = int(2 * radius + 8 * (h0 + 3))
    ss = 8
    c = (size / 2 + 0.3, size / 2 + 0.2)
    yy, xx = (np.mgrid[0:size * ss, 0:size * ss] + 0.5) / ss
    inside = (((xx - c[0]) ** 2 + (yy - c[1]) ** 2) <= radius ** 2).astype(float)
    inside = inside.reshape(size, ss, size, ss).mean(axis=(1, 3))
    y, x = np.mgrid[0:size, 0:size] + 0.5
    rr = np.clip(1 - ((x - c[0]) ** 2 + (y - c[1]) ** 2) / radius ** 2, 0, 1)
    shade = 0.55 + 0.30 * np.sqrt(rr) * (0.6 + 0.4 * (x - c[0]) / radius)
    grey = ((118 / 255 + 0.055) / 1.055) ** 2.4
    box_o = {"outline_px": [[c[0] - radius, c[1] - radius], [c[0] + radius, c[1] + radius]]}
    for interior in ("flat", "shaded"):
        sharp = grey + ((shade if interior == "shaded" else 0.83) - grey) * inside
        for streak in (0.0, length):
            for h in (h0, h0 + 3):
                k = kernel(r, streak, ang, h)
                blurred = fftconvolve(sharp, k, mode="same")
                box = ck.object_box(box_o, h, size, size)
                true = ck.kernel_streak(k)[:2]
                for quant in (False, True):
                    f = quantise if quant else (lambda v: v)
                    got = ck.kernel_streak(ck.solve_kernel(np.dstack([f(sharp)] * 3), np.dstack([f(blurred)] * 3),
                                                           box, h))[:2]
                    print(f"{interior:6} L {streak:.2f} window {h:2} {'8-bit' if quant else 'exact'}: "
                          f"true r across {true[0]:.4f} L {true[1]:.4f}; solved {got[0]:.4f} ({100 * (got[0] / true[0] - 1):+.1f} %) "
                          f"L {got[1]:.4f}")


if __name__ == "__main__":
    main()
