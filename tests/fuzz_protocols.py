#!/usr/bin/python3
"""Protocol fuzz test: a seeded generator of mutated protocols, each through `blurcue validate` and, when accepted,
a short simulated `blurcue run`.

usage: fuzz_protocols.py BLURCUE PROTOCOLS_DIR WORK_DIR [--seed N] [--count N] [--keep]

Without --seed each run draws a new seed (from the clock and the process id), so every CI run tries other mutants;
the first line printed is the seed and the command that reproduces the run.

PROTOCOLS_DIR holds the shipped protocols pointed at a real scene (tests/copy_protocols.cmake). Each mutant is one
of them with 1-3 mutations: a deleted key, a wrong type, an extreme number (nan, 1e400, 1e308, 1e-300, -1, 0,
2^64, ...), deep nesting (as written in the file, up to 100000 levels), an odd string (empty, NUL, unicode, 100 KB),
a file cut short or with bytes that are not UTF-8, a bad path (a folder, /dev/zero, /proc/self/mem, a FIFO, a
missing file, a file that is not an image or not a calibration, an image of the wrong size), another valid enum
value, a repeated or multiplied list.

Must hold, for every mutant: no signal, no exit 10 (or any code but 0, 2, 3), no timeout; a rejection names the
protocol file and the field on every stderr line (libpng warnings aside): "FILE: /json/pointer: ..." or, for a text
that is not JSON (empty, cut short, not UTF-8, nested too deep), "FILE: not valid JSON ... line N, column M";
an accepted protocol runs 3 trials (--stop-after 3) with the simulated observer and exits 0 - or run refuses it for
that observer (exit 2 or 3) and `validate --plan --observer sim` refuses it with the same line (a protocol a person
can run that the simulated observer cannot answer, counted apart). Prints the counts and
every failure with its seed and mutations; exits 1 on any failure. Reproduce one mutant with --seed S --count 1 --first K (K is its index) --keep.
"""
import argparse
import copy
import json
import math
import os
import random
import re
import shutil
import struct
import subprocess
import sys
import time
import zlib

VALIDATE_TIMEOUT_S = 60
RUN_TIMEOUT_S = 120

PATH_FIELDS = [("scene", "background"), ("scene", "board_free"), ("scene", "calib"), ("content", "image"),
               ("content", "texture"), ("content", "real_photos")]


def png(path, width, height, depth=8, colour=2):
    """A PNG of a grey gradient (colour 0: grey, 2: RGB), written without any imaging library."""
    channels = {0: 1, 2: 3}[colour]
    bytes_per = channels * depth // 8
    rows = b""
    for y in range(height):
        value = (y * 255 // max(1, height - 1)) & 0xFF
        rows += b"\x00" + bytes([value]) * (width * bytes_per)

    def chunk(tag, data):
        return struct.pack(">I", len(data)) + tag + data + struct.pack(">I", zlib.crc32(tag + data) & 0xFFFFFFFF)

    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n")
        f.write(chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, depth, colour, 0, 0, 0)))
        f.write(chunk(b"IDAT", zlib.compress(rows)))
        f.write(chunk(b"IEND", b""))


def make_files(work):
    """Files for the bad-path mutations; returns name -> absolute path."""
    files = {}
    d = os.path.join(work, "files")
    os.makedirs(d, exist_ok=True)
    files["folder"] = os.path.join(d, "a-folder.png")
    os.makedirs(files["folder"], exist_ok=True)
    files["missing"] = os.path.join(d, "no-such-file.png")
    files["dev_zero"] = "/dev/zero"
    files["proc_mem"] = "/proc/self/mem"
    files["fifo"] = os.path.join(d, "fifo.json")
    if not os.path.exists(files["fifo"]):
        os.mkfifo(files["fifo"])
    files["text"] = os.path.join(d, "not-an-image.png")
    with open(files["text"], "w") as f:
        f.write("hello, not an image\n")
    files["empty"] = os.path.join(d, "empty.json")
    open(files["empty"], "w").close()
    files["deep_json"] = os.path.join(d, "deep.json")
    with open(files["deep_json"], "w") as f:
        f.write("[" * 100000 + "]" * 100000)
    files["huge_number_json"] = os.path.join(d, "huge.json")
    with open(files["huge_number_json"], "w") as f:
        f.write('{"camera": {"focal_length_mm": 1e400}}')
    files["other_json"] = os.path.join(d, "other.json")
    with open(files["other_json"], "w") as f:
        f.write('{"name": "not a calibration", "version": 1}')
    files["small_png"] = os.path.join(d, "small.png")
    png(files["small_png"], 64, 48)
    files["thin_png"] = os.path.join(d, "thin.png")
    png(files["thin_png"], 4000, 2, colour=0)
    files["tiny_png"] = os.path.join(d, "tiny.png")
    png(files["tiny_png"], 1, 1, colour=0)
    files["grey16_png"] = os.path.join(d, "grey16.png")
    png(files["grey16_png"], 96, 64, depth=16, colour=0)
    return files


class Mutator:
    """Mutations of a protocol held as Python values; raw text (1e400, NaN, deep nesting) goes in as a placeholder
    string replaced after dumping."""

    def __init__(self, rng, files, scene_dir):
        self.rng = rng
        self.files = files
        self.scene_dir = scene_dir
        self.raw = {}

    def placeholder(self, text):
        key = "@@RAW%d@@" % len(self.raw)
        self.raw[key] = text
        return key

    def paths(self, value, here=()):
        """Every (container, key) below value."""
        out = []
        if isinstance(value, dict):
            for k, v in value.items():
                out.append((value, k, here + (k,)))
                out += self.paths(v, here + (k,))
        elif isinstance(value, list):
            for i, v in enumerate(value):
                out.append((value, i, here + (i,)))
                out += self.paths(v, here + (i,))
        return out

    def pick(self, doc, want=None):
        spots = [s for s in self.paths(doc) if want is None or want(s[0][s[1]])]
        return self.rng.choice(spots) if spots else None

    def extreme_number(self):
        return self.rng.choice([
            0, -1, 1, 2, 0.5, 1e-300, -1e-300, 1e308, -1e308, 2 ** 64, 2 ** 64 - 1, 2 ** 63, -2 ** 63, 2 ** 31,
            10 ** 30, 1e6, 100000, 10001, 16385, 3.7, -0.0, 1e-7, 60001, 0.09, 101, 150, 7681,
            self.placeholder("1e400"), self.placeholder("-1e400"), self.placeholder("NaN"),
            self.placeholder("Infinity"), self.placeholder("1" + "0" * 400),
        ])

    def odd_string(self):
        return self.rng.choice([
            "", " ", "\u0000", "a\u0000b", "\n", "line\nbreak", "\t", "é漢字🙂", "\u202e", "\ufeff",
            "a" * 100000, "x" * 5000, "\u6f22" * 30000, "é" * 41, "../../../../../../etc/passwd", "%s%n%x", "{distance_m}", "~/~0/~1",
            "soccer", "wood", "measured", "until_response", "Escape", "F13", "KP_10", "\\",
            "NaN", "1e400", "-1", "0",
        ])

    def bad_path(self):
        name = self.rng.choice(sorted(self.files))
        return self.files[name]

    def deep(self, depth):
        return self.placeholder("[" * depth + "1" + "]" * depth)

    def mutate(self, doc):
        """One mutation; returns its description."""
        kind = self.rng.choice(["delete", "delete", "type", "type", "extreme", "extreme", "extreme", "deep",
                                "string", "string", "path", "path", "path", "enum", "enum", "list", "scale",
                                "scale", "add"])
        if kind == "delete":
            s = self.pick(doc)
            if s is None:
                return "nothing to delete"
            container, key, where = s
            del container[key]
            return "delete %s" % "/".join(map(str, where))
        if kind == "type":
            s = self.pick(doc)
            if s is None:
                return "nothing to retype"
            container, key, where = s
            container[key] = self.rng.choice([{}, [], "x", True, False, None, 3, 2.5, {"a": 1}, [1, 2], -7])
            return "type %s = %s" % ("/".join(map(str, where)), json.dumps(container[key]))
        if kind == "extreme":
            s = self.pick(doc, lambda v: isinstance(v, (int, float)) and not isinstance(v, bool))
            if s is None:
                return "no number"
            container, key, where = s
            container[key] = self.extreme_number()
            return "extreme %s = %s" % ("/".join(map(str, where)), self.raw.get(container[key], container[key]))
        if kind == "deep":
            s = self.pick(doc)
            if s is None:
                return "nothing to nest"
            container, key, where = s
            depth = self.rng.choice([3, 40, 63, 64, 65, 1000, 100000])
            container[key] = self.deep(depth)
            return "deep %s depth %d" % ("/".join(map(str, where)), depth)
        if kind == "string":
            s = self.pick(doc, lambda v: isinstance(v, str))
            if s is None:
                return "no string"
            container, key, where = s
            container[key] = self.odd_string()
            return "string %s = %r" % ("/".join(map(str, where)), container[key][:40])
        if kind == "path":
            section, field = self.rng.choice(PATH_FIELDS)
            if not isinstance(doc.get(section), dict):
                doc[section] = {}
            value = self.bad_path()
            if self.rng.random() < 0.3:
                # A valid file of the wrong kind: the scene's own files where another is expected.
                value = os.path.join(self.scene_dir, self.rng.choice(
                    ["scene.png", "scene-no-board.png", "camera.json", "truth.json", "../calib.json"]))
            if field == "real_photos" and self.rng.random() < 0.5:
                value = value + "{distance_m}"
            doc[section][field] = value
            return "path /%s/%s = %s" % (section, field, value)
        if kind == "enum":
            choices = {
                "task": ["forced_choice", "adjustment"], "counterbalance": ["none", "swap_copies", "by_participant"],
                "type": ["grid", "ball", "picture"], "show": ["background", "board_free"],
                "order": ["shuffled", "ascending", "descending"], "texture": ["soccer", "wood", "grid", "face"],
                "stimulus_ms": ["until_response", 100, 10, 60000], "shuffle": [True, False],
                "left": ["none", "measured", "estimated", "fitted", 0, 3.5, 100],
                "right": ["none", "measured", "estimated", "fitted", 0, 3.5, 100],
                "parameter": ["cutoff"], "block": ["task1", "task2", "main"],
            }
            spots = [s for s in self.paths(doc) if s[1] in choices]
            if not spots:
                return "no enum"
            container, key, where = self.rng.choice(spots)
            container[key] = self.rng.choice(choices[key])
            return "enum %s = %s" % ("/".join(map(str, where)), json.dumps(container[key]))
        if kind == "list":
            s = self.pick(doc, lambda v: isinstance(v, list) and v)
            if s is None:
                return "no list"
            container, key, where = s
            how = self.rng.choice(["repeat-one", "times-40", "empty", "reverse"])
            lst = container[key]
            if how == "repeat-one":
                lst.append(copy.deepcopy(self.rng.choice(lst)))
            elif how == "times-40":
                container[key] = [copy.deepcopy(x) for x in lst * 40]
            elif how == "empty":
                container[key] = []
            else:
                lst.reverse()
            return "list %s %s" % ("/".join(map(str, where)), how)
        if kind == "scale":
            s = self.pick(doc, lambda v: isinstance(v, (int, float)) and not isinstance(v, bool))
            if s is None:
                return "no number"
            container, key, where = s
            factor = self.rng.choice([0.5, 2, 3, 10, 0.1])
            value = container[key] * factor
            container[key] = int(value) if isinstance(container[key], int) and value == int(value) else value
            return "scale %s x %g" % ("/".join(map(str, where)), factor)
        # add: a key where one may or may not belong
        s = self.pick(doc, lambda v: isinstance(v, dict))
        target = s[0][s[1]] if s else doc
        key = self.rng.choice(["repetitions", "sides", "adjust", "practice", "breaks", "extra", "factors", "edge",
                               "section", "speed_cm_s", "distance_m", "from_edge", "to_edge", "cutoff"])
        target[key] = self.rng.choice([1, 2, 11, 0, "x", [1, 2], {"left": "measured", "right": "none"},
                                       {"count": 3}, {"every_trials": 1}, {"levels": [2, 4]}, {"edge": [1, 2]}])
        return "add %s = %s" % (key, json.dumps(target[key]))


def stderr_lines(text):
    # libpng's own warnings (e.g. "libpng warning: iCCP: ...") are not blurcue's messages.
    return [line for line in text.splitlines() if line.strip() and not line.startswith("libpng")]


# What a problem line says after "FILE: ": the field as a JSON pointer ("/blocks/0/factors/edge: ...", "/: ..." for the
# whole document), or, for a text that is not JSON at all (empty, cut short, not UTF-8, nested too deep), where in it
# the parser stopped. Anything else names no field.
FIELD_OR_PLACE = re.compile(r"/\S*?: \S|not valid JSON\b.*\bline \d+, column \d+")


def refusal_problems(stderr, path):
    """Why a refusal's stderr does not name the protocol file and the field on every line ([] when it does). The
    lines: "blurcue: FILE: FIELD...", then "FILE: FIELD..." per further problem, then "(N problems)"."""
    lines = stderr_lines(stderr)
    if not lines:
        return ["no message"]
    out = []
    if len(lines) > 1 and lines[-1].startswith("('blurcue init DIR --from EXAMPLE'"):
        lines = lines[:-1]  # the advice after a protocol whose files are missing
    m = re.fullmatch(r"\((\d+) problems(?:, the first (\d+) listed)?\)", lines[-1])
    if m and len(lines) != int(m.group(2) or m.group(1)) + 1:
        out.append("%d lines for %s problems (an escaped newline joins two?)" % (len(lines) - 1,
                                                                              m.group(2) or m.group(1)))
    body = lines[:-1] if m else lines
    for i, line in enumerate(body):
        prefix = ("blurcue: " if i == 0 else "") + path + ": "
        if not line.startswith(prefix):
            out.append("does not name the file: " + line[:200])
        elif not FIELD_OR_PLACE.match(line[len(prefix):]):
            out.append("names no field: " + line[:200])
        if "\\n" + path in line or "\\n(" in line:
            out.append("joins two problems: " + line[:200])
    return out


def observer_refusal_agrees(blurcue, path, run_stderr, env):
    """True when `validate --plan --observer sim` refuses the protocol with the line `run --observer sim` refused it
    with: the two agree for that observer (validate without --observer checks the protocol for a person)."""
    try:
        v = subprocess.run([blurcue, "validate", path, "--plan", "--observer", "sim"], capture_output=True, text=True,
                           errors="replace", timeout=VALIDATE_TIMEOUT_S, env=env)
    except subprocess.TimeoutExpired:
        return False
    line = run_stderr.strip().splitlines()[-1] if run_stderr.strip() else ""
    return v.returncode == 3 and line != "" and line in v.stderr

def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("blurcue")
    ap.add_argument("protocols")
    ap.add_argument("work")
    ap.add_argument("--seed", type=int, default=None, help="by default a new one each run (printed first)")
    ap.add_argument("--count", type=int, default=600)
    ap.add_argument("--first", type=int, default=0, help="index of the first mutant (reproduce one)")
    ap.add_argument("--keep", action="store_true", help="keep every mutant file")
    args = ap.parse_args()
    if args.seed is None:
        args.seed = (time.time_ns() // 1000 ^ os.getpid() << 20) % 10 ** 9
    # First: the seed and how to run these mutants again (a failure names its index for --first K --count 1).
    print("fuzz seed %d; reproduce: %s %s %s %s %s --seed %d --count %d --first %d" % (
        args.seed, sys.executable, os.path.abspath(__file__), args.blurcue, os.path.abspath(args.protocols),
        os.path.abspath(args.work), args.seed,
        args.count, args.first), flush=True)

    work = os.path.abspath(args.work)
    shutil.rmtree(os.path.join(work, "mutants"), ignore_errors=True)
    os.makedirs(os.path.join(work, "mutants"), exist_ok=True)
    files = make_files(work)
    protocols_dir = os.path.abspath(args.protocols)
    scene_dir = os.path.join(os.path.dirname(protocols_dir), "scene")
    shipped = sorted(f for f in os.listdir(protocols_dir) if f.endswith(".json") and "schema" not in f)
    originals = {f: json.load(open(os.path.join(protocols_dir, f))) for f in shipped}
    env = dict(os.environ)
    env.pop("DISPLAY", None)  # the simulated observer runs headless

    counts = {"mutants": 0, "rejected": 0, "accepted": 0, "ran": 0, "crash": 0, "exit10": 0, "other_exit": 0,
              "timeout": 0, "accepted_then_failed": 0, "refused_for_the_observer": 0, "unnamed_message": 0}
    failures = []
    started = time.time()
    print("%d mutants of %s" % (args.count, ", ".join(shipped)), flush=True)
    for index in range(args.first, args.first + args.count):
        rng = random.Random("%d/%d" % (args.seed, index))
        base = rng.choice(shipped)
        doc = copy.deepcopy(originals[base])
        mutator = Mutator(rng, files, scene_dir)
        mutations = [mutator.mutate(doc) for _ in range(rng.choice([1, 1, 2, 3]))]
        text = json.dumps(doc, indent=1, ensure_ascii=rng.random() < 0.5)
        for key, raw in mutator.raw.items():
            text = text.replace(json.dumps(key), raw)
        data = text.encode("utf-8", errors="surrogatepass")
        if rng.random() < 0.08:
            # The file itself: cut short, a byte that is not UTF-8, a byte-order mark, a duplicated key, or empty.
            how = rng.choice(["truncate", "bad-utf8", "bom", "duplicate-key", "empty"])
            at = rng.randrange(len(data) + 1)
            if how == "truncate":
                data = data[:at]
            elif how == "bad-utf8":
                data = data[:at] + rng.choice([b"\xff", b"\xc3", b"\xed\xa0\x80", b"\x00"]) + data[at:]
            elif how == "bom":
                data = b"\xef\xbb\xbf" + data
            elif how == "duplicate-key":
                data = data.replace(b'"name":', b'"name": "dup", "name":', 1)
            else:
                data = b""
            mutations.append("file " + how)
        # Mutants live beside the shipped protocols so their relative paths still resolve.
        path = os.path.join(protocols_dir, "fuzz-%d.json" % index)
        with open(path, "wb") as f:
            f.write(data)
        counts["mutants"] += 1
        label = "mutant %d (seed %d) of %s: %s" % (index, args.seed, base, "; ".join(mutations))

        def fail(what, detail):
            failures.append("%s\n  %s: %s" % (label, what, detail.strip()[-600:]))
            shutil.copy(path, os.path.join(work, "mutants", os.path.basename(path)))

        try:
            v = subprocess.run([args.blurcue, "validate", path], capture_output=True, text=True, errors="replace",
                               timeout=VALIDATE_TIMEOUT_S, env=env)
        except subprocess.TimeoutExpired:
            counts["timeout"] += 1
            fail("validate timed out after %d s" % VALIDATE_TIMEOUT_S, "")
            os.remove(path)
            continue
        if v.returncode < 0:
            counts["crash"] += 1
            fail("validate killed by signal %d" % -v.returncode, v.stderr)
        elif v.returncode == 10:
            counts["exit10"] += 1
            fail("validate exit 10", v.stderr)
        elif v.returncode in (2, 3):
            counts["rejected"] += 1
            problems = refusal_problems(v.stderr, path)
            if problems:
                counts["unnamed_message"] += 1
                fail("rejection does not name the protocol file and the field on every line: " + problems[0],
                     v.stderr)
        elif v.returncode == 0:
            counts["accepted"] += 1
            db = os.path.join(work, "run.sqlite")
            for suffix in ("", "-wal", "-shm", "-journal"):
                if os.path.exists(db + suffix):
                    os.remove(db + suffix)
            # Participant information the mutant asks for: a valid answer to each field (its own range or choices).
            info = []
            fields = doc.get("participant_info") if isinstance(doc, dict) else None
            for f in fields if isinstance(fields, list) else []:
                if not isinstance(f, dict) or "key" not in f:
                    continue
                kind = f.get("type", "text")
                value = ("%d" % math.ceil(f["min"]) if kind == "integer" else repr(f["min"])) \
                    if kind in ("integer", "number") else f["choices"][0] if kind == "choice" else "x"
                info += ["--info", "%s=%s" % (f["key"], value)]
            try:
                r = subprocess.run([args.blurcue, "run", path, "--participant", "P1", "--db", db, "--observer", "sim",
                                    "--stop-after", "3", "--sim-fps", "2"] + info,
                                   capture_output=True, text=True, errors="replace", timeout=RUN_TIMEOUT_S, env=env)
                if r.returncode in (2, 3) and observer_refusal_agrees(args.blurcue, path, r.stderr, env):
                    # A protocol a person can run that the simulated observer cannot answer (no real camera for its
                    # arcmin model): validate, asked for the same observer, refuses it with run's own line.
                    counts["refused_for_the_observer"] += 1
                elif r.returncode != 0:
                    counts["accepted_then_failed"] += 1
                    if r.returncode < 0:
                        counts["crash"] += 1
                    fail("validate accepted, run exit %d" % r.returncode, r.stderr)
                else:
                    counts["ran"] += 1
            except subprocess.TimeoutExpired:
                counts["timeout"] += 1
                counts["accepted_then_failed"] += 1
                fail("validate accepted, run timed out after %d s" % RUN_TIMEOUT_S, "")
        else:
            counts["other_exit"] += 1
            fail("validate exit %d" % v.returncode, v.stderr)
        if args.keep:
            shutil.copy(path, os.path.join(work, "mutants", os.path.basename(path)))
        os.remove(path)
        if (index - args.first + 1) % 20 == 0:
            print("  %d mutants, %.0f s" % (index - args.first + 1, time.time() - started), flush=True)

    for f in failures:
        print("FAIL " + f)
    print("counts: " + ", ".join("%s %d" % kv for kv in counts.items()) + " (%.0f s)" % (time.time() - started))
    bad = counts["crash"] + counts["exit10"] + counts["other_exit"] + counts["timeout"] + \
        counts["accepted_then_failed"] + counts["unnamed_message"]
    if bad:
        print("fuzz: %d failures (mutants kept in %s)" % (bad, os.path.join(work, "mutants")))
        return 1
    print("fuzz ok: 0 crashes, 0 exit 10, 0 timeouts, 0 accepted-then-failed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
