"""Adaptive procedures: each track, its threshold with an interval, a summary per procedure cell, comparisons.

One track is one participant's procedure in one cell (the crossing of its block's factors, labelled by its levels,
e.g. "distance_m 0.5") in one session. Its threshold and interval, from the procedure's own parameters (procedures.csv
beside trials.csv, joined to each row as `procedure_parameters` by common.load_trials):

  QUEST+     the posterior over the protocol's grid (threshold x slope x lapse, uniform prior, the Weibull with the
             protocol's guess rate) given the track's answers, computed here from the answers (its mean checked
             against the posterior_threshold the procedure recorded): the threshold is the median of the threshold's
             marginal posterior (the cumulative mass interpolated linearly between grid points; the mean runs high,
             pulled by the grid's long upper tail), the interval its equal-tailed 95 % credible interval on the grid
             (the 2.5 % and 97.5 % quantiles, each the grid point where the cumulative mass first reaches it).
  staircase  the turning points the procedure records (src/procedure/adaptive.cc Staircase::ReversalLevels: the level
             shown on the answer that made the direction change), found by replaying its up/down rule on the answers;
             the threshold is the mean of the last 6 turning points (4 when there are 4 or 5), the interval a t
             interval over the midpoints of the consecutive turning-point pairs used (3 pairs: 2 degrees of freedom).

plan::TrackEstimate (src/plan/threshold.cc) takes the same estimates, so `blurcue plan` and the report agree. A missed
deadline counts as a wrong answer, as the procedure counted it (rows with status timed_out, where given; a QUEST+
track whose rows lack them gets them back from the procedure's own stimulus choice, quest_fill_missed; a staircase
from its levels, staircase_fill_missed).
A value that means "not determined" is said in words, never written as a number: a QUEST+ posterior whose median is
the grid's lowest or highest threshold, a staircase that turned at its bound, too few turning points, a posterior
that the answers here do not reproduce. An interval end on the grid's bound says so (`interval_at_bound`).
"""
import json
import math

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
from scipy import stats as sps

import criteria
from common import Chart, axis_label, level_unit, save, session_words

CREDIBLE = 0.95
COLORS = ["#0072B2", "#E69F00", "#009E73", "#CC79A7", "#D55E00", "#56B4E9", "#F0E442", "#000000"]


def _num(series):
    return pd.to_numeric(series.astype(str).replace({"": np.nan, "nan": np.nan}), errors="coerce")


def _text(v):
    return f"{v:.4g}"


def parameters(g):
    """The procedure's parameters for a track's rows (the JSON procedures.csv gives), or None without them."""
    if "procedure_parameters" not in g:
        return None
    texts = [t for t in g["procedure_parameters"].astype(str) if t.strip() not in ("", "nan")]
    return json.loads(texts[0]) if texts else None


def cell_label(g):
    """The cell by its levels: 'edge=9;speed_cm_s=3' -> 'edge 9, speed_cm_s 3'."""
    text = str(g["cell"].iloc[0]) if "cell" in g and str(g["cell"].iloc[0]) not in ("", "nan") else ""
    if not text:
        return f"cell {g['procedure_cell'].iloc[0]}"
    return ", ".join(part.replace("=", " ", 1) for part in text.split(";") if part)


# --------------------------------------------------------------------------------------------------------------------
# Staircase


class _Staircase:
    """The n-up/m-down rule of src/procedure/adaptive.cc Staircase: `level` is what it shows next; update() takes an
    answer; `turns` are the levels shown on the answers whose step went the other way than the last (ReversalLevels)."""

    def __init__(self, p):
        self.p, self.level, self.turns = p, float(p["start"]), []
        self.run_ok = self.run_bad = self.direction = 0
        self.steps = p.get("steps") or [0.0]

    def update(self, ok):
        move = 0
        if ok:
            self.run_bad, self.run_ok = 0, self.run_ok + 1
            if self.run_ok >= self.p["down"]:
                move, self.run_ok = -1, 0
        else:
            self.run_ok, self.run_bad = 0, self.run_bad + 1
            if self.run_bad >= self.p["up"]:
                move, self.run_bad = 1, 0
        if move == 0:
            return
        if self.direction != 0 and move != self.direction:
            self.turns.append(self.level)
        self.direction = move
        step = self.steps[min(len(self.turns), len(self.steps) - 1)]
        self.level = min(max(self.level + move * step, self.p["min"]), self.p["max"])


def staircase_turns(p, levels, correct):
    """Replays the rule on the answers: (turning points, the levels the rule would have shown)."""
    s, shown = _Staircase(p), []
    for ok in correct:
        shown.append(s.level)
        s.update(ok)
    return s.turns, np.array(shown)


def staircase_fill_missed(p, levels, correct, most=5):
    """The track with the answers these rows lack put back: where a row's level is not the one the rule shows next, a
    missed deadline came before it (counted wrong, at the level shown). Returns (levels, correct, missed); missed None
    when the rows cannot be explained by at most `most` missed answers each."""
    s, xs, oks, missed = _Staircase(p), [], [], 0
    for x, ok in zip(levels, correct):
        for _ in range(most + 1):
            if abs(s.level - x) <= 1e-6 * max(1.0, abs(x)):
                break
            xs.append(s.level), oks.append(False)
            s.update(False)
            missed += 1
        else:
            return levels, correct, None
        xs.append(float(x)), oks.append(bool(ok))
        s.update(ok)
    return np.array(xs), np.array(oks), missed


def turns_from_levels(levels):
    """Without the procedure's parameters: the levels at which the direction of the levels shown changed."""
    turns, last = [], 0
    for i in range(1, len(levels)):
        move = np.sign(levels[i] - levels[i - 1])
        if move != 0 and last != 0 and move != last:
            turns.append(levels[i - 1])
        last = move if move != 0 else last
    return turns


# The staircase posterior (src/procedure/threshold_fit.h StaircasePosterior, its twin, held to it by
# tests/data/staircase_posterior_golden.csv): a Weibull whose threshold is the level answered correctly `target` of the
# time, lapses included, over a grid of threshold x slope x lapse with a uniform prior; the median of the threshold's
# marginal and its equal-tailed 95 % credible interval, each grid point's mass spread over its cell in log threshold.
THETA_POINTS, SLOPE_POINTS, SLOPE_LOW, SLOPE_HIGH, LAPSES = 161, 17, 0.5, 5.0, (0.0, 0.025, 0.05)
MIN_ANSWERS = 10  # fewer: not determined, whatever the posterior (kMinAnswers)


def staircase_posterior(guess, target, lo, hi, levels, correct):
    """dict(determined, estimate, low, high, at_bound, why) as StaircasePosterior gives it."""
    levels = np.maximum(np.asarray(levels, float), 0.0)
    correct = np.asarray(correct, bool)
    if len(levels) < MIN_ANSWERS:
        return {"determined": False, "why": f"not determined: {len(levels)} answers (needs {MIN_ANSWERS})"}
    ux, inv = np.unique(levels, return_inverse=True)
    right = np.bincount(inv, weights=correct.astype(float))
    wrong = np.bincount(inv).astype(float) - right
    low_end = max(lo, hi / 1000)
    log_theta = math.log(low_end) + (math.log(hi) - math.log(low_end)) * np.arange(THETA_POINTS) / (THETA_POINTS - 1)
    slope = np.exp(math.log(SLOPE_LOW) + (math.log(SLOPE_HIGH) - math.log(SLOPE_LOW)) * np.arange(SLOPE_POINTS) /
                   (SLOPE_POINTS - 1))
    lapse = np.asarray(LAPSES)
    span = 1 - guess - lapse
    c = -np.log1p(-(target - guess) / span)
    with np.errstate(divide="ignore", invalid="ignore"):  # log 0 at level 0; 0 x log 0 in np.where's unused branch
        u = np.exp(slope[None, :, None] * (np.log(ux)[None, None, :] - log_theta[:, None, None]))  # [theta, slope, x]
        p = guess - span[None, None, :, None] * np.expm1(-c[None, None, :, None] * u[:, :, None, :])
        ll = (np.where(right > 0, right * np.log(p), 0) + np.where(wrong > 0, wrong * np.log1p(-p), 0)).sum(-1)
    mass = np.exp(ll - ll.max()).sum(axis=(1, 2))
    cumulative = np.cumsum(mass) / mass.sum()
    step = log_theta[1] - log_theta[0]

    def quantile(q):
        k = min(int(np.searchsorted(cumulative, q, side="left")), THETA_POINTS - 1)
        before = cumulative[k - 1] if k else 0.0
        m = cumulative[k] - before
        start = max(log_theta[k] - step / 2, log_theta[0])
        end = min(log_theta[k] + step / 2, log_theta[-1])
        return math.exp(start + ((q - before) / m if m > 0 else 0.5) * (end - start)), k

    tail = (1 - CREDIBLE) / 2
    (estimate, _), (low, i_low), (high, i_high) = quantile(0.5), quantile(tail), quantile(1 - tail)
    low_at, high_at = i_low <= 1, i_high + 2 >= THETA_POINTS
    tenth = (math.log(hi) - math.log(low_end)) / 10
    out = {"determined": False, "estimate": estimate, "low": low, "high": high, "at_bound": ""}
    if low_at and high_at:
        out["why"] = f"not determined: its 95 % interval spans the whole of {criteria.range_words(lo, hi)}"
    elif low_at and math.log(estimate) < math.log(low_end) + tenth:
        out["why"] = f"not determined: below {criteria.range_words(lo, hi)} (the answers put it at the lowest levels)"
    elif high_at and math.log(estimate) > math.log(hi) - tenth:
        out["why"] = f"not determined: above {criteria.range_words(lo, hi)} (the answers put it at the highest levels)"
    elif low_at or high_at:
        out["why"] = (f"not determined: its 95 % interval reaches the {'lowest' if low_at else 'highest'} level of "
                      f"{criteria.range_words(lo, hi)} (the answers do not bound it there)")
    else:
        out["determined"] = True
    return out


def staircase_threshold(p, levels, correct):
    """A staircase track's threshold (dict): estimate, interval and what they mean."""
    out = {"method": "posterior median at the staircase's target (Weibull, uniform prior over threshold x slope 0.5-5 "
                     "x lapse 0-5 %); interval: its equal-tailed 95 % credible interval"}
    if p is None:
        return out | {"why": "not determined: the export has no procedures.csv (its rule, so its target and range, "
                             "unknown; export again with this blurcue)",
                      "turning_points": len(turns_from_levels(levels))}
    filled, answers, missed = staircase_fill_missed(p, levels, correct)
    if missed:
        levels, correct = filled, answers
        out["note"] = (f"{missed} missed answer{'s' if missed > 1 else ''} (not in these rows) put back where the "
                       "levels show them, counted wrong as the procedure counted them")
    turns, replayed = staircase_turns(p, levels, correct)
    out["turning_points"] = len(turns)
    if len(replayed) != len(levels) or np.abs(replayed - levels).max() > 1e-6 * max(1.0, np.abs(levels).max()):
        first = int(np.argmax(np.abs(replayed - levels) > 1e-6))
        out["why"] = (f"not determined: replaying the answers here gives level {_text(replayed[first])} at the "
                      f"track's trial {first + 1}, the record shows {_text(levels[first])} (answers missing from "
                      "these rows, such as missed deadlines?)")
        return out
    lo, hi = criteria.tested_range(p, levels)
    out["range"] = (lo, hi)
    guess = float(p.get("guess", 0.5))
    target = criteria.criterion("staircase", p, guess).answers
    if not math.isfinite(target):
        return out | {"why": "not determined: this up/down rule has no closed-form target"}
    if not (guess + 0.01 < target < 0.94):  # as plan::TrackEstimate
        return out | {"why": (f"not determined: a {int(p['up'])}-up/{int(p['down'])}-down staircase converges on "
                              f"{100 * target:.1f} % correct, " + ("at or below what guessing gives" if target <= guess + 0.01
                                                                    else "beyond what its fit can place"))}
    fit = staircase_posterior(guess, target, lo, hi, levels, correct)
    if not fit["determined"]:
        return out | {"why": fit["why"]}
    out.update(estimate=fit["estimate"], low=fit["low"], high=fit["high"], interval_at_bound=fit["at_bound"])
    return out


# --------------------------------------------------------------------------------------------------------------------
# QUEST+


def quest_posterior(p, stimuli, correct):
    """The posterior over the grid [threshold, slope, lapse] (uniform prior) after the answers, as QUEST+ keeps it."""
    t = np.asarray(p["thresholds"], float)[:, None, None]
    b = np.asarray(p["slopes"], float)[None, :, None]
    lam = np.asarray(p["lapses"], float)[None, None, :]
    g = float(p["guess"])
    log_post = np.zeros((t.shape[0], b.shape[1], lam.shape[2]))
    with np.errstate(divide="ignore"):
        for x, ok in zip(stimuli, correct):
            psi = 1 - lam - (1 - g - lam) * np.exp(-((x / t) ** b))
            log_post = log_post + np.log(psi if ok else 1 - psi)
    log_post -= log_post.max()
    post = np.exp(log_post)
    return post / post.sum()


def _likelihoods(p):
    """P(correct) per stimulus over the grid: [stimulus, threshold, slope, lapse]."""
    x = np.asarray(p["stimuli"], float)[:, None, None, None]
    t = np.asarray(p["thresholds"], float)[None, :, None, None]
    b = np.asarray(p["slopes"], float)[None, None, :, None]
    lam = np.asarray(p["lapses"], float)[None, None, None, :]
    g = float(p["guess"])
    return 1 - lam - (1 - g - lam) * np.exp(-((x / t) ** b))


def quest_next(post, psi, stimuli):
    """QUEST+'s next stimulus (src/procedure/adaptive.cc QuestPlus::Next): least expected posterior entropy, the first
    of equals."""
    expected = np.zeros(len(stimuli))
    with np.errstate(divide="ignore", invalid="ignore"):
        for outcome in (psi, 1 - psi):
            joint = post[None] * outcome
            pk = joint.sum(axis=(1, 2, 3))
            q = joint / np.where(pk > 0, pk, 1)[:, None, None, None]
            h = -np.where(q > 0, q * np.log(np.where(q > 0, q, 1)), 0).sum(axis=(1, 2, 3))
            expected += np.where(pk > 0, pk * h, 0)
    return float(np.asarray(stimuli, float)[int(np.argmin(expected))])


def quest_fill_missed(p, stimuli, correct, most=5):
    """The track with the answers these rows lack put back: where a row's stimulus is not the one QUEST+ would show
    next, a missed deadline came before it (the procedure counted it wrong, at the stimulus it chose). Returns
    (stimuli, correct, missed); missed None when the rows cannot be explained by at most `most` missed answers each."""
    psi = _likelihoods(p)
    index = {float(x): i for i, x in enumerate(p["stimuli"])}
    post = np.full(psi.shape[1:], 1.0 / psi[0].size)
    xs, oks, missed = [], [], 0
    for x, ok in zip(stimuli, correct):
        for _ in range(most + 1):
            shown = quest_next(post, psi, p["stimuli"])
            if abs(shown - x) <= 1e-9 * max(1.0, abs(x)):
                break
            post = post * (1 - psi[index[shown]])
            post /= post.sum()
            xs.append(shown), oks.append(False)
            missed += 1
        else:
            return stimuli, correct, None
        if float(x) not in index:
            return stimuli, correct, None
        post = post * (psi[index[float(x)]] if ok else 1 - psi[index[float(x)]])
        post /= post.sum()
        xs.append(float(x)), oks.append(bool(ok))
    return np.array(xs), np.array(oks), missed


def credible(grid, mass, level=CREDIBLE):
    """Equal-tailed interval on a grid: the first grid point where the cumulative mass reaches (1 - level) / 2, and the
    first where it reaches 1 - (1 - level) / 2."""
    cum = np.cumsum(mass)
    tail = (1 - level) / 2
    return grid[int(np.searchsorted(cum, tail - 1e-12))], grid[int(np.searchsorted(cum, 1 - tail - 1e-12))]


def median(grid, mass):
    """The grid's median: the cumulative mass interpolated linearly between the grid points around 1/2 (as
    plan::TrackEstimate)."""
    cum = np.cumsum(mass) / np.sum(mass)
    k = int(np.argmax(cum >= 0.5))
    if k == 0:
        return float(grid[0])
    return float(grid[k - 1] + (0.5 - cum[k - 1]) / (cum[k] - cum[k - 1]) * (grid[k] - grid[k - 1]))


def quest_threshold(p, stimuli, correct, recorded=None):
    """A QUEST+ track's threshold (dict) from its posterior over the protocol's grid."""
    if p is None:
        out = {"method": "QUEST+'s posterior mean as recorded (procedures.csv missing: no grid, no interval)",
               "why": "interval not determined: the export has no procedures.csv (export again with this blurcue)"}
        if recorded is not None and math.isfinite(recorded):
            out["estimate_recorded"] = recorded
        return out
    missed = 0
    if recorded is not None and math.isfinite(recorded):
        filled, answers, missed = quest_fill_missed(p, stimuli, correct)
        if missed:  # only where the rows lack answers: the procedure's record then decides (the mean check below)
            stimuli, correct = filled, answers
    post = quest_posterior(p, stimuli, correct)
    grid = np.asarray(p["thresholds"], float)
    slopes = np.asarray(p["slopes"], float)
    marginal, slope_marginal = post.sum(axis=(1, 2)), post.sum(axis=(0, 2))
    mean = float((marginal * grid).sum())
    estimate = median(grid, marginal)
    out = {"method": f"QUEST+ posterior over the protocol's grid ({len(grid)} thresholds x {len(slopes)} slopes x "
                     f"{len(p['lapses'])} lapses, uniform prior): median, equal-tailed {CREDIBLE:.0%} credible "
                     "interval", "slope": float((slope_marginal * slopes).sum()), "posterior_mean": mean}
    if missed:
        out["note"] = (f"{missed} missed answer{'s' if missed > 1 else ''} (not in these rows) put back where QUEST+ "
                       "chose its stimulus, counted wrong as the procedure counted them")
    stim = np.asarray(p["stimuli"], float)
    lo, hi = criteria.tested_range(p, stim)
    out["range"] = (lo, hi)
    if recorded is not None and math.isfinite(recorded) and abs(recorded - mean) > 1e-6 * max(1.0, abs(mean)):
        out["why"] = (f"not determined: the answers in these rows give a posterior mean of {_text(mean)}, the "
                      f"procedure recorded {_text(recorded)} (answers missing from these rows, such as missed "
                      "deadlines?)")
        return out
    if slope_marginal.argmax() in (0, len(slopes) - 1) and len(slopes) > 1:
        out["note"] = (out.get("note", "") + "; " if out.get("note") else "") + (f"the slope's posterior peaks at its grid's {'lowest' if slope_marginal.argmax() == 0 else 'highest'} "
                       f"value {_text(slopes[slope_marginal.argmax()])}: the grid may not hold the observer's slope")
    if marginal[0] >= 0.5 or estimate < lo:
        out["why"] = criteria.beyond_words("below", lo, hi, f"posterior mass {marginal[0]:.2f} on the grid's lowest "
                                                            "threshold")
        return out
    if marginal[-1] >= 0.5 or estimate > hi:
        out["why"] = criteria.beyond_words("above", lo, hi, f"posterior mass {marginal[-1]:.2f} on the grid's "
                                                            "highest threshold")
        return out
    low, high = credible(grid, marginal)
    tail = (1 - CREDIBLE) / 2
    bound = (["lower"] if low == grid[0] and marginal[0] >= tail else []) + \
            (["upper"] if high == grid[-1] and marginal[-1] >= tail else [])
    # No interval end beyond the stimuli shown: there the answers say nothing, the grid's prior everything.
    if low < lo:
        low, bound = lo, sorted(set(bound) | {"lower"})
    if high > hi:
        high, bound = hi, sorted(set(bound) | {"upper"})
    out.update(estimate=estimate, low=float(low), high=float(high), interval_at_bound=" and ".join(bound))
    return out


# --------------------------------------------------------------------------------------------------------------------
# Tables and charts


def track_rows(m):
    """One dict per track: who, which cell, the levels and answers, and its threshold."""
    d = m.dropna(subset=["level"]).copy()
    d["level"] = _num(d["level"])
    keys = [k for k in ("participant", "session_id", "block_name", "procedure_cell") if k in d]
    several_blocks = "block_name" in d and d["block_name"].nunique() > 1
    sessions = d.groupby("participant")["session_id"].nunique() if "session_id" in d else None
    said = session_words(d) if "session_id" in d else None
    out = []
    for key, g in d.sort_values("trial_index").groupby(keys, sort=True):
        if "status" in g:
            g = g.assign(y=g["y"].where(g["status"] != "timed_out", 0))
        g = g.dropna(subset=["level", "y"])
        if g.empty:
            continue
        key = dict(zip(keys, key if isinstance(key, tuple) else (key,)))
        p = parameters(g)
        kind = (p or {}).get("procedure") or ("quest_plus" if "posterior_threshold" in g and
                                               _num(g["posterior_threshold"]).notna().any() else "staircase")
        levels, correct = g["level"].to_numpy(float), g["y"].to_numpy() == 1
        if "status" in g:  # a missed deadline, where the rows hold one, counts as wrong (as the procedure counted it)
            correct &= (g["status"] != "timed_out").to_numpy()
        recorded = _num(g["posterior_threshold"]).iloc[-1] if "posterior_threshold" in g else math.nan
        result = quest_threshold(p, levels, correct, recorded) if kind == "quest_plus" else \
            staircase_threshold(p, levels, correct)
        label = cell_label(g)
        if several_blocks:
            label = f"{key['block_name']}: {label}"
        participant = str(key["participant"])
        if sessions is not None and sessions.get(key["participant"], 1) > 1:
            # Said as what it is: the record's id alone ("session 2") read as a second session after an abort.
            participant += f" ({said[g.index[0]]})"
        crit = criteria.criterion(kind, p, float((p or {}).get("guess", 0.5)))
        out.append({"participant": participant, "cell": label, "kind": kind, "levels": levels, "correct": correct,
                    "criterion": crit.short(), "units": level_unit(p) if p else "",
                    "posterior": _num(g["posterior_threshold"]).to_numpy() if kind == "quest_plus" and
                    "posterior_threshold" in g else None, "result": result})
    return out


def _track_table(tracks):
    rows = []
    for t in tracks:
        r = t["result"]
        determined = "estimate" in r
        rows.append({
            "participant": t["participant"], "cell": t["cell"],
            "procedure": "QUEST+" if t["kind"] == "quest_plus" else "staircase", "trials": len(t["levels"]),
            "units": t.get("units", ""),
            "criterion": t.get("criterion", ""),
            "share_correct": float(t["correct"].mean()),
            "threshold": r["estimate"] if determined else None,
            "threshold_low": r.get("low") if determined else None,
            "threshold_high": r.get("high") if determined else None,
            "interval_at_bound": r.get("interval_at_bound", ""),
            "turning_points": r.get("turning_points") if t["kind"] != "quest_plus" else None,
            "slope": r.get("slope") if determined else None,
            "posterior_mean": r.get("posterior_mean") if determined else None,
            "threshold_says": "determined" if determined else r.get("why", "not determined"),
            "note": r.get("note", ""), "method": r["method"]})
    return pd.DataFrame(rows)


MIN_FOR_INTERVAL = 3  # a t interval across participants needs some spread to estimate (as study_tests.MIN_PARTICIPANTS_T)


def summary_table(tracks):
    """Per cell across participants: the determined thresholds' mean with a t 95 % interval (3 or more) and median,
    the count of tracks not determined beside them. A cell where half its tracks or more are not determined gets no
    summary number: the determined ones are a selection (the easier tracks), not the cell."""
    rows = []
    for cell in dict.fromkeys(t["cell"] for t in tracks):
        these = [t for t in tracks if t["cell"] == cell]
        v = np.array([t["result"]["estimate"] for t in these if "estimate" in t["result"]], float)
        row = {"cell": cell, "criterion": "; ".join(dict.fromkeys(t.get("criterion", "") for t in these)),
               "units": "; ".join(dict.fromkeys(t.get("units", "") for t in these)),
               "tracks": len(these), "determined": len(v), "not_determined": len(these) - len(v)}
        # A track beyond the tested range has a threshold known only to lie past it: the mean or median of the
        # others would move the cell's threshold toward the range (censored values left out). Said in words.
        censored = [t for t in these if "estimate" not in t["result"] and "the tested range" in
                    t["result"].get("why", "") and ("below" in t["result"]["why"] or "above" in t["result"]["why"])]
        if censored:
            row["interval"] = (f"not determined: {len(censored)} of {len(these)} tracks lie beyond the tested range "
                               "(their thresholds are censored there; a mean or median of the others would be "
                               "biased toward the range)")
            rows.append(row)
            continue
        if 2 * len(v) <= len(these):
            row["interval"] = (f"not determined: {len(v)} of {len(these)} tracks determined (the determined ones "
                               "would stand for the cell)")
            rows.append(row)
            continue
        row.update(mean=float(v.mean()), median=float(np.median(v)))
        if len(v) < MIN_FOR_INTERVAL:
            row["interval"] = (f"not determined: {len(v)} participants' thresholds are too few for an interval "
                               f"across participants (needs {MIN_FOR_INTERVAL}); each track's own interval is in the "
                               "tracks table")
            rows.append(row)
            continue
        row["interval"] = f"t 95 % across {len(v)} participants"
        half = sps.t.ppf(0.975, len(v) - 1) * v.std(ddof=1) / math.sqrt(len(v))
        row["sd_across_participants"] = float(v.std(ddof=1))
        ranges = [t["result"]["range"] for t in these if "range" in t["result"]]
        lo, hi = (min(r[0] for r in ranges), max(r[1] for r in ranges)) if ranges else (-math.inf, math.inf)
        if v.mean() - half < lo or v.mean() + half > hi:
            # A t interval past what the procedure could show (a negative threshold, say) is no interval.
            row["interval"] = (f"not determined: the t 95 % interval across participants reaches beyond "
                               f"{criteria.range_words(lo, hi)}")
        else:
            row.update(mean_low=float(v.mean() - half), mean_high=float(v.mean() + half))
        rows.append(row)
    return pd.DataFrame(rows)


def summary_words(summary):
    """The thresholds per cell for the report's summary, in the words of the thresholds table (criterion, unit, test,
    N, tracks not determined): one clause per cell."""
    out = []
    for _, r in summary.iterrows():
        unit = f"{r['units']}; " if str(r.get("units", "")) not in ("", "nan") else ""
        text = f"{r['cell']}: threshold at {r['criterion']}"
        if pd.notna(r.get("mean_low")):
            text += (f" {r['mean']:.3g} [{r['mean_low']:.3g}, {r['mean_high']:.3g}] ({unit}mean of "
                     f"{int(r['determined'])} participants' thresholds, t 95 %)")
        elif pd.notna(r.get("mean")) and int(r["determined"]) == 1:
            text += f" {r['mean']:.3g} ({unit}one participant's threshold)"
        elif pd.notna(r.get("mean")):
            text += (f" {r['mean']:.3g} ({unit}mean of {int(r['determined'])} participants' thresholds; its interval "
                     f"{r['interval']})")
        else:
            text += f" {r.get('interval') or 'not determined'}"
        text += f"; {int(r['not_determined'])} of {int(r['tracks'])} tracks not determined"
        out.append(text)
    return "; ".join(out)


def comparisons_table(tracks):
    """Every pair of cells, paired across the participants with a determined threshold in both: the mean
    difference (second minus first) with its t 95 % interval and the paired t-test (3 or more participants). Not
    where the cells' thresholds stand for different criteria (70.7 % against 79.4 % correct), nor where a cell's
    summary gives no number (censored tracks, half or more not determined: summary_table's rules)."""
    by = {}
    for t in tracks:
        if "estimate" in t["result"]:
            by.setdefault(t["cell"], {})[t["participant"]] = t["result"]["estimate"]
    cells = list(dict.fromkeys(t["cell"] for t in tracks))
    summary = summary_table(tracks).set_index("cell")
    criterion = {c: summary.loc[c, "criterion"] for c in cells}
    rows = []
    for i, a in enumerate(cells):
        for b in cells[i + 1:]:
            both = sorted(set(by.get(a, {})) & set(by.get(b, {})))
            row = {"first": a, "second": b, "pairs": len(both)}
            unsummarised = [c for c in (a, b) if pd.isna(summary.loc[c].get("mean", math.nan))]
            if criterion[a] != criterion[b]:
                row["test"] = (f"not compared: the thresholds stand for different criteria ({criterion[a]}, "
                               f"{criterion[b]})")
            elif unsummarised:
                row["test"] = (f"not determined: {unsummarised[0]}'s thresholds give no summary ("
                               f"{summary.loc[unsummarised[0], 'interval']})")
            elif len(both) >= MIN_FOR_INTERVAL:
                diff = np.array([by[b][p] - by[a][p] for p in both])
                half = sps.t.ppf(0.975, len(diff) - 1) * diff.std(ddof=1) / math.sqrt(len(diff))
                row.update(mean_difference=float(diff.mean()), difference_low=float(diff.mean() - half),
                           difference_high=float(diff.mean() + half))
                if diff.std(ddof=1) > 0:
                    row["p_paired_t"] = float(sps.ttest_rel([by[b][p] for p in both], [by[a][p] for p in both]).pvalue)
                row["test"] = "paired t across participants"
            else:
                row["test"] = (f"not determined: {len(both)} participants with a threshold in both cells (a test needs "
                               f"{MIN_FOR_INTERVAL})")
            rows.append(row)
    return pd.DataFrame(rows)


def _bar(r):
    """An estimate's error bar for matplotlib; none where its interval is not determined."""
    if "low" not in r:
        return None
    return [[r["estimate"] - r["low"]], [r["high"] - r["estimate"]]]


def _tracks_figure(tracks, cells, study, group_note, out_dir, name):
    n = len(cells)
    cols = min(n, 3)
    rows = math.ceil(n / cols)
    width = 6.8 if cols == 1 else 4.2 * cols + 0.6
    fig, axes = plt.subplots(rows, cols, figsize=(width, 3.2 * rows + 0.8), squeeze=False, sharey=True)
    for ax, cell in zip(axes.flat, cells):
        these = [t for t in tracks if t["cell"] == cell]
        for i, t in enumerate(these):
            c = COLORS[i % len(COLORS)] if len(these) <= len(COLORS) else "#0072B2"
            alpha = 0.9 if len(these) <= len(COLORS) else 0.35
            step = np.arange(1, len(t["levels"]) + 1)
            # Labelled once per participant (the colour is the participant's within a cell) where they are told apart.
            ax.plot(step, t["levels"], "-", color=c, lw=1, alpha=alpha,
                    label=str(t["participant"]) if len(these) <= len(COLORS) else None)
            if len(these) <= len(COLORS):
                ax.plot(step[t["correct"]], t["levels"][t["correct"]], "o", color=c, ms=3)
                ax.plot(step[~t["correct"]], t["levels"][~t["correct"]], "x", color=c, ms=3.5)
            r = t["result"]
            if "estimate" in r:
                ax.errorbar(len(step) + 1.5 + 0.4 * (i % 5), r["estimate"], yerr=_bar(r), fmt="s", color=c, ms=3.5,
                            lw=0.9, alpha=alpha)
        ax.set_title(cell, loc="left", fontsize=10)
        ax.set_xlabel("trial of the procedure")
        if 1 < len(these) <= len(COLORS):
            ax.legend(title="participant", fontsize=7, title_fontsize=7, loc="best")
    for ax in axes.flat[n:]:
        ax.set_visible(False)
    units = "; ".join(dict.fromkeys(t.get("units", "") for t in tracks if t.get("units")))
    for ax in axes[:, 0]:
        ax.set_ylabel(axis_label("level shown", units))
    kinds = {t["kind"] for t in tracks}
    fig.suptitle(f"{study}: procedure tracks ({', '.join('QUEST+' if k == 'quest_plus' else 'staircase' for k in sorted(kinds))})"
                 f"\n{group_note}; o correct, x wrong; squares at the right: each track's threshold and interval",
                 x=0.01, ha="left", fontsize=11)
    fig.tight_layout()
    return save(fig, out_dir, name)


def _thresholds_figure(tracks, summary, cells, study, group_note, out_dir, name):
    fig, ax = plt.subplots(figsize=(max(6.8, 1.3 * len(cells) + 2.5), 3.8))
    for xi, cell in enumerate(cells):
        these = [t for t in tracks if t["cell"] == cell and "estimate" in t["result"]]
        offsets = np.linspace(-0.25, 0.25, len(these)) if len(these) > 1 else [0.0]
        for off, t in zip(offsets, these):
            r = t["result"]
            ax.errorbar(xi + off, r["estimate"], yerr=_bar(r), fmt="o", color="#999999", ms=3, lw=0.8)
        s = summary[summary["cell"] == cell].iloc[0]
        if "mean_low" in s and pd.notna(s.get("mean_low")):
            ax.errorbar(xi + 0.38, s["mean"], yerr=[[s["mean"] - s["mean_low"]], [s["mean_high"] - s["mean"]]],
                        fmt="D", color="#D55E00", ms=6, lw=1.6)
        missing = int(s["not_determined"])
        if missing:
            ax.annotate(f"{missing} not determined", (xi, 0), xycoords=("data", "axes fraction"), ha="center",
                        va="bottom", fontsize=8, color="#D55E00")
    ax.set_xticks(range(len(cells)))
    # A cell's levels one per line: "from_edge 3, speed_cm_s 1.8, to_edge 8" side by side ran into its neighbour.
    ax.set_xticklabels([c.replace(", ", "\n") for c in cells], fontsize=8)
    ax.set_xlim(-0.6, len(cells) - 0.4)
    units = "; ".join(dict.fromkeys(t.get("units", "") for t in tracks if t.get("units")))
    ax.set_ylabel(axis_label("threshold", units))
    ax.set_title(f"{study}: thresholds per cell\n{group_note}\ngrey: each participant with its 95 % interval; "
                 "orange: the mean with its t 95 % interval", loc="left", fontsize=10)
    fig.tight_layout()
    return save(fig, out_dir, name)


def charts(m, study, out_dir, slug, group_note):
    """The tracks, the thresholds per cell and the comparisons between cells, for one study's procedure rows."""
    tracks = track_rows(m)
    if not tracks:
        return [Chart(f"{slug}-tracks", None, None, None, ["no procedure track with levels and answers"])]
    cells = list(dict.fromkeys(t["cell"] for t in tracks))
    table = _track_table(tracks)
    summary = summary_table(tracks)
    png, svg = _tracks_figure(tracks, cells, study, group_note, out_dir, f"{slug}-tracks")
    methods = sorted(set(table["method"]))
    out = [Chart(f"{slug}-tracks", png, svg, table,
                 [f"{group_note}: one track per participant and procedure cell (the crossing of its block's factors, "
                  "by its levels); threshold and interval: " + "; ".join(methods),
                  "a threshold that the track does not determine is said in words (threshold_says), never written "
                  "as a number; interval_at_bound: an interval end on the grid's or the level's bound"])]
    png, svg = _thresholds_figure(tracks, summary, cells, study, group_note, out_dir, f"{slug}-thresholds")
    out.append(Chart(f"{slug}-thresholds", png, svg, summary,
                     [f"{group_note}: per cell, the determined thresholds' mean with a t 95 % interval across "
                      f"participants ({MIN_FOR_INTERVAL} or more) and their median; tracks whose threshold is not "
                      "determined are counted, not averaged, and a cell where half its tracks or more are not "
                      "determined gets no number"]))
    if len(cells) > 1:
        out.append(Chart(f"{slug}-threshold-comparisons", None, None, comparisons_table(tracks),
                         [f"{group_note}: each pair of cells, paired across the participants with a determined "
                          "threshold in both: mean of (second - first) with its t 95 % interval, paired t-test "
                          "(not adjusted for the number of pairs)"]))
    return out
