#!/usr/bin/env python3
"""preview_inset_check.py BLURCUE PROTOCOL WORKDIR

blurcue preview's insets show each object at 1:1 screen scale, as a participant sees it: every inset equals, pixel
for pixel, the part of the frame that blurcue run --capture wrote for the same trial (the frame the window shows),
around the object's outline as the capture's JSON gives it. The sheet's labels stay inside their own tile.
"""
import json
import pathlib
import re
import subprocess
import sys

import numpy as np
from PIL import Image

bc, protocol, work = sys.argv[1], sys.argv[2], pathlib.Path(sys.argv[3])
work.mkdir(parents=True, exist_ok=True)
sheet_path, capture, db = work / "sheet.png", work / "capture", work / "c.sqlite"
for p in (sheet_path, db):
    p.unlink(missing_ok=True)
subprocess.run(["rm", "-rf", str(capture)], check=True)
listing = subprocess.run([bc, "preview", protocol, "--out", str(sheet_path), "--columns", "1", "--list"],
                         check=True, capture_output=True, text=True).stdout
subprocess.run([bc, "run", protocol, "--participant", "P1", "--db", str(db), "--observer", "sim", "--capture",
                str(capture)], check=True, capture_output=True)

tiles = [line for line in listing.splitlines() if line.startswith("#")]
sheet = np.asarray(Image.open(sheet_path).convert("RGB")).astype(int)
row_h = sheet.shape[0] // len(tiles)
assert sheet.shape[0] == row_h * len(tiles), (sheet.shape, len(tiles))

# Each capture: its two sides' (source, radius in photo px to 2 decimals) and the frame.
captures = []
for js in sorted(capture.glob("trial-*.json")):
    d = json.loads(js.read_text())
    if d.get("practice") or len(d["objects"]) != 2:
        continue
    key = tuple((o["source"], f"{o['r_camera_px']:.2f}") for o in d["objects"])
    captures.append((key, d, np.asarray(Image.open(js.with_suffix(".png")).convert("RGB")).astype(int)))

TW, TH, INSET = 320, 180, 180  # preview's defaults for a 1280 x 720 frame: whole frame 320 px wide, insets 180 px
checked = 0
for i, line in enumerate(tiles):
    sides = re.findall(r"([LR]) (\w+) ([0-9.]+) px =", line)
    key = tuple((source, radius) for _, source, radius in sides)
    match = [c for c in captures if c[0] == key]
    if not match:
        continue  # the participant's list did not show this pair on these sides
    _, d, frame = match[0]
    for k, o in enumerate(d["objects"]):
        inset = sheet[i * row_h + 20: i * row_h + INSET, TW + 4 + k * (INSET + 4): TW + 4 + k * (INSET + 4) + INSET]
        xs = [p[0] for p in o["outline_px"]]
        ys = [p[1] for p in o["outline_px"]]
        cx, cy = (min(xs) + max(xs)) / 2, (min(ys) + max(ys)) / 2
        best = None
        for dy in range(-3, 4):  # the crop's corner, within a few px of the outline's centre
            for dx in range(-3, 4):
                x0 = min(max(int(round(cx)) - INSET // 2 + dx, 0), frame.shape[1] - INSET)
                y0 = min(max(int(round(cy)) - INSET // 2 + dy, 0), frame.shape[0] - INSET)
                diff = np.abs(frame[y0 + 20: y0 + INSET, x0: x0 + INSET] - inset).max()
                best = diff if best is None else min(best, diff)
        assert best is not None and best <= 1, f"tile {i + 1} {o['side']}: inset differs from the captured frame by {best}"
        checked += 1
    # The tile's label lines lie below its pictures and above the next tile: the strip holds them all.
    strip = sheet[i * row_h + INSET: (i + 1) * row_h]
    assert (strip[-3:] == 40).all(), f"tile {i + 1}: its label runs into the next tile"
assert checked >= 8, f"only {checked} insets compared with a capture"
print(f"ok: {checked} insets equal the captured frames pixel for pixel (1:1)")
