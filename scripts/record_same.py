#!/usr/bin/python3
"""Behaviour unchanged across a change of the record's code: runs the same seeded simulated sessions with two blurcue
binaries (BEFORE and AFTER), each into its own record, exports each record with both binaries, and compares.

  record_same.py --before BIN --after BIN --work DIR --demo REPO/results/demo [--protocols REPO/protocols]
                 [--stimuli REPO/stimuli] [--old-record DB ...] [--skip-runs]

What it compares (each a line OK / DIFFERS, exit 1 when anything differs):
  1. the export of BEFORE's record by BEFORE and by AFTER, byte for byte (every file): an older record read by the
     new code (a migrated copy in memory) exports the same tables;
  2. the export of AFTER's record by AFTER against (1)'s by BEFORE, byte for byte, but for trials.csv's answered_at
     (a wall-clock time) - the same sessions recorded by the new code export the same tables;
  3. the two records' rows, table by table (sqlite3's own reading, ordered by id), with the wall-clock times and the
     writer's host/lock columns masked, and tables or columns only AFTER has listed apart (the additions);
  4. each --old-record (e.g. the demo's study.sqlite) exported by both binaries, byte for byte.
Needs the demo's scene (scripts/demo.sh made it): the shipped protocols read ../results/demo/ and ../stimuli/.
"""
import argparse
import filecmp
import os
import shutil
import sqlite3
import subprocess
import sys

# The sessions: (protocol, participant). Seeds are derived from study and participant, so both binaries draw the same.
SESSIONS = [
    ("test1-static-grids", "P1"),
    ("test2-moving-balls", "P1"),
    ("pre-research-depth-matching", "P1"),
    ("quest-blur-difference", "P1"),
    ("quest-blur-difference", "P2"),
    ("staircase-ball-gain", "P1"),
    ("odd-one-out-grids", "P1"),
    ("yes-no-ball", "P1"),
    ("video-ball-depth", "P1"),
]
# Columns whose values are wall-clock times or the writer's process: differ between any two runs.
MASKED = {"created", "started", "ended", "answered_at", "lock_host", "lock_pid", "lock_token", "lock_heartbeat_ms",
          "host", "software_version"}


def run(cmd, **kw):
    result = subprocess.run(cmd, capture_output=True, text=True, **kw)
    if result.returncode != 0:
        sys.exit("failed (%d): %s\n%s%s" % (result.returncode, " ".join(cmd), result.stdout, result.stderr))
    return result.stdout


def export(binary, db, out):
    shutil.rmtree(out, ignore_errors=True)
    run([binary, "export", "--db", db, "--out", out])


def same_folders(a, b, ignore_column=None):
    """Differences between two export folders: files only in one, files that differ (trials.csv compared without
    `ignore_column`)."""
    problems = []
    names_a, names_b = set(os.listdir(a)), set(os.listdir(b))
    for name in sorted(names_a ^ names_b):
        problems.append("%s only in %s" % (name, a if name in names_a else b))
    for name in sorted(names_a & names_b):
        pa, pb = os.path.join(a, name), os.path.join(b, name)
        if filecmp.cmp(pa, pb, shallow=False):
            continue
        if ignore_column and name == "trials.csv" and drop_column(pa, ignore_column) == drop_column(pb, ignore_column):
            continue
        problems.append("%s differs" % name)
    return problems


def drop_column(path, column):
    import csv
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    if not rows or column not in rows[0]:
        return rows
    k = rows[0].index(column)
    return [r[:k] + r[k + 1:] for r in rows]


def table_rows(db):
    con = sqlite3.connect("file:%s?mode=ro" % db, uri=True)
    tables = [r[0] for r in con.execute("SELECT name FROM sqlite_schema WHERE type='table' ORDER BY name")]
    out = {}
    for t in tables:
        columns = [r[1] for r in con.execute("SELECT * FROM pragma_table_info(?)", (t,))]
        select = ", ".join("NULL" if c in MASKED else '"%s"' % c for c in columns)
        out[t] = (columns, con.execute("SELECT %s FROM \"%s\" ORDER BY rowid" % (select, t)).fetchall())
    version = con.execute("PRAGMA user_version").fetchone()[0]
    con.close()
    return version, out


def compare_records(before, after):
    vb, rb = table_rows(before)
    va, ra = table_rows(after)
    lines, ok = ["schema version %d -> %d" % (vb, va)], True
    for t in sorted(set(rb) | set(ra)):
        if t not in ra:
            lines.append("table %s missing after" % t)
            ok = False
            continue
        if t not in rb:
            lines.append("table %s added (%d rows)" % (t, len(ra[t][1])))
            continue
        cb, rows_b = rb[t]
        ca, rows_a = ra[t]
        added = [c for c in ca if c not in cb]
        if [c for c in cb if c not in ca]:
            lines.append("table %s lost columns" % t)
            ok = False
        keep = [ca.index(c) for c in cb]
        rows_a = [tuple(r[k] for k in keep) for r in rows_a]
        same = rows_a == rows_b
        ok &= same
        lines.append("table %s: %d rows %s%s" % (t, len(rows_b), "equal" if same else "DIFFER",
                                                 ("; columns added: " + ", ".join(added)) if added else ""))
    return ok, lines


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--before", required=True)
    ap.add_argument("--after", required=True)
    ap.add_argument("--work", required=True)
    ap.add_argument("--demo", required=True, help="a demo's results/demo folder (scene, calib.json, pictures, take, track)")
    here = os.path.dirname(os.path.abspath(__file__))
    ap.add_argument("--protocols", default=os.path.join(here, "..", "protocols"))
    ap.add_argument("--stimuli", default=os.path.join(here, "..", "stimuli"))
    ap.add_argument("--old-record", action="append", default=[])
    ap.add_argument("--skip-runs", action="store_true", help="reuse the records of an earlier call")
    a = ap.parse_args()
    work = os.path.abspath(a.work)
    # The repository's layout, so the shipped protocols find ../results/demo/ and ../stimuli/.
    if not a.skip_runs:
        shutil.rmtree(work, ignore_errors=True)
        os.makedirs(os.path.join(work, "results"))
        shutil.copytree(a.protocols, os.path.join(work, "protocols"))
        shutil.copytree(a.stimuli, os.path.join(work, "stimuli"))
        demo = os.path.join(work, "results", "demo")
        os.makedirs(demo)
        for name in ("scene", "calib.json", "pictures", "take", "track"):
            src = os.path.join(a.demo, name)
            (shutil.copytree if os.path.isdir(src) else shutil.copy)(src, os.path.join(demo, name))
        for which, binary in (("before", a.before), ("after", a.after)):
            db = os.path.join(work, which + ".sqlite")
            for protocol, participant in SESSIONS:
                run([binary, "run", os.path.join(work, "protocols", protocol + ".json"), "--participant", participant,
                     "--db", db, "--observer", "sim"])
    ok = True
    bb, ba, aa = (os.path.join(work, n) for n in ("out-before-by-before", "out-before-by-after", "out-after-by-after"))
    export(a.before, os.path.join(work, "before.sqlite"), bb)
    export(a.after, os.path.join(work, "before.sqlite"), ba)
    export(a.after, os.path.join(work, "after.sqlite"), aa)
    for title, problems in (("1. BEFORE's record exported by BEFORE and AFTER, byte for byte", same_folders(bb, ba)),
                            ("2. AFTER's record by AFTER vs BEFORE's by BEFORE (answered_at aside)",
                             same_folders(bb, aa, "answered_at"))):
        print(("OK       " if not problems else "DIFFERS  ") + title + " (%d files)" % len(os.listdir(bb)))
        for p in problems:
            print("         " + p)
        ok &= not problems
    same, lines = compare_records(os.path.join(work, "before.sqlite"), os.path.join(work, "after.sqlite"))
    print(("OK       " if same else "DIFFERS  ") + "3. the two records' rows (times, host, lock masked)")
    for line in lines:
        print("         " + line)
    ok &= same
    for i, old in enumerate(a.old_record):
        ob, oa = os.path.join(work, "old%d-by-before" % i), os.path.join(work, "old%d-by-after" % i)
        export(a.before, old, ob)
        export(a.after, old, oa)
        problems = same_folders(ob, oa)
        print(("OK       " if not problems else "DIFFERS  ") + "4. %s exported by BEFORE and AFTER, byte for byte "
              "(%d files)" % (old, len(os.listdir(ob))))
        for p in problems:
            print("         " + p)
        ok &= not problems
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
