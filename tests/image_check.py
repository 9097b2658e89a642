#!/usr/bin/python3
"""The images the CLI's drawing commands write, checked on the pixels (their printed line says nothing of them).

usage: image_check.py disc IN OUT RADIUS_PX
         OUT must be IN blurred by a pillbox of RADIUS_PX, worked out here apart from blurcue: sRGB decoded (IEC
         61966-2-1), alpha premultiplied, the disc's kernel by 32 x 32 supersampling of each pixel's coverage,
         scipy's FFT convolution. Its error against OUT (the interior, away from the borders' padding) must be at most
         1/2 of the error of the same image blurred at 0.9 x and 1.1 x the radius: a radius 10 % off fails.
       image_check.py drawn BACKGROUND OUT
         OUT must be BACKGROUND with one object drawn over it: at least 200 px differ by more than 2 levels, and
         every pixel that differs at all lies in a box under a quarter of the image - a blank, black, untouched or
         wholly redrawn image fails.
Prints "ok: ..." and exits 0, or "FAIL: ..." and exits 1.
"""
import sys

import numpy as np
from PIL import Image
from scipy.signal import fftconvolve


def decode(v8):
    v = v8 / 255.0
    return np.where(v <= 0.04045, v / 12.92, ((v + 0.055) / 1.055) ** 2.4)


def encode(lin):
    lin = np.clip(lin, 0, 1)
    return 255 * np.where(lin <= 0.0031308, 12.92 * lin, 1.055 * lin ** (1 / 2.4) - 0.055)


def disc_kernel(r, sub=32):
    n = int(np.ceil(r)) + 1
    offsets = (np.arange(sub) + 0.5) / sub - 0.5
    k = np.zeros((2 * n + 1, 2 * n + 1))
    for i, y in enumerate(range(-n, n + 1)):
        for j, x in enumerate(range(-n, n + 1)):
            yy, xx = np.meshgrid(y + offsets, x + offsets, indexing="ij")
            k[i, j] = np.mean(xx * xx + yy * yy <= r * r)
    return k / k.sum()


def blurred(rgba8, r):
    rgba = rgba8.astype(float)
    alpha = rgba[..., 3] / 255.0
    k = disc_kernel(r)
    premult = [fftconvolve(decode(rgba[..., c]) * alpha, k, mode="same") for c in range(3)]
    a = fftconvolve(alpha, k, mode="same")
    safe = np.maximum(a, 1e-6)
    return np.stack([encode(p / safe) for p in premult] + [255 * a], axis=-1)


def check_disc(src, out, r):
    a = np.asarray(Image.open(src).convert("RGBA"))
    b = np.asarray(Image.open(out).convert("RGBA")).astype(float)
    if a.shape != b.shape:
        return f"FAIL: {out} is {b.shape[1]}x{b.shape[0]}, {src} is {a.shape[1]}x{a.shape[0]}"
    m = int(np.ceil(1.1 * r)) + 2
    inner = (slice(m, -m), slice(m, -m))
    ref = {k: blurred(a, k * r)[inner] for k in (0.9, 1.0, 1.1)}
    # Where the radius shows: opaque pixels whose value moves by more than 1 level between 0.9 r and 1.1 r (a flat
    # area is the same at every radius and would dilute the error).
    where = (a[inner][..., 3] > 128) & (np.abs(ref[0.9][..., :3] - ref[1.1][..., :3]).max(axis=-1) > 1)
    if where.sum() < 1000:
        return f"FAIL: {src}: only {int(where.sum())} px show the radius; pick an image with edges"

    def err(k):
        return float(np.mean(np.abs(ref[k][..., :3] - b[inner][..., :3])[where]))

    e, lo, hi = err(1.0), err(0.9), err(1.1)
    if not (e <= 0.5 * min(lo, hi)):
        return (f"FAIL: {out} is not {src} blurred by a disc of {r} px: mean error {e:.3f} levels, against "
                f"{lo:.3f} at 0.9 r and {hi:.3f} at 1.1 r")
    return (f"ok: {out} is {src} blurred by a disc of {r} px: mean error {e:.3f} levels (0.9 r: {lo:.3f}, 1.1 r: "
            f"{hi:.3f})")


def check_drawn(background, out):
    a = np.asarray(Image.open(background).convert("RGB")).astype(int)
    b = np.asarray(Image.open(out).convert("RGB")).astype(int)
    if a.shape != b.shape:
        return f"FAIL: {out} is {b.shape[1]}x{b.shape[0]}, {background} is {a.shape[1]}x{a.shape[0]}"
    diff = np.abs(a - b).max(axis=-1)
    changed = diff > 2
    if changed.sum() < 200:
        return f"FAIL: {out}: only {int(changed.sum())} px differ from {background} by over 2 levels (nothing drawn)"
    ys, xs = np.nonzero(diff > 0)  # the object with its blurred fringe
    y0, y1, x0, x1 = ys.min(), ys.max() + 1, xs.min(), xs.max() + 1
    box = (y1 - y0) * (x1 - x0)
    if box > diff.size / 4:
        return f"FAIL: {out}: the changed pixels span {x1 - x0}x{y1 - y0} px, over a quarter of the image"
    return (f"ok: {out}: one object of {int(changed.sum())} px drawn in a {x1 - x0}x{y1 - y0} box at ({x0}, {y0}); "
            "the rest is the background")


def main():
    what = sys.argv[1] if len(sys.argv) > 1 else ""
    if what == "disc" and len(sys.argv) == 5:
        text = check_disc(sys.argv[2], sys.argv[3], float(sys.argv[4]))
    elif what == "drawn" and len(sys.argv) == 4:
        text = check_drawn(sys.argv[2], sys.argv[3])
    else:
        print(__doc__, file=sys.stderr)
        return 2
    print(text)
    return 0 if text.startswith("ok:") else 1


if __name__ == "__main__":
    sys.exit(main())
