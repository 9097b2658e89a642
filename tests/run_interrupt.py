#!/usr/bin/python3
"""Ctrl-C during `blurcue run`: the session stops between trials, says what was saved and how to go on, and exits 130
(128 + SIGINT, as a shell reports it); --resume then completes it. Before, run died at once and printed nothing.

  run_interrupt.py BLURCUE PROTOCOL DB

SIGINT is sent once the progress shows the second trial on its way (so the handler is in place), the record is read
with sqlite3 (not blurcue): the answers counted there must be what run said it saved, and the resumed session must end
completed. Exits 1 on any difference.
"""
import os
import re
import signal
import sqlite3
import subprocess
import sys
import time


def main():
    blurcue, protocol, db = sys.argv[1:4]
    for suffix in ("", "-wal", "-shm"):
        if os.path.exists(db + suffix):
            os.remove(db + suffix)
    args = [blurcue, "run", protocol, "--participant", "C1", "--observer", "sim", "--db", db, "--seed", "4"]
    p = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, bufsize=1)
    err = ""
    deadline = time.time() + 120
    while time.time() < deadline:
        ch = p.stderr.read(1)
        if not ch:
            break
        err += ch
        if re.search(r"trial [2-9]\d* of", err):
            p.send_signal(signal.SIGINT)
            break
    out, rest = p.communicate(timeout=120)
    err += rest
    print(out.strip())
    print(err.strip().splitlines()[-1] if err.strip() else "")
    bad = []
    if p.returncode != 130:
        bad.append("exit %d, expected 130 (128 + SIGINT)" % p.returncode)
    if not re.search(r"blurcue run: interrupted \(SIGINT\): every answer so far is saved in .*; continue the session "
                     r"with --resume", err):
        bad.append("no line saying what was saved and how to go on")
    said = re.search(r": (\d+) of (\d+) trials answered \((\d+) answered now\); not finished", out)
    answered = sqlite3.connect(db).execute("select count(*) from responses").fetchone()[0]
    if not said:
        bad.append("run's summary line does not say the session is unfinished")
    elif int(said.group(1)) != answered or answered == 0:
        bad.append("run said %s answered, the record holds %d" % (said.group(1), answered))
    r = subprocess.run(args + ["--resume"], capture_output=True, text=True)
    if r.returncode != 0 or "; completed" not in r.stdout:
        bad.append("--resume: exit %d, %s" % (r.returncode, (r.stdout + r.stderr).strip()[-200:]))
    for b in bad:
        print("BAD: " + b)
    print("ok: Ctrl-C stops run with every answer saved and --resume completes it" if not bad else "FAILED")
    sys.exit(1 if bad else 0)


if __name__ == "__main__":
    main()
