#!/usr/bin/python3
"""blurcue make-stimuli's textures, checked against their geometry worked out here (not against earlier output):

  grid.png    1024 x 1024, a 5 x 5 grid: exactly 6 dark bands across each axis, evenly spaced (within 2 px)
  soccer.png  2048 x 1024 equirectangular truncated icosahedron: 12 dark pentagons (regions joined across the seam
              and at the poles), each 85-100 % of a spherical regular pentagon's share of the sphere (its angular
              circumradius from the solid's 60 vertices, area by spherical excess: 2.35 %; the seam lines take the
              rest), all within 2 % of each other, and each pentagon's centre 63.43 deg (arctan 2, the icosahedron's
              edge) from exactly 5 others
  wood.png    2048 x 1024, not flat
  face.png    800 x 1200 with alpha: transparent corners, an opaque centre

usage: stimuli_check.py BLURCUE OUT_DIR      (runs make-stimuli --out OUT_DIR first)
"""
import itertools
import math
import subprocess
import sys

import numpy as np
from PIL import Image
from scipy import ndimage

PHI = (1 + 5 ** 0.5) / 2


def pentagon_share():
    verts = set()
    for base in [(0, 1, 3 * PHI), (1, 2 + PHI, 2 * PHI), (PHI, 2, PHI ** 3)]:
        for p in [base, base[1:] + base[:1], base[2:] + base[:2]]:
            for sign in itertools.product([1, -1], repeat=3):
                verts.add(tuple(s * x for s, x in zip(sign, p)))
    v = np.array(sorted(verts))
    assert len(v) == 60
    v /= np.linalg.norm(v, axis=1)[:, None]
    centre = np.array([0, 1, PHI]) / math.hypot(1, PHI)
    radius = float(np.min(np.arccos(np.clip(v @ centre, -1, 1))))
    angle = 2 * math.atan(1 / (math.cos(radius) * math.tan(math.pi / 5)))  # a regular spherical pentagon's angle
    return (5 * angle - 3 * math.pi) / (4 * math.pi)


def check_grid(path, problems):
    g = np.asarray(Image.open(path).convert("L")).astype(float)
    if g.shape != (1024, 1024):
        return problems.append(f"{path}: {g.shape[1]}x{g.shape[0]}, expected 1024x1024")
    for axis, name in ((1, "rows"), (0, "columns")):
        lab, n = ndimage.label((g < 128).mean(axis=axis) > 0.5)
        centres = [float(np.mean(np.nonzero(lab == i)[0])) for i in range(1, n + 1)]
        steps = np.diff(centres)
        if n != 6 or np.ptp(steps) > 2:
            problems.append(f"{path}: {n} dark bands across the {name} at {centres}, expected 6 evenly spaced")


def check_soccer(path, problems):
    s = np.asarray(Image.open(path).convert("L")).astype(float)
    if s.shape != (1024, 2048):
        return problems.append(f"{path}: {s.shape[1]}x{s.shape[0]}, expected 2048x1024")
    h, w = s.shape
    lat = (0.5 - (np.arange(h) + 0.5) / h) * math.pi
    lon = ((np.arange(w) + 0.5) / w - 0.5) * 2 * math.pi
    weight = np.cos(lat)[:, None] * np.ones((1, w))
    # Pentagons: the dark fill (about 64-80 of 255), apart from the darker seam lines around every face.
    lab, n = ndimage.label(ndimage.binary_opening((s >= 60) & (s < 120), iterations=2))
    parent = list(range(n + 1))

    def root(x):
        while parent[x] != x:
            x = parent[x]
        return x
    for y in range(h):  # the seam at longitude +-180
        if lab[y, 0] and lab[y, -1]:
            parent[root(lab[y, -1])] = root(lab[y, 0])
    for row in (0, -1):  # a pole's row is one point
        labels = [x for x in set(lab[row].tolist()) if x]
        for x in labels[1:]:
            parent[root(x)] = root(labels[0])
    xyz = np.stack([np.cos(lat)[:, None] * np.cos(lon)[None, :], np.cos(lat)[:, None] * np.sin(lon)[None, :],
                    np.sin(lat)[:, None] * np.ones((1, w))], axis=-1)
    regions = {}
    for i in range(1, n + 1):
        mask = lab == i
        r = regions.setdefault(root(i), [0.0, np.zeros(3)])
        r[0] += float(weight[mask].sum())
        r[1] += (xyz[mask] * weight[mask][:, None]).sum(axis=0)
    total = float(weight.sum())
    big = [(a / total, c / np.linalg.norm(c)) for a, c in regions.values() if a / total > 0.002]
    share = pentagon_share()
    if len(big) != 12:
        return problems.append(f"{path}: {len(big)} dark pentagons, expected 12")
    areas = np.array([a for a, _ in big])
    if not (0.85 * share <= areas.min() and areas.max() <= share) or np.ptp(areas) > 0.02 * areas.mean():
        problems.append(f"{path}: pentagon shares {areas.min():.4f}-{areas.max():.4f} of the sphere, expected "
                        f"{0.85 * share:.4f}-{share:.4f} and equal")
    centres = np.array([c for _, c in big])
    angles = np.degrees(np.arccos(np.clip(centres @ centres.T, -1, 1)))
    near = (np.abs(angles - math.degrees(math.atan(2))) < 1.0).sum(axis=1)
    if not np.all(near == 5):
        problems.append(f"{path}: pentagon centres with 5 neighbours at 63.43 deg: {int(np.sum(near == 5))} of 12")
    return share, areas.mean()


def main():
    bc, out = sys.argv[1], sys.argv[2]
    done = subprocess.run([bc, "make-stimuli", "--out", out], capture_output=True, text=True)
    if done.returncode != 0:
        print(f"FAIL: make-stimuli exit {done.returncode}: {done.stderr.strip()}")
        return 1
    problems = []
    check_grid(f"{out}/grid.png", problems)
    soccer = check_soccer(f"{out}/soccer.png", problems)
    wood = np.asarray(Image.open(f"{out}/wood.png").convert("L")).astype(float)
    if wood.shape != (1024, 2048) or wood.std() < 5:
        problems.append(f"{out}/wood.png: {wood.shape[1]}x{wood.shape[0]}, grey std {wood.std():.1f} (flat?)")
    face = np.asarray(Image.open(f"{out}/face.png"))
    if face.shape != (1200, 800, 4) or face[0, 0, 3] != 0 or face[-1, -1, 3] != 0 or face[600, 400, 3] != 255:
        problems.append(f"{out}/face.png: shape {face.shape}, alpha at a corner {face[0, 0, -1]}, centre "
                        f"{face[600, 400, -1]} (expected RGBA 800x1200, transparent corners, opaque centre)")
    for p in problems:
        print("FAIL:", p)
    if problems:
        return 1
    print(f"ok: make-stimuli: grid 6 x 6 bands; soccer 12 pentagons of {100 * soccer[1]:.2f} % of the sphere each "
          f"(geometry {100 * soccer[0]:.2f} %), each 63.43 deg from 5 others; wood and face as described")
    return 0


if __name__ == "__main__":
    sys.exit(main())
