#!/usr/bin/env python3
"""cut_images.py: damaged copies of real images for the CLI tests of issue 39 (a damaged input is refused, exit 3).

  cut_images.py photo IN.png OUT.jpg            OUT: IN as a JPEG (Pillow, quality 92), cut at 75 % of its bytes
  cut_images.py sequence IN-%04d.png OUT-%04d.jpg K
                                                 every frame of IN as a JPEG; frame K's file cut at 75 %
"""
import os
import sys

from PIL import Image


def jpeg(src, dst, cut):
    Image.open(src).convert("RGB").save(dst, quality=92)
    if cut:
        data = open(dst, "rb").read()
        open(dst, "wb").write(data[: len(data) * 3 // 4])


def main():
    mode = sys.argv[1]
    if mode == "photo":
        os.makedirs(os.path.dirname(os.path.abspath(sys.argv[3])), exist_ok=True)
        jpeg(sys.argv[2], sys.argv[3], True)
        print("ok: cut", sys.argv[3])
    elif mode == "sequence":
        src, dst, k = sys.argv[2], sys.argv[3], int(sys.argv[4])
        os.makedirs(os.path.dirname(os.path.abspath(dst % 0)), exist_ok=True)
        i = 0
        while os.path.exists(src % i):
            jpeg(src % i, dst % i, i == k)
            i += 1
        if i <= k:
            sys.exit(f"only {i} frames in {src}")
        print("ok: cut frame", k, "of", i)
    else:
        sys.exit(__doc__)


main()
