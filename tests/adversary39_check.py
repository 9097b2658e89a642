#!/usr/bin/python3
"""What an adversary found against issue 39 and what it must get now, each case on fresh copies, every input's bytes
compared before and after:

  merge of a record with a response whose trial was deleted       exit 3 naming the record (was map::at, exit 10)
  run on a record whose stored protocol text was edited            exit 3 naming the record (was exit 10)
  preview --out the protocol's own scene photo                     exit 2, the photo untouched (was overwritten)
  render --object ball:TEX --out TEX                               exit 2, the texture untouched (was overwritten)
  synth-take --out a longer take's folder                          the folder holds the new take alone (was a mix)

usage: adversary39_check.py BLURCUE CLI_TEST_DIR    (the CLI tests' scene, calibration and protocols)
"""
import hashlib
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
    for p in problems:
        print("FAIL:", p)
    if problems:
        return 1
    print("ok: an edited record's dangling row and protocol text refused (exit 3), preview and render refuse to write "
          "over their inputs (exit 2), synth-take replaces a take whole; every input byte-identical")
    return 0


if __name__ == "__main__":
    sys.exit(main())
