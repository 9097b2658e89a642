#!/usr/bin/env python3
"""camera_exif_test.py BLURCUE DIR: `blurcue camera` against photos whose EXIF Pillow wrote (an independent writer).

Each case's expected camera is worked out here from the tags written, not by blurcue's code: the sensor from the
focal-plane resolution (px per cm -> mm), from the sensor table (the thesis's NEX-5N: 23.4 x 15.6 mm), from the
35 mm equivalent (diagonal 43.27 mm x f / f35, the image's aspect), and a photo stored turned (Orientation 6).
Missing tags are refused, exit 3, naming the tag and the option that gives it.
"""
import json
import math
import os
import struct
import subprocess
import sys

from PIL import Image, TiffImagePlugin

BC, DIR = sys.argv[1], sys.argv[2]
os.makedirs(DIR, exist_ok=True)
R = TiffImagePlugin.IFDRational
EXIF_IFD = 0x8769


def photo(name, size, base=None, sub=None):
    """A JPEG of `size` with IFD0 tags `base` and Exif-IFD tags `sub`; None = no EXIF at all."""
    path = os.path.join(DIR, name)
    img = Image.new("RGB", size, (90, 120, 150))
    if base is None and sub is None:
        img.save(path, quality=92)
        return path
    exif = Image.Exif()
    for k, v in (base or {}).items():
        exif[k] = v
    if sub:
        exif[EXIF_IFD] = dict(sub)  # the Exif sub-IFD, written nested
    img.save(path, quality=92, exif=exif.tobytes())
    return path


def run(*args):
    p = subprocess.run([BC, "camera", *args], capture_output=True, text=True)
    return p.returncode, p.stdout, p.stderr


def camera(path, *extra):
    code, out, err = run(path, *extra)
    assert code == 0, (path, code, err)
    return json.loads(out), err


def near(a, b, tol=1e-3):
    return abs(a - b) <= tol * max(1.0, abs(b))


failures = []


def check(what, ok, detail=""):
    print(("ok   " if ok else "FAIL ") + what + (f" ({detail})" if detail and not ok else ""))
    if not ok:
        failures.append(what)


MAKE, MODEL, ORIENT = 0x010F, 0x0110, 0x0112
FNUMBER, FOCAL, FOCAL35, SUBJECT, EXPOSURE = 0x829D, 0x920A, 0xA405, 0x9206, 0x829A
XDIM, YDIM, FPX, FPY, FPUNIT = 0xA002, 0xA003, 0xA20E, 0xA20F, 0xA210

# 1. Focal-plane resolution in px per cm (unit 3): 600 px over 2.34 cm is a 23.4 mm wide sensor.
p = photo("fpr.jpg", (600, 400), {MAKE: "Acme", MODEL: "Unlisted 1"},
          {FOCAL: R(21, 1), FNUMBER: R(56, 10), XDIM: 600, YDIM: 400, FPX: R(600 * 100, 234), FPY: R(400 * 100, 156),
           FPUNIT: 3, SUBJECT: R(12, 10), EXPOSURE: R(1, 60)})
c, err = camera(p)
check("focal-plane resolution: f, N, sensor, size",
      near(c["focal_length_mm"], 21) and near(c["f_number"], 5.6) and near(c["sensor_width_mm"], 23.4)
      and near(c["sensor_height_mm"], 15.6) and c["image_width_px"] == 600 and c["image_height_px"] == 400, c)
check("the name is make and model", c.get("name") == "Acme Unlisted 1", c)
check("the exposure is ExposureTime 1/60 s in ms", near(c.get("exposure_ms", -1), 1000 / 60), c)
check("the focus distance is printed from SubjectDistance", "1200 mm" in err, err)

# The file it writes is a camera.json calibrate's loader takes (blurcue estimate reads it).
out = os.path.join(DIR, "camera.json")
code, _, err = run(p, "--out", out)
code2 = subprocess.run([BC, "estimate", "--camera", out, "--ref-u-mm", "342.3", "--ref-r-px", "8", "--u-mm", "527.3"],
                       capture_output=True, text=True).returncode
check("--out writes a camera.json that estimate reads", code == 0 and code2 == 0, f"{code} {code2} {err}")

# 2. The sensor table: the thesis's camera by its Model, no focal-plane tags.
p = photo("table.jpg", (459, 306), {MAKE: "SONY", MODEL: "NEX-5N"}, {FOCAL: R(21, 1), FNUMBER: R(56, 10)})
c, err = camera(p)
check("sensor table: NEX-5N is 23.4 x 15.6 mm",
      near(c["sensor_width_mm"], 23.4) and near(c["sensor_height_mm"], 15.6) and "sensor table" in err, (c, err))

# 3. The 35 mm equivalent: 21 mm that frames as 32 mm does on 36 x 24 mm.
p = photo("fl35.jpg", (600, 400), {MODEL: "Unlisted 2"}, {FOCAL: R(21, 1), FNUMBER: R(4, 1), FOCAL35: 32})
c, err = camera(p)
diagonal = math.hypot(36, 24) * 21 / 32
h = diagonal / math.sqrt(1 + 1.5 ** 2)
check("35 mm equivalent: the diagonal kept, the image's aspect",
      near(c["sensor_width_mm"], 1.5 * h) and near(c["sensor_height_mm"], h) and "approximate" in err, (c, err))

# 4. Stored turned (Orientation 6, 90 degrees): calibrate sees 400 x 600, so the sensor's sides swap too.
p = photo("turned.jpg", (600, 400), {MODEL: "Unlisted 3", ORIENT: 6},
          {FOCAL: R(50, 1), FNUMBER: R(28, 10), XDIM: 600, YDIM: 400, FPX: R(600, 36), FPY: R(400, 24), FPUNIT: 4})
c, err = camera(p)
check("turned photo: 400 x 600 px, sensor 24 x 36 mm",
      c["image_width_px"] == 400 and c["image_height_px"] == 600 and near(c["sensor_width_mm"], 24)
      and near(c["sensor_height_mm"], 36), (c, err))

# 5. --sensor-mm overrides; --f-number fills a missing FNumber.
p = photo("nofnumber.jpg", (600, 400), {MODEL: "Unlisted 4"}, {FOCAL: R(35, 1)})
code, _, err = run(p)
# Everything missing is named at once (it took three runs to learn the three options a bare photo needs).
check("a missing FNumber and sensor are refused at once, naming the tags and the options",
      code == 3 and "EXIF FNumber (0x829d) is missing, no sensor size (EXIF FocalPlaneXResolution (0xa20e) is "
      "missing, EXIF FocalLengthIn35mmFilm (0xa405) is missing, model 'Unlisted 4' not in the sensor table); give "
      "--f-number and --sensor-mm W H" in err and err.count("\n") == 1, (code, err))
c, err = camera(p, "--f-number", "8", "--sensor-mm", "36", "24")
check("--f-number and --sensor-mm fill what EXIF lacks",
      near(c["f_number"], 8) and near(c["sensor_width_mm"], 36) and near(c["sensor_height_mm"], 24), (c, err))

# 6. No sensor size anywhere: refused naming what was looked for.
p = photo("nosensor.jpg", (600, 400), {MODEL: "Unlisted 5"}, {FOCAL: R(35, 1), FNUMBER: R(8, 1)})
code, _, err = run(p)
check("no sensor size: refused, --sensor-mm named", code == 3 and "give --sensor-mm W H" in err, (code, err))
# A tag that is there but says "unknown" is not called missing.
p = photo("fl35-zero.jpg", (600, 400), {}, {FOCAL: R(35, 1), FNUMBER: R(8, 1), FOCAL35: 0})
code, _, err = run(p)
check("a 35 mm equivalent of 0 is named as 0 (unknown), not as missing",
      code == 3 and "EXIF FocalLengthIn35mmFilm (0xa405) is 0 (unknown), no EXIF Model); give --sensor-mm W H" in err,
      (code, err))

# 7. No EXIF at all.
p = photo("plain.jpg", (600, 400))
code, _, err = run(p)
check("no EXIF: refused in one line", code == 3 and "holds no EXIF" in err and err.count("\n") == 1, (code, err))

# 8. Impossible values are the camera's limits' errors: a focal length of 0.1 mm.
p = photo("tiny.jpg", (600, 400), {MODEL: "NEX-5N"}, {FOCAL: R(1, 10), FNUMBER: R(8, 1)})
code, _, err = run(p)
check("an impossible focal length is refused naming the field", code == 3 and "focal_length_mm" in err, (code, err))

# 9. A zero focal length (a lens without electronic contacts writes 0/1): refused naming the tag and the option.
p = photo("zero-focal.jpg", (600, 400), {MODEL: "NEX-5N"}, {FOCAL: R(0, 1), FNUMBER: R(8, 1)})
code, _, err = run(p)
check("a zero focal length is refused naming the EXIF tag and --focal-length-mm",
      code == 3 and "zero-focal.jpg: EXIF FocalLength (0x920a) is 0 (unknown); give --focal-length-mm" in err
      and err.count("\n") == 1, (code, err))
# With a zero FNumber too, both are named at once (it took two runs).
p = photo("zero-both.jpg", (600, 400), {MODEL: "NEX-5N"}, {FOCAL: R(0, 1), FNUMBER: R(0, 1)})
code, _, err = run(p)
check("a zero focal length and f-number are named at once",
      code == 3 and "EXIF FocalLength (0x920a) is 0 (unknown), EXIF FNumber (0x829d) is 0 (unknown); give "
      "--focal-length-mm and --f-number" in err, (code, err))

# 10. A sensor size worked out of a tag, impossible: says where it came from. The 35 mm equivalent of 1 mm for a
# 21 mm lens is a 756 mm wide sensor.
p = photo("fl35-1.jpg", (600, 400), {MODEL: "Unlisted 6"}, {FOCAL: R(21, 1), FNUMBER: R(8, 1), FOCAL35: 1})
code, _, err = run(p)
check("an impossible sensor from the 35 mm equivalent names its source and --sensor-mm",
      code == 3 and "/sensor_width_mm: must be in [0.5, 500] mm, got 756 (the sensor size from the 35 mm equivalent "
      "focal length (1 mm); give --sensor-mm W H)" in err, (code, err))

# 11. A PNG (Pillow writes its EXIF in an eXIf chunk, which libexif does not read): the message says the file is
# not a JPEG rather than that it has no EXIF; with every number given, camera.json is written.
p = os.path.join(DIR, "tagged.png")
exif = Image.Exif()
exif[MODEL] = "NEX-5N"
exif[EXIF_IFD] = {FOCAL: R(21, 1), FNUMBER: R(8, 1)}
Image.new("RGB", (600, 400), (90, 120, 150)).save(p, exif=exif.tobytes())
code, _, err = run(p)
check("a PNG: not a JPEG, its EXIF not read",
      code == 3 and "tagged.png: is not a JPEG: its EXIF, if any, is not read (EXIF is read from JPEG files); give "
      "--focal-length-mm, --f-number and --sensor-mm W H" in err, (code, err))
code, _, err = run(p, "--focal-length-mm", "21")
check("a PNG with a focal length given: the two others named, not the one given",
      code == 3 and err.endswith("give --f-number and --sensor-mm W H\n"), (code, err))
c, err = camera(p, "--focal-length-mm", "21", "--f-number", "8", "--sensor-mm", "23.4", "15.6")
check("a PNG with every number given", c["image_width_px"] == 600 and near(c["sensor_width_mm"], 23.4), (c, err))

# 12. SubjectDistance 0xFFFFFFFF/1 is infinity, said so (not "not in EXIF").
p = photo("infinity.jpg", (600, 400), {MODEL: "NEX-5N"}, {FOCAL: R(21, 1), FNUMBER: R(8, 1), SUBJECT: R(2 ** 32 - 1, 1)})
c, err = camera(p)
check("SubjectDistance infinity is printed as infinity", "SubjectDistance): infinity" in err, err)

# 13. A rational stored as the signed type (SRATIONAL, 10) is read with its sign: -21/-1 is 21 mm (libexif's
# "fix" had made it the unsigned 4294967275/4294967295 = 0.99999999534 mm), -21/1 is refused as negative.
def signed_focal(name, num, den):
    path = photo(name, (600, 400), {MODEL: "NEX-5N"}, {FOCAL: R(21, 1), FNUMBER: R(8, 1)})
    data = bytearray(open(path, "rb").read())
    tiff = data.index(b"Exif\x00\x00") + 6
    little = data[tiff:tiff + 2] == b"II"
    end = "<" if little else ">"
    entry = data.index(struct.pack(end + "HHI", FOCAL, 5, 1), tiff)  # tag, RATIONAL, one value
    offset = struct.unpack(end + "I", data[entry + 8:entry + 12])[0]
    data[entry:entry + 8] = struct.pack(end + "HHI", FOCAL, 10, 1)  # SRATIONAL
    data[tiff + offset:tiff + offset + 8] = struct.pack(end + "ii", num, den)
    open(path, "wb").write(bytes(data))
    return path


c, err = camera(signed_focal("srational.jpg", -21, -1))
check("a signed rational -21/-1 is 21 mm", near(c["focal_length_mm"], 21), (c, err))
code, _, err = run(signed_focal("negative.jpg", -21, 1))
check("a negative focal length is refused naming the tag", code == 3 and "negative.jpg: EXIF FocalLength (0x920a) is "
      "-21 (negative" in err and "--focal-length-mm" in err, (code, err))

if failures:
    sys.exit(f"{len(failures)} failed: {failures}")
print("ok: camera.json from EXIF as the tags say")
