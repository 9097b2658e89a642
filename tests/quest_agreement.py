#!/usr/bin/env python3
"""blurcue's QUEST+ against python3-questplus (an independent implementation, Debian's): the same grid, prior and
observer answers must give the same stimulus on every trial and the same posterior.
usage: quest_agreement.py QUEST_TRACE WORKDIR"""
import json, os, subprocess, sys, warnings

import numpy as np
import questplus as qp

warnings.simplefilter("ignore")  # questplus logs 0 * log(0) as a RuntimeWarning; it counts it as 0, as blurcue does
trace, work = sys.argv[1], sys.argv[2]
os.makedirs(work, exist_ok=True)
cases = [
    # The blur difference a person notices (arcmin), a 2AFC guess of 0.5, lapse unknown.
    dict(stimuli=[round(0.25 * i, 6) for i in range(1, 25)], threshold=[round(0.3 * i, 6) for i in range(1, 21)],
         slope=[1.5, 2.5, 3.5, 5.0], lapse=[0.0, 0.02, 0.05], guess=0.5,
         observer=dict(threshold=2.1, slope=3.0, lapse=0.02), trials=60, seed=1),
    # A relative difference with a steep observer whose threshold lies near the grid's top.
    dict(stimuli=[round(0.05 * i, 6) for i in range(1, 41)], threshold=[round(0.1 * i, 6) for i in range(1, 21)],
         slope=[2.0, 4.0], lapse=[0.01], guess=0.5,
         observer=dict(threshold=1.8, slope=6.0, lapse=0.0), trials=40, seed=2),
]
for n, case in enumerate(cases):
    rng = np.random.default_rng(case["seed"])
    u = rng.random(case["trials"]).tolist()
    spec = dict(case, u=u)
    path = os.path.join(work, f"quest-{n}.json")
    json.dump(spec, open(path, "w"))
    ours = json.loads(subprocess.run([trace, path], check=True, capture_output=True, text=True).stdout)
    q = qp.QuestPlusWeibull(intensities=case["stimuli"], thresholds=case["threshold"], slopes=case["slope"],
                            lower_asymptotes=[case["guess"]], lapse_rates=case["lapse"],
                            responses=["Correct", "Incorrect"], stim_scale="linear",
                            stim_selection_method="min_entropy", param_estimation_method="mean")
    o = case["observer"]
    theirs = []
    for i in range(case["trials"]):
        x = q.next_intensity
        pc = 1 - o["lapse"] - (1 - case["guess"] - o["lapse"]) * np.exp(-((x / o["threshold"]) ** o["slope"]))
        q.update(intensity=x, response="Correct" if u[i] < pc else "Incorrect")
        theirs.append(x)
        if abs(x - ours["stimuli"][i]) > 1e-9:
            raise SystemExit(f"case {n} trial {i}: questplus shows {x}, blurcue {ours['stimuli'][i]}")
    post = np.asarray(q.posterior.values, dtype=float).reshape(-1)  # threshold, slope, lower asymptote, lapse
    diff = np.abs(post - np.asarray(ours["posterior"])).max()
    est = q.param_estimate
    assert diff < 1e-9, (n, diff)
    assert abs(est["threshold"] - ours["mean_threshold"]) < 1e-9, (est, ours["mean_threshold"])
    assert abs(est["slope"] - ours["mean_slope"]) < 1e-9, (est, ours["mean_slope"])
    print(f"case {n}: {case['trials']} trials, the same stimulus every trial, posterior within {diff:.1e}, "
          f"threshold {ours['mean_threshold']:.4f} (observer {o['threshold']})")
print("ok: blurcue's QUEST+ agrees with python3-questplus")
