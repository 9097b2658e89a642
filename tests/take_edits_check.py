#!/usr/bin/env python3
"""take_edits_check.py BLURCUE TAKE TRACK WORK: a tracked take read back (blurcue ar) refuses hand edits (issue 39).

TAKE holds frame-%04d.png and TRACK the folder blurcue track wrote for it. Each case copies TRACK, makes one edit and
runs `ar` on it: exit 3 with one line naming the file and the field or line. The copy as written draws (exit 0).
"""
import json
import os
import shutil
import subprocess
import sys

BC, TAKE, TRACK, WORK = sys.argv[1:5]
failures = []


def ar(track):
    out = os.path.join(WORK, os.path.basename(track) + ".avi")
    p = subprocess.run([BC, "ar", os.path.join(TAKE, "frame-%04d.png"), "--track", track, "--ball", "50,50",
                        "--out", out], capture_output=True, text=True)
    return p.returncode, p.stderr.strip()


def case(name, edit, code_wanted, text_wanted):
    track = os.path.join(WORK, name)
    shutil.rmtree(track, ignore_errors=True)
    shutil.copytree(TRACK, track)
    edit(track)
    code, err = ar(track)
    ok = code == code_wanted and text_wanted in err and (code == 0 or "\n" not in err)
    print(("ok   " if ok else "FAIL ") + name + ("" if ok else f" (exit {code}: {err})"))
    if not ok:
        failures.append(name)


def edit_json(track, frame, change):
    path = os.path.join(track, "calib-%04d.json" % frame)
    j = json.load(open(path))
    change(j)
    json.dump(j, open(path, "w"), indent=1)


def cut_last_row(track):
    path = os.path.join(track, "track.csv")
    lines = open(path).read().rstrip("\n").split("\n")
    lines[-1] = ",".join(lines[-1].split(",")[:3])  # 3 of 19 fields, no line break: a file cut inside its last row
    open(path, "w").write("\n".join(lines))


os.makedirs(WORK, exist_ok=True)
case("as-written", lambda t: None, 0, "")
case("focus-500", lambda t: edit_json(t, 1, lambda j: j["model"].__setitem__("focus_mm", 500)), 3,
     "calib-0001.json: /model/focus_mm: must be the take's")
case("aperture-first-frame", lambda t: edit_json(t, 0, lambda j: j["model"].__setitem__("aperture_mm", 5)), 3,
     "calib-0000.json: /model/aperture_mm: must be the take's")
case("cut-last-row", cut_last_row, 3, "track.csv: line 4: has 3 fields, the header 19")
case("board-cols-8", lambda t: edit_json(t, 2, lambda j: j["board"].__setitem__("cols", 8)), 3,
     "calib-0002.json: /edges/0/sections: 7 sections but the board has 8 columns")
if failures:
    sys.exit(f"{len(failures)} failed: {failures}")
print("ok: a tracked take's hand edits are refused")
