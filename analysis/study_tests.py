"""Tests of a study's measure with participants as the unit: answers of one participant are not independent, so a
share is first taken per participant, and the test runs across participants.

  per condition   the share of answers (Wilson 95 %, descriptive) and, against chance, a one-sample t test of the
                  participants' shares (with 3 or more participants) beside an exact sign test (how many participants
                  were above chance, ties left out); one participant: the exact binomial test of that participant's
                  answers; two: no test (said in words)
  group effect    the participants' shares (or mean values) compared between the between-subject groups: Welch's t
                  and Mann-Whitney's U for two groups, Welch's one-way ANOVA and Kruskal-Wallis for more
"""
import math

import numpy as np
import pandas as pd
from scipy import stats as sps

import stats

MIN_PARTICIPANTS_T = 3  # a t test across participants needs some spread to estimate; with 2 it has 1 df


def per_participant(m, column="y", by=()):
    """One row per participant (and level of `by`): n answers and the mean of `column` (a share for a 0/1 measure)."""
    keys = ["participant"] + list(by)
    g = m.groupby(keys, dropna=False)[column]
    return g.agg(n="count", mean="mean").reset_index()


def sign_p(values, chance):
    """Exact two-sided sign test: how many values lie above chance among those that differ from it."""
    above = int(np.sum(np.asarray(values) > chance + 1e-12))
    below = int(np.sum(np.asarray(values) < chance - 1e-12))
    return (stats.binom_p(above, above + below, 0.5) if above + below else math.nan), above, below


def against_chance(m, chance, people=None):
    """The test of m's 0/1 measure against chance with participants as the unit: dict(test, p, and for 3+
    participants mean, ci_low, ci_high of the participants' shares, t, df, p_sign, above, below). people: how many
    participants the whole analysis has (a table's rows are tested alike): one - the exact binomial test of that
    participant's answers."""
    shares = per_participant(m)["mean"].to_numpy(float)
    n_people = len(shares)
    if (people or n_people) == 1:
        k, n = int(m["y"].sum()), len(m)
        return {"test": "exact binomial, one participant's answers", "p": stats.binom_p(k, n, chance)}
    if n_people < MIN_PARTICIPANTS_T:
        return {"test": f"none: {n_people} participants are too few for a test across participants (needs "
                        f">= {MIN_PARTICIPANTS_T})", "p": math.nan}
    mean, sd = shares.mean(), shares.std(ddof=1)
    half = sps.t.ppf(0.975, n_people - 1) * sd / math.sqrt(n_people)
    p_sign, above, below = sign_p(shares, chance)
    if sd == 0:  # every participant had the same share: t is undefined, the sign test still says something
        t, p = math.nan, p_sign
        test = "exact sign test across participants (every participant's share the same: no t)"
    else:
        t = (mean - chance) / (sd / math.sqrt(n_people))
        p = float(2 * sps.t.sf(abs(t), n_people - 1))
        test = f"one-sample t across {n_people} participants' shares"
    return {"test": test, "p": p, "participant_mean": mean, "participant_low": max(0.0, mean - half),
            "participant_high": min(1.0, mean + half), "t": t, "df": n_people - 1, "p_sign": p_sign,
            "participants_above": above, "participants_below": below}


def summary_words(m, chance, what):
    """One line for the report's summary: the measure over participants and its test against chance (None: no
    chance level, the share only)."""
    k, n = int(m["y"].sum()), len(m)
    people = m["participant"].nunique()
    if people == 1:
        p, lo, hi = stats.wilson(k, n)
        text = f"{what} {p:.2f} [{lo:.2f}, {hi:.2f}] of {n} answers (one participant)"
        if chance is not None:
            text += f"; chance {chance:.2g}, {p_text(stats.binom_p(k, n, chance))} (exact binomial)"
        return text
    shares = per_participant(m)["mean"].to_numpy(float)
    mean = shares.mean()
    if people < MIN_PARTICIPANTS_T:
        return (f"{what}: mean of {people} participants' shares {mean:.2f} ({n} answers)" +
                (f"; chance {chance:.2g}: too few participants for a test across them" if chance is not None else ""))
    half = sps.t.ppf(0.975, people - 1) * shares.std(ddof=1) / math.sqrt(people)
    # A t interval of shares is cut at 0 and 1: a share beyond them is not a value the interval could hold.
    text = (f"{what}: mean of {people} participants' shares {mean:.2f} [{max(0.0, mean - half):.2f}, "
            f"{min(1.0, mean + half):.2f}] ({n} answers)")
    if chance is not None:
        r = against_chance(m, chance)
        text += (f"; against chance {chance:.2g}: {r['test']}, {p_text(r['p'])}; {r['participants_above']} of "
                 f"{people} participants above chance ({p_text(r['p_sign'])}, sign test)")
    return text


def p_text(p):
    if p is None or (isinstance(p, float) and math.isnan(p)):
        return "no test"
    return "p < 0.001" if p < 0.001 else f"p = {p:.3f}"


def group_effect(m, group, column="y"):
    """The between-subject group's effect with participants as the unit: per group the participants, the mean of
    their shares (or mean values) with a t 95 % interval; then Welch's t and Mann-Whitney's U (two groups) or Welch's
    ANOVA and Kruskal-Wallis (more). Returns (table, notes, words)."""
    pp = per_participant(m, column, by=[group])
    # A participant in two groups would make the groups dependent: the record assigns one group per session, so only
    # a participant's repeated sessions could; those are analysed apart, so here each participant has one group.
    rows, samples = [], {}
    for level, g in pp.groupby(group):
        v = g["mean"].to_numpy(float)
        samples[str(level)] = v
        half = sps.t.ppf(0.975, len(v) - 1) * v.std(ddof=1) / math.sqrt(len(v)) if len(v) > 1 else math.nan
        rows.append({"group": str(level), "participants": len(v), "answers": int(g["n"].sum()),
                     "participant_mean": v.mean(),
                     # Shares (column y) cannot leave [0, 1]: their t interval is cut there.
                     "ci_low": max(0.0, v.mean() - half) if column == "y" else v.mean() - half,
                     "ci_high": min(1.0, v.mean() + half) if column == "y" else v.mean() + half,
                     "participant_sd": v.std(ddof=1) if len(v) > 1 else math.nan})
    table = pd.DataFrame(rows)
    names = list(samples)
    notes = ["one value per participant (the share of their answers, or their mean), compared between the groups"]
    sizes = [len(samples[n]) for n in names]
    if len(names) < 2:
        return table, notes, "one group only"
    # Welch's t on 2 against 2 has about 1.6 degrees of freedom: as few as the test against chance takes (3).
    if min(sizes) < MIN_PARTICIPANTS_T:
        words = ("no test of the group effect: " + ", ".join(f"group {n} has {len(samples[n])} participant"
                                                              f"{'s' if len(samples[n]) != 1 else ''}" for n in names)
                 + f" (needs >= {MIN_PARTICIPANTS_T} in each)")
        notes.append(words)
        return table, notes, words
    means = {n: samples[n].mean() for n in names}
    order = sorted(names, key=lambda n: means[n])
    direction = f"group {order[-1]} higher than group {order[0]}"
    if len(names) == 2:
        a, b = samples[names[0]], samples[names[1]]
        if np.var(a, ddof=1) + np.var(b, ddof=1) == 0:
            t_words, p_t = "Welch's t undefined (no spread within either group)", math.nan
        else:
            t, p_t = sps.ttest_ind(a, b, equal_var=False)
            t_words = f"Welch's t = {t:.2f}, {p_text(float(p_t))}"
        u, p_u = sps.mannwhitneyu(a, b, alternative="two-sided")
        # The direction is said as a finding only where a test finds it; otherwise as what the sample shows.
        found = (not math.isnan(float(p_t)) and float(p_t) < 0.05) or float(p_u) < 0.05
        words = (f"{t_words}; Mann-Whitney U = {u:.1f}, {p_text(float(p_u))}; " +
                 (direction if found else f"{direction} in this sample, not significant at 0.05 by either test"))
        table["test"] = ["Welch t / Mann-Whitney U"] + [""] * (len(table) - 1)
        table["p_welch"] = [float(p_t)] + [math.nan] * (len(table) - 1)
        table["p_mann_whitney"] = [float(p_u)] + [math.nan] * (len(table) - 1)
    else:
        p_w = welch_anova_p([samples[n] for n in names])
        h, p_k = sps.kruskal(*[samples[n] for n in names])
        found = (not math.isnan(p_w) and p_w < 0.05) or float(p_k) < 0.05
        words = (f"Welch's ANOVA {p_text(p_w)}; Kruskal-Wallis H = {h:.2f}, {p_text(float(p_k))}; highest group "
                 f"{order[-1]}, lowest {order[0]}" + ("" if found else " in this sample, not significant at 0.05 by "
                                                      "either test"))
        table["test"] = ["Welch ANOVA / Kruskal-Wallis"] + [""] * (len(table) - 1)
        table["p_welch"] = [p_w] + [math.nan] * (len(table) - 1)
        table["p_kruskal"] = [float(p_k)] + [math.nan] * (len(table) - 1)
    notes.append("group effect: " + words)
    return table, notes, words


def welch_anova_p(samples):
    """Welch's one-way ANOVA (unequal variances) p-value; NaN when a group has no spread."""
    k = len(samples)
    n = np.array([len(s) for s in samples], float)
    m = np.array([np.mean(s) for s in samples])
    v = np.array([np.var(s, ddof=1) for s in samples])
    if np.any(v == 0):
        return math.nan
    w = n / v
    mw = np.sum(w * m) / np.sum(w)
    a = np.sum(w * (m - mw) ** 2) / (k - 1)
    tmp = np.sum((1 - w / np.sum(w)) ** 2 / (n - 1))
    b = 1 + 2 * (k - 2) / (k ** 2 - 1) * tmp
    f = a / b
    df2 = (k ** 2 - 1) / (3 * tmp)
    return float(sps.f.sf(f, k - 1, df2))
