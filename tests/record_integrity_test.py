#!/usr/bin/python3
"""Nothing an experimenter owns is destroyed (issue 39), end to end through the blurcue executable.

usage: record_integrity_test.py CASE BLURCUE DIR   (DIR: the CLI tests' folder, with protocols/ and the scene)

schema_numbers  a record whose schema number was set by hand (-5, -2147483648, -1, 0, 1 and 6 on a current record,
                one above the current version) is refused by export, report, sessions, merge and run: exit 3, one line
                naming the record and the number, the file byte for byte as it was and no output left behind. (-5
                crashed export, run and report; -1 was std::bad_alloc, exit 10; 0, 1 and 6 replayed the migrations.)
study_names     studies named "pilot 1", "pilot/1", 72 CJK characters (216 bytes) and "a<zero-width space>b": export and
                report exit 0, each study's summary and each report section's charts are files of their own (the
                first two used to share one set of charts; the long name stopped export and report with exit 3).
Prints "ok: ..." and exits 0, or names the first failure and exits 1.
"""
import html
import json
import os
import re
import shutil
import sqlite3
import subprocess
import sys


def fail(what):
    print("FAIL: " + what)
    sys.exit(1)


def run(argv, timeout=300):
    env = dict(os.environ)
    env.pop("DISPLAY", None)
    return subprocess.run(argv, capture_output=True, text=True, errors="replace", timeout=timeout, env=env)


def protocol(protocols, work, name, file_name):
    """The shipped test 1 renamed `name`, its scene's paths made absolute, written to WORK/FILE_NAME."""
    doc = json.load(open(os.path.join(protocols, "test1-static-grids.json"), encoding="utf-8"))
    doc["name"] = name
    for key, value in list(doc.get("scene", {}).items()):
        if isinstance(value, str) and key != "show" and not os.path.isabs(value):
            doc["scene"][key] = os.path.normpath(os.path.join(protocols, value))
    path = os.path.join(work, file_name)
    with open(path, "w", encoding="utf-8") as f:
        json.dump(doc, f, ensure_ascii=False)
    return path


def record(bc, protocol_path, db, participant):
    r = run([bc, "run", protocol_path, "--participant", participant, "--db", db, "--observer", "sim"])
    if r.returncode != 0:
        fail("run %s for %s: exit %d: %s" % (protocol_path, participant, r.returncode, r.stderr.strip()[-400:]))


def file_bytes(path):
    with open(path, "rb") as f:
        return f.read()


def schema_numbers(bc, protocols, work):
    base = os.path.join(work, "base.sqlite")
    test1 = protocol(protocols, work, "numbers", "numbers.json")
    record(bc, test1, base, "P1")
    con = sqlite3.connect(base)
    con.execute("PRAGMA journal_mode = DELETE")  # one file: what is compared byte for byte
    current = con.execute("PRAGMA user_version").fetchone()[0]
    con.close()
    checked = 0
    for number in (-5, -2147483648, -1, 0, 1, 6, current + 1):
        db = os.path.join(work, "n%d.sqlite" % number)
        shutil.copy(base, db)
        con = sqlite3.connect(db)
        con.execute("PRAGMA user_version = %d" % number)
        con.close()
        before = file_bytes(db)
        out = os.path.join(work, "out-%d" % number)
        commands = {
            "export": [bc, "export", "--db", db, "--out", out],
            "report": [bc, "report", "--db", db, "--out", out],
            "sessions": [bc, "sessions", "--db", db],
            "merge": [bc, "merge", db, "--out", out + ".sqlite"],
            "run": [bc, "run", test1, "--participant", "P2", "--db", db, "--observer", "sim"],
        }
        for what, argv in commands.items():
            r = run(argv)
            lines = [line for line in r.stderr.splitlines() if line.strip()]
            if r.returncode != 3:
                fail("%s of a record numbered %d: exit %d, expected 3: %s" % (what, number, r.returncode, r.stderr))
            want = "blurcue: %s: record schema number %d " % (db, number)
            if len(lines) != 1 or not lines[0].startswith(want):
                fail("%s of a record numbered %d: expected one line starting %r, got %r" % (what, number, want, lines))
            if file_bytes(db) != before:
                fail("%s changed the record numbered %d" % (what, number))
            for left in (db + "-wal", db + "-journal", out, out + ".sqlite"):
                if os.path.exists(left):
                    fail("%s of a record numbered %d left %s" % (what, number, left))
            checked += 1
    print("ok: %d refusals (export, report, sessions, merge, run x 7 schema numbers): exit 3, one line naming the "
          "record and the number, the record unchanged" % checked)


def section_charts(index):
    """Each section of index.html (by its heading) with the image files it shows."""
    sections = {}
    for part in re.split(r"(?=<h2)", index):
        heading = re.match(r"<h2[^>]*>(.*?)</h2>", part, re.S)
        if heading:
            sections[html.unescape(re.sub(r"<[^>]+>", "", heading.group(1)))] = set(
                html.unescape(src) for src in re.findall(r"<img[^>]+src=['\"]([^'\"]+)['\"]", part))
    return sections


def study_names(bc, protocols, work):
    names = ["pilot 1", "pilot/1", "\u6f22" * 72, "a\u200bb"]
    db = os.path.join(work, "names.sqlite")
    for i, name in enumerate(names):
        path = protocol(protocols, work, name, "names-%d.json" % i)
        for participant in ("P1", "P2"):  # two: the names are the question, not the models across participants
            record(bc, path, db, participant)
    r = run([bc, "export", "--db", db, "--out", os.path.join(work, "tables")])
    if r.returncode != 0:
        fail("export: exit %d: %s" % (r.returncode, r.stderr))
    summaries = sorted(f for f in os.listdir(os.path.join(work, "tables")) if f.startswith("summary-"))
    if len(summaries) != len(names):
        fail("export wrote %d summaries for %d studies: %s" % (len(summaries), len(names), summaries))
    if max(len(f.encode("utf-8")) for f in summaries) > 112:
        fail("a summary's file name is over 112 bytes: %s" % summaries)
    out = os.path.join(work, "report")
    r = run([bc, "report", "--db", db, "--out", out, "--boot", "20"], timeout=600)
    if r.returncode != 0:
        fail("report: exit %d: %s" % (r.returncode, r.stderr[-1500:]))
    index = open(os.path.join(out, "index.html"), encoding="utf-8").read()
    sections = section_charts(index)
    seen = {}
    for name in names:
        titled = [t for t in sections if t.startswith("study " + name)]
        if len(titled) != 1:
            fail("report: %d sections titled 'study %s' among %s" % (len(titled), name, sorted(sections)))
        charts = sections[titled[0]]
        if not charts:
            fail("report: the section of %r shows no chart" % name)
        for chart in charts:
            if chart in seen:
                fail("report: %s is shown in the sections of %r and %r" % (chart, seen[chart], name))
            seen[chart] = name
            if not os.path.isfile(os.path.join(out, chart)):
                fail("report: the section of %r shows %s, which is not there" % (name, chart))
            if len(os.path.basename(chart).encode("utf-8")) > 104:
                fail("report: a chart's file name is over 104 bytes: %s" % chart)
    # And across the page (the model comparison's section has a chart per study too): no file shown twice.
    shown = [html.unescape(src) for src in re.findall(r"<img[^>]+src=['\"]([^'\"]+)['\"]", index)]
    if len(shown) != len(set(shown)) or len(shown) < 2 * len(names):
        fail("report: %d charts shown, %d distinct, expected at least %d: %s" % (
            len(shown), len(set(shown)), 2 * len(names), shown))
    print("ok: 4 studies named 'pilot 1', 'pilot/1', 72 CJK characters and 'a<ZWSP>b': export and report exit 0, "
          "%d summaries and %d charts, each study's its own" % (len(summaries), len(shown)))


def main():
    case, bc, folder = sys.argv[1:4]
    protocols = os.path.abspath(os.path.join(folder, "protocols"))
    work = os.path.abspath(os.path.join(folder, "record-" + case))
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    {"schema_numbers": schema_numbers, "study_names": study_names}[case](bc, protocols, work)


if __name__ == "__main__":
    main()
