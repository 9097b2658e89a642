"""The report's psychometric fit (analysis/stats.py) against an independent implementation, psignifit 4
(Schuett, Harmeling, Macke & Wichmann 2016; `pip install psignifit`, not in Debian): on the same 2AFC data the two
thresholds (where the sigmoid core is at half height) agree within each other's 95 % intervals.

Prints "SKIP: ..." and exits 0 where psignifit is not installed (PyPI is not reachable from every machine).
"""
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "analysis"))
import stats  # noqa: E402

try:
    import psignifit  # noqa: E402
except ImportError:
    print("SKIP: psignifit is not installed (pip install psignifit; it is not packaged by Debian)")
    sys.exit(0)


def main():
    # A 2AFC observer with a Weibull threshold 1.2 and slope 3, lapse 0.02: 8 levels x 40 trials, seeded.
    rng = np.random.default_rng(11)
    levels = np.array([0.3, 0.5, 0.7, 0.9, 1.2, 1.6, 2.2, 3.0])
    truth = stats.PsychometricFit("weibull", 1.2, 3.0, 0.5, 0.02, 0, 4, 0, True)
    n = np.full(len(levels), 40)
    k = rng.binomial(n, truth(levels))

    ours = stats.fit_psychometric(levels, k, n, kind="weibull", gamma=0.5, lam=(0.0, 0.1))
    stats.bootstrap(levels, k, n, ours, n_boot=300, seed=3)
    half = ours.gamma + (1 - ours.gamma - ours.lam) * 0.5  # psignifit's threshold: the core at half height
    th_ours = stats.threshold(ours, half)
    boot = []
    rng2 = np.random.default_rng(5)
    for _ in range(300):
        kb = rng2.binomial(n, np.clip(ours(levels), 0, 1))
        fb = stats.fit_psychometric(levels, kb, n, kind="weibull", gamma=0.5, lam=(0.0, 0.1),
                                    starts=[(ours.alpha, ours.beta)])
        boot.append(stats.threshold(fb, fb.gamma + (1 - fb.gamma - fb.lam) * 0.5))
    ours_lo, ours_hi = np.percentile([b for b in boot if not math.isnan(b)], [2.5, 97.5])

    data = np.column_stack([levels, k, n])
    result = psignifit.psignifit(data, sigmoid="weibull", experiment_type="2AFC")
    estimate = result.parameter_estimate
    ci = result.confidence_intervals
    th_theirs = float(estimate["threshold"])
    # One [low, high] per confidence level, the first the 95 % one (psignifit's default levels: 0.95, 0.9, 0.68).
    lo, hi = (float(v) for v in np.asarray(ci["threshold"], float).reshape(-1, 2)[0])
    print(f"threshold: ours {th_ours:.3f} [{ours_lo:.3f}, {ours_hi:.3f}], psignifit {th_theirs:.3f} [{lo:.3f}, {hi:.3f}]")
    if not (lo <= th_ours <= hi and ours_lo <= th_theirs <= ours_hi):
        print("FAIL: the thresholds disagree beyond their intervals")
        sys.exit(1)
    print("ok: the report's Weibull fit and psignifit agree within their 95 % intervals")


if __name__ == "__main__":
    main()
