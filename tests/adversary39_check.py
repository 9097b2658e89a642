#!/usr/bin/python3
"""What an adversary found against issue 39 and what it must get now, each case on fresh copies, every input's bytes
compared before and after:

  merge of a record with a response whose trial was deleted       exit 3 naming the record (was map::at, exit 10)
  run on a record whose stored protocol text was edited            exit 3 naming the record (was exit 10)
  preview --out the protocol's own scene photo                     exit 2, the photo untouched (was overwritten)
  render --object ball:TEX --out TEX                               exit 2, the texture untouched (was overwritten)
  synth-take --out a longer take's folder                          the folder holds the new take alone (was a mix)
  synth-scene --out a folder holding a file of one's own           exit 3, the folder untouched (was written into)
  ar --track a folder whose track.csv lost its last row            exit 3 naming track.csv (was a shorter take)
  ar --track a folder with a calibration's pose edited             exit 3 naming the file and /pose/tvec/2 (was drawn)

usage: adversary39_check.py BLURCUE CLI_TEST_DIR    (the CLI tests' scene, calibration and protocols)
"""
import hashlib
import json
import os
import shutil
import sqlite3
import subprocess
import sys


def sha(path):
    return hashlib.sha256(open(path, "rb").read()).hexdigest()


def main():
    bc, t = sys.argv[1], sys.argv[2]
    w = os.path.join(t, "adversary39")
    shutil.rmtree(w, ignore_errors=True)
    os.makedirs(w)
    problems = []

    def run(args, code, text, untouched=()):
        before = {p: sha(p) for p in untouched}
        done = subprocess.run([bc] + args, capture_output=True, text=True, timeout=300)
        err = done.stderr.strip()
        if done.returncode != code or text not in err or (code and "\n" in err):
            problems.append(f"{' '.join(args[:2])}...: exit {done.returncode}, expected {code} with '{text}': {err}")
        for p, h in before.items():
            if sha(p) != h:
                problems.append(f"{' '.join(args[:2])}...: {p} changed")

    protocol = os.path.join(t, "protocols", "test1-static-grids.json")
    db = os.path.join(w, "s.sqlite")
    subprocess.run([bc, "run", protocol, "--participant", "P1", "--db", db, "--observer", "sim", "--stop-after", "3"],
                   check=True, capture_output=True)
    edited = os.path.join(w, "edited.sqlite")
    shutil.copy(db, edited)
    con = sqlite3.connect(edited)
    con.execute("DELETE FROM trials WHERE id = (SELECT min(trial_id) FROM responses)")
    con.commit()
    con.close()
    run(["merge", edited, "--out", os.path.join(w, "m.sqlite")], 3, "edited.sqlite: a row refers to trial",
        [edited])
    text = os.path.join(w, "text.sqlite")
    shutil.copy(db, text)
    con = sqlite3.connect(text)
    con.execute("UPDATE protocol_versions SET json = replace(json, '\"name\"', '\"name\" ')")
    con.execute("UPDATE protocol_versions SET json = replace(json, 'grids', 'grids ')")
    con.commit()
    con.close()
    run(["run", protocol, "--participant", "P2", "--db", text, "--observer", "sim", "--stop-after", "1"], 3,
        "text.sqlite: the protocol text stored under hash", [text])
    photo = os.path.join(t, "scene", "scene.png")
    run(["preview", protocol, "--out", photo], 2, "is also the input the protocol's scene.background", [photo])
    texture = os.path.join(w, "tex.png")
    shutil.copy(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "stimuli", "grid.png"), texture)
    run(["render", "--calib", os.path.join(t, "calib.json"), "--background", photo, "--object", "ball:" + texture,
         "--out", texture], 2, "is also the input --object", [texture])
    take = os.path.join(w, "take")
    for frames in ("3", "1"):
        subprocess.run([bc, "synth-take", "--out", take, "--frames", frames, "--quiet"], check=True,
                       capture_output=True)
    left = sorted(f for f in os.listdir(take) if f.startswith("frame-"))
    if left != ["frame-0000.png"]:
        problems.append(f"synth-take --frames 1 over a 3-frame take left {left}")
    mine = os.path.join(w, "mine")
    os.makedirs(mine)
    with open(os.path.join(mine, "scene.png"), "wb") as f:
        f.write(open(os.path.join(take, "frame-0000.png"), "rb").read())
    with open(os.path.join(mine, "notes.txt"), "w") as f:
        f.write("my notes\n")
    run(["synth-scene", "--out", mine, "--quiet"], 3, "holds notes.txt, which this command did not write",
        [os.path.join(mine, "scene.png"), os.path.join(mine, "notes.txt")])
    if sorted(os.listdir(mine)) != ["notes.txt", "scene.png"]:
        problems.append(f"synth-scene wrote into a folder of one's own: {sorted(os.listdir(mine))}")
    subprocess.run([bc, "synth-take", "--out", take, "--frames", "3", "--supersample", "1", "--quiet"], check=True,
                   capture_output=True)
    track = os.path.join(w, "track")
    subprocess.run([bc, "track", os.path.join(take, "take.avi"), "--camera", os.path.join(take, "camera.json"),
                    "--out", track, "--quiet"], check=True, capture_output=True)
    ar = [os.path.join(take, "take.avi"), "--track"]
    cut = os.path.join(w, "track-cut")
    shutil.copytree(track, cut)
    lines = open(os.path.join(cut, "track.csv")).read().splitlines(keepends=True)
    with open(os.path.join(cut, "track.csv"), "w") as f:
        f.writelines(lines[:-1])
    run(["ar"] + ar + [cut, "--ball", "50,125", "--out", os.path.join(w, "cut.avi"), "--quiet"], 3,
        "track.csv: has 2 frames, but calib-0002.json holds a calibration of frame 2",
        [os.path.join(cut, "track.csv")])
    moved = os.path.join(w, "track-moved")
    shutil.copytree(track, moved)
    calib = os.path.join(moved, "calib-0001.json")
    text = open(calib).read()
    data = json.loads(text)
    data["pose"]["tvec"][2] += 0.5
    with open(calib, "w") as f:
        json.dump(data, f)
    run(["ar"] + ar + [moved, "--ball", "50,125", "--out", os.path.join(w, "moved.avi"), "--quiet"], 3,
        "calib-0001.json: /pose/tvec/2: must be", [calib])
    for p in problems:
        print("FAIL:", p)
    if problems:
        return 1
    print("ok: an edited record's dangling row and protocol text refused (exit 3), preview and render refuse to write "
          "over their inputs (exit 2), synth-take replaces a take whole, synth-scene refuses a folder of one's own, a track "
          "folder with its last row cut or a pose edited is refused (exit 3); every input byte-identical")
    return 0


if __name__ == "__main__":
    sys.exit(main())
