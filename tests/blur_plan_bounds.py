#!/usr/bin/python3
"""validate's blur plan for a procedure's trials against what run records (the FTE's staircase of grid cards: validate
said "0 of 80 trials" per pixel while run drew 138 of 226 per pixel).

  blur_plan_bounds.py BLURCUE PROTOCOL DB

validate's line "the N procedure trials are planned at their level as each is shown: K would be per pixel ... at the
procedure's least level, M at its largest" bounds what any session of the protocol can record: a trial is drawn per pixel
at some level only if it is at the largest (at most M of the N are), and one radius only if it is at the least (at most
N - K are). The session is run with the simulated observer and every answered trial's recorded blur_plan (responses'
shown JSON) counted, the record read with sqlite3 (not blurcue). Exits 1 when the record breaks a bound, or when the
session shows nothing that could break one (no per-pixel trial and no one-radius trial where the bounds leave room).
"""
import json
import os
import re
import sqlite3
import subprocess
import sys


def main():
    blurcue, protocol, db = sys.argv[1:4]
    v = subprocess.run([blurcue, "validate", protocol], capture_output=True, text=True)
    if v.returncode != 0:
        sys.exit("validate exit %d: %s" % (v.returncode, v.stderr.strip()))
    m = re.search(r"the (\d+) procedure trials are planned at their level as each is shown: (\d+) would be per pixel"
                  r".* at the procedure's least level, (\d+) at its largest", v.stdout)
    if not m:
        sys.exit("validate printed no plan for the procedure's trials:\n" + v.stdout)
    n, least, most = map(int, m.groups())
    for suffix in ("", "-wal", "-shm"):  # a fresh record each time (the test's own file)
        if os.path.exists(db + suffix):
            os.remove(db + suffix)
    r = subprocess.run([blurcue, "run", protocol, "--participant", "P1", "--observer", "sim", "--db", db, "--seed", "5"],
                       capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit("run exit %d: %s" % (r.returncode, r.stderr.strip()))
    # A trial skipped once its procedure stopped records no scene shown (no blur_plan): only those shown count.
    plans = [json.loads(s).get("blur_plan") for (s,) in sqlite3.connect(db).execute(
        "select shown from responses where shown is not null")]
    per_pixel, one = plans.count("per_pixel"), plans.count("one_radius")
    print("validate: %d procedure trials, per pixel %d at the least level, %d at the largest; run recorded %d per pixel, "
          "%d one radius" % (n, least, most, per_pixel, one))
    bad = []
    if per_pixel > most:
        bad.append("%d per-pixel trials recorded, validate allowed at most %d" % (per_pixel, most))
    if one > n - least:
        bad.append("%d one-radius trials recorded, validate allowed at most %d" % (one, n - least))
    if per_pixel == 0 or one == 0:
        bad.append("the session drew only one plan: nothing here tests the bounds")
    for b in bad:
        print("BAD: " + b)
    print("ok: the record keeps within validate's blur plan" if not bad else "FAILED")
    sys.exit(1 if bad else 0)


if __name__ == "__main__":
    main()
