#!/usr/bin/python3
"""The report's per-track thresholds against simulated observers of known threshold (issue 38's must-hold).

Usage: threshold_coverage_check.py EXPORT_DIR KIND [PLAN_CSV]   (KIND: staircase or quest_plus)

EXPORT_DIR is `blurcue export` of sessions answered by `--observer sim:weber=W,...,side=0,blurrier=0` (a drawn
Weber fraction per participant). Each track's true threshold is worked out here from docs/observer.md's formula, not
by blurcue's code: the observer tells radii r_a and r_b (arcmin, r = 2 s) apart with P = Phi(z75 d / ln(1 + w)),
d = |ln E(r_a / 2) - ln E(r_b / 2)|, E(s) = (s^p + s_i^p)^(1/p), and answers at random on `lapse` of trials:
P_all = (1 - lapse) P + lapse / 2. The target: a 1-up/n-down staircase's 0.5^(1/n) of all answers (Levitt), QUEST+'s
guess + (1 - guess - lapse/2)(1 - 1/e). The reference radius is read from the trials (the less blurred side), and the
recorded radius of the test side is checked against the level's rule (relative: r_ref (1 + level); arcmin: r_ref +
level) before anything is computed from it. The thresholds are the report's own (analysis/tracks.py track_rows).
Asserts: at least 80 % of tracks determined, their 95 % intervals holding the truth in at least 90 %, the mean
relative error within max(5 %, 2 Monte Carlo SE) (issue 38's must-hold). With PLAN_CSV (`blurcue plan`'s table for the
same protocol), the plan's predicted share of tracks determined within 15 points of the one measured. Prints what it
measured.
"""
import math
import os
import sys

import numpy as np
import pandas as pd
from scipy.stats import norm

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "analysis"))
import common  # noqa: E402
import tracks  # noqa: E402

Z75 = norm.ppf(0.75)


def params(text):
    out = {"intrinsic": 0.6, "weber": 0.35, "exponent": 2.0, "lapse": 0.04}
    for part in str(text).replace("sim:", "").split(","):
        if "=" in part:
            k, v = part.split("=", 1)
            if k in out:
                out[k] = float(v)
    return out


def share(o, r_a, r_b):
    e = lambda r: ((r / 2) ** o["exponent"] + o["intrinsic"] ** o["exponent"]) ** (1 / o["exponent"])
    d = abs(math.log(e(r_a)) - math.log(e(r_b)))
    return (1 - o["lapse"]) * norm.cdf(Z75 * d / math.log1p(o["weber"])) + o["lapse"] / 2


def main(folder, kind, plan_csv=None):
    m = common.load_trials(os.path.join(folder, "trials.csv"))
    m = m[m["practice"] == 0].copy()
    m["y"] = pd.to_numeric(m["correct"], errors="coerce")
    rows = tracks.track_rows(m)
    if len(rows) < 20:
        sys.exit(f"FAIL: only {len(rows)} tracks in {folder}")
    det = cov = 0
    rel = []
    for t in rows:
        who = m[m["participant"].astype(str) == t["participant"].split(" (")[0]]
        o = params(who["observer_params"].iloc[0] if "observer_params" in who else who["observer"].iloc[0])
        p = tracks.parameters(who)
        cell = who[who["cell"].astype(str).str.replace("=", " ").str.replace(";", ", ") == t["cell"]]
        cell = cell if len(cell) else who
        cell = cell[pd.to_numeric(cell["level"]).notna() & pd.to_numeric(cell["r_left_arcmin"]).notna()]
        rl, rr = pd.to_numeric(cell["r_left_arcmin"]), pd.to_numeric(cell["r_right_arcmin"])
        ref = float(np.median(np.minimum(rl, rr)))
        level = pd.to_numeric(cell["level"])
        test_side = np.maximum(rl, rr)
        relative = p.get("variable", "relative_difference") == "relative_difference"
        rule = ref * (1 + level) if relative else ref + level
        if not np.allclose(test_side, rule, rtol=2e-3, atol=2e-3):
            sys.exit(f"FAIL: {t['participant']} {t['cell']}: the test side's radius is not the level's rule "
                     f"({'relative' if relative else 'arcmin'}): {test_side.to_numpy()[:4]} vs {rule.to_numpy()[:4]}")
        if kind == "staircase":
            target = 0.5 ** (1 / int(p["down"]))
        else:
            target = p["guess"] + (1 - p["guess"] - o["lapse"] / 2) * (1 - math.exp(-1))
        radius = (lambda x: ref * (1 + x)) if relative else (lambda x: ref + x)
        lo, hi = 1e-6, 50.0
        for _ in range(200):
            mid = (lo + hi) / 2
            lo, hi = (mid, hi) if share(o, radius(mid), ref) < target else (lo, mid)
        truth = (lo + hi) / 2
        r = t["result"]
        if "estimate" not in r:
            print(f"  {t['participant']:>4} {t['cell']}: truth {truth:.3f}, {r.get('why')}")
            continue
        det += 1
        hit = r["low"] <= truth <= r["high"]
        cov += hit
        rel.append(r["estimate"] / truth - 1)
        print(f"  {t['participant']:>4} {t['cell']}: truth {truth:.3f}, estimate {r['estimate']:.3f} "
              f"[{r['low']:.3f}, {r['high']:.3f}]{'' if hit else '  MISSES'}")
    rel = np.array(rel)
    mcse = rel.std(ddof=1) / math.sqrt(len(rel))
    print(f"{kind}: {det} of {len(rows)} tracks determined, {cov} of {det} intervals hold the truth, mean relative "
          f"error {rel.mean():+.3f} (Monte Carlo SE {mcse:.3f}), median {np.median(rel):+.3f}")
    ok = det >= 0.8 * len(rows) and cov >= 0.9 * det and abs(rel.mean()) <= max(0.05, 2 * mcse)
    if plan_csv:
        plan = pd.read_csv(plan_csv)
        plan = plan[(plan["test"] == "threshold") & (plan["participants"] == plan["participants"].max())]
        predicted = float(plan["determined_share"].mean())
        print(f"plan: {predicted:.0%} of tracks determined, measured {det / len(rows):.0%}")
        ok = ok and abs(predicted - det / len(rows)) <= 0.15
    print("ok" if ok else "FAIL")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main(*sys.argv[1:4]))
