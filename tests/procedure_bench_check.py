#!/usr/bin/env python3
"""Checks `blurcue bench procedures` output against what the procedures are known to do (usage: CSV)."""
import csv, sys

rows = list(csv.DictReader(open(sys.argv[1])))
assert len(rows) == 80, len(rows)
get = {(r["procedure"], r["condition"], int(r["trials"])): {k: float(v) for k, v in r.items()
                                                             if k not in ("procedure", "condition")} for r in rows}
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
    assert beyond["bias"] < -0.15 * beyond["truth"], (p, beyond)
print("ok: procedures behave as known (nominal QUEST+ bias %+.1f %%, RMSE %.1f %% at 160 trials)"
      % (100 * q["bias"] / q["truth"], 100 * q["rmse"] / q["truth"]))
