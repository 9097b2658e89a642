#!/usr/bin/python3
"""The staircase posterior's golden table: tracks (a seeded Weibull observer through a 1-up/n-down staircase) with
analysis/tracks.py staircase_posterior's answer for each. `--write` makes tests/data/staircase_posterior_golden.csv;
without it, checks the Python twin against the table (exit 1 on a difference). The C++ twin
(src/procedure/threshold_fit.h) is held to the same table by procedure_test (StaircasePosterior.MatchesTheGoldenTable)."""
import math
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "analysis"))
import tracks  # noqa: E402

TABLE = os.path.join(HERE, "data", "staircase_posterior_golden.csv")


def cases():
    rng = np.random.default_rng(2026)
    out = []
    for i in range(24):
        down = 2 if i % 3 else 3
        target = 0.5 ** (1 / down)
        lo, hi = (0.02, 3.0) if i % 4 else (0.0, 6.0)
        truth, slope = math.exp(rng.uniform(math.log(0.05), math.log(2.5))), rng.uniform(0.8, 3)
        f = (target - 0.5) / (0.5 - 0.02)
        alpha = truth / (-math.log(1 - f)) ** (1 / slope)
        level, run, levels, correct = 1.0, 0, [], []
        for _ in range(int(rng.integers(5, 60))):
            ok = rng.random() < 0.5 + 0.48 * (1 - math.exp(-(level / alpha) ** slope))
            levels.append(level), correct.append(bool(ok))
            move = 1 if not ok else 0
            if ok:
                run += 1
                if run >= down:
                    run, move = 0, -1
            else:
                run = 0
            level = min(hi, max(lo, round(level + move * 0.1, 10)))
        out.append((0.5, target, lo, hi, levels, correct))
    return out


def row(case):
    guess, target, lo, hi, levels, correct = case
    r = tracks.staircase_posterior(guess, target, lo, hi, levels, correct)
    return [f"{guess!r}", f"{target!r}", f"{lo!r}", f"{hi!r}", " ".join(repr(float(x)) for x in levels),
            "".join("1" if c else "0" for c in correct), str(int(r["determined"])), repr(float(r.get("estimate", 0))),
            repr(float(r.get("low", 0))), repr(float(r.get("high", 0))), r.get("at_bound", ""),
            r.get("why", "").split(":")[1].split()[0] if not r["determined"] else ""]


HEADER = "guess,target,lo,hi,levels,correct,determined,estimate,low,high,at_bound,why_word"

if __name__ == "__main__":
    rows = [",".join(row(c)) for c in cases()]
    if "--write" in sys.argv:
        with open(TABLE, "w") as f:
            f.write(HEADER + "\n" + "\n".join(rows) + "\n")
        print(f"wrote {TABLE}: {len(rows)} tracks")
        sys.exit(0)
    with open(TABLE) as f:
        table = f.read().splitlines()[1:]
    bad = 0
    for i, (want, got) in enumerate(zip(table, rows)):
        w, g = want.split(","), got.split(",")
        same = w[:7] == g[:7] and w[10:] == g[10:] and all(
            abs(float(a) - float(b)) <= 1e-9 * max(1.0, abs(float(a))) for a, b in zip(w[7:10], g[7:10]))
        if not same:
            bad += 1
            print(f"track {i}: table {want}\n          python {got}")
    if len(table) != len(rows) or bad:
        print(f"FAIL: {bad} of {len(rows)} tracks differ from {TABLE}")
        sys.exit(1)
    print(f"ok: the Python twin gives the golden table's {len(rows)} tracks")
