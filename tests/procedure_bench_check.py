#!/usr/bin/env python3
"""Checks `blurcue bench procedures` output against what the procedures are known to do (usage: CSV [CSV2]): CSV2,
the same bench under another seed, checks the Monte Carlo standard errors against the difference between the runs."""
import csv, sys

rows = list(csv.DictReader(open(sys.argv[1])))
assert len(rows) == 80, len(rows)
get = {(r["procedure"], r["condition"], int(r["trials"])): {k: float(v) for k, v in r.items()
                                                             if k not in ("procedure", "condition", "within_target", "fails")} for r in rows}
procs = ["constant_stimuli", "staircase_1u2d", "staircase_1u3d", "quest_plus"]
for p in procs:  # a nominal observer: more trials, smaller error
    assert get[(p, "nominal", 160)]["rmse"] < get[(p, "nominal", 20)]["rmse"], p
q = get[("quest_plus", "nominal", 160)]
assert abs(q["bias"]) < 0.05 * q["truth"], q  # QUEST+ (its own model) is nearly unbiased
assert q["rmse"] < get[("constant_stimuli", "nominal", 160)]["rmse"], "QUEST+ not better than constant stimuli"
# The staircases aim below the Weibull threshold (70.7 %, 79.4 % of a 2AFC with no lapses), in that order.
assert get[("staircase_1u2d", "nominal", 20)]["truth"] < get[("staircase_1u3d", "nominal", 20)]["truth"] < q["truth"]
for p in ("staircase_1u3d", "quest_plus"):  # failures the chart must show
    side = get[(p, "side_bias", 160)]
    assert side["bias"] > 0.15 * side["truth"], (p, side)
    beyond = get[(p, "beyond_range", 160)]
    if p == "quest_plus":  # QUEST+'s posterior mean gives a number pinned inside its grid
        assert beyond["bias"] < -0.15 * beyond["truth"], (p, beyond)
    else:  # the staircase posterior says "not determined: above the tested range" (docs/thresholds.md), no number
        assert beyond["failed"] == beyond["runs"], (p, beyond)
# Verdicts: one of three words, and consistent with the numbers and the 10 % / 15 % lines they decide.
for row in rows:
    assert row["within_target"] in ("yes", "no", "undecided") and row["fails"] in ("yes", "no", "undecided"), row
    t, rmse, se = float(row["truth"]), float(row["rmse"]), float(row["rmse_se"])
    if row["within_target"] == "yes":
        assert rmse + 1.9 * se <= 0.1 * t, row
    if row["fails"] == "yes":
        assert abs(float(row["bias"])) - 1.9 * float(row["bias_se"]) > 0.15 * t, row
if len(sys.argv) > 2:  # the standard errors say how far another seed's run lands: |z| > 1.96 in about 5 % of rows
    other = {(r["procedure"], r["condition"], int(r["trials"])): r for r in csv.DictReader(open(sys.argv[2]))}
    for column in ("rmse", "bias"):
        z = []
        for key, a in get.items():
            b = other[key]
            se = (a[column + "_se"] ** 2 + float(b[column + "_se"]) ** 2) ** 0.5
            if se > 0:
                z.append(abs(a[column] - float(b[column])) / se)
        beyond = sum(v > 1.96 for v in z) / len(z)
        assert beyond <= 0.15 and max(z) < 4.5, (column, beyond, max(z))
        print(f"{column}: {100 * beyond:.1f} % of {len(z)} rows differ between seeds by > 1.96 Monte Carlo se "
              f"(largest |z| {max(z):.2f})")
print("ok: procedures behave as known (nominal QUEST+ bias %+.1f %%, RMSE %.1f %% at 160 trials)"
      % (100 * q["bias"] / q["truth"], 100 * q["rmse"] / q["truth"]))
