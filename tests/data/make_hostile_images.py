#!/usr/bin/env python3
"""Writes the hostile PNGs the CLI tests read (run from anywhere; writes next to this script).

  bad-iccp.png            a valid 16x12 RGB image whose iCCP chunk holds a broken ICC profile: libpng decodes it
                          and prints "libpng warning: iCCP: ..." on stderr unless blurcue keeps that off
  bad-iccp-truncated.png  the same cut off inside its IDAT: not decodable, and libpng complains on the way
  huge-header.png         an IHDR claiming 65535 x 65535 px over a few bytes of data: refused from the header
  small.png               the same 16x12 image without the iCCP chunk: a plain input for option tests
"""
import os
import struct
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))


def chunk(kind, data):
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)


def png(width, height, rows, iccp=None):
    out = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0))
    if iccp is not None:
        out += chunk(b"iCCP", b"broken profile\x00\x00" + zlib.compress(iccp))
    raw = b"".join(b"\x00" + row for row in rows)
    return out + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b"")


def main():
    w, h = 16, 12
    rows = [bytes(v for x in range(w) for v in (x * 15 % 256, y * 20 % 256, (x + y) * 7 % 256)) for y in range(h)]
    # 132 bytes that claim to be a 132-byte ICC profile but carry no 'acsp' signature.
    profile = struct.pack(">I", 132) + b"\x00" * 128
    good = png(w, h, rows, iccp=profile)
    with open(os.path.join(HERE, "bad-iccp.png"), "wb") as f:
        f.write(good)
    idat = good.index(b"IDAT")
    with open(os.path.join(HERE, "bad-iccp-truncated.png"), "wb") as f:
        f.write(good[: idat + 12])
    with open(os.path.join(HERE, "small.png"), "wb") as f:
        f.write(png(w, h, rows))
    with open(os.path.join(HERE, "huge-header.png"), "wb") as f:
        f.write(png(65535, 65535, [b""]))


if __name__ == "__main__":
    main()
