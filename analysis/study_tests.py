"""Tests of a study's measure with participants as the unit: answers of one participant are not independent, so a
share is first taken per participant, and the test runs across participants.

  per condition   the share of answers (Wilson 95 %, descriptive) and one exact test against chance of the
                  participants' shares (3 or more participants; `test` names it, `p` is its p-value, the one that
                  Holm adjusts and the chart's stars show - no second p is printed beside it):
                  - chance 0.5 (a pair, a side): the exact sign-flip permutation test of the participants' shares
                    around 0.5 (sign_flip_p). Under the null each participant's share - 0.5 is symmetric about 0
                    (binomial answers at 0.5, or participants with preferences spread symmetrically about it), so
                    each of the 2^G sign patterns of the deviations is equally likely and the p-value, the share of
                    patterns whose |mean| reaches the observed one, is exact at any N of participants and answers.
                    It replaced a one-sample t of the shares, whose false-positive rate was 12.5 % with 7
                    participants of one answer each (6 of 7 one way: t p = 0.047, exact 0.125), and which was
                    undefined where every participant chose the same side: a unanimous cell now gets the smallest p
                    any cell of G participants can get (2 / 2^G), never a larger one than a weaker cell.
                  - chance other than 0.5 (odd one out 1/n, correct at chance): a guessing participant's share is
                    skewed (Binomial(n, 1/3) / n is not symmetric about 1/3), so no sign flip is exact; the test is
                    the exact binomial test of the answers under every participant guessing at chance
                    (binomial_null_p): under that null every answer is an independent draw at chance, so the total is
                    binomial. With a correct answer, below chance has no mirror image, and "does anyone do better
                    than guessing" is the question asked.
                  The sign flips are enumerated exactly (_sum_distribution); tests/test_stats.py measures the
                  false-positive rate at 3-12 participants with 1-20 answers each; one participant: the exact
                  binomial test of that participant's answers (stats.binom_p; one_participant_test), none for a
                  single answer (said in words: one answer cannot test anything - at chance 0.5 its p is 1 whichever
                  it is), and where n answers can never reach p < 0.05 the words say how low p can go; two: no test
                  (said in words: a sign flip of 2 can never give p < 0.5).
  group effect    the participants' shares (or mean values) compared between the between-subject groups: Welch's t
                  and Mann-Whitney's U for two groups, Welch's one-way ANOVA and Kruskal-Wallis for more
"""
import functools
import math

import numpy as np
import pandas as pd
from scipy import stats as sps

import stats

MIN_PARTICIPANTS_T = 3  # a test across participants needs some: 2 sign patterns of 4 are as extreme as any
EXACT_SUPPORT = 1 << 21  # distinct sums convolved exactly; beyond: the sign patterns listed (<= 20), else sampled
MONTE_CARLO_DRAWS, MONTE_CARLO_SEED = 200_000, 38


def per_participant(m, column="y", by=()):
    """One row per participant (and level of `by`): n answers and the mean of `column` (a share for a 0/1 measure)."""
    keys = ["participant"] + list(by)
    g = m.groupby(keys, dropna=False)[column]
    return g.agg(n="count", mean="mean").reset_index()


def sides(values, chance):
    """How many values lie above chance and how many below (those at chance in neither)."""
    return int(np.sum(np.asarray(values) > chance + 1e-12)), int(np.sum(np.asarray(values) < chance - 1e-12))


def sign_p(values, chance):
    """Exact two-sided sign test: how many values lie above chance among those that differ from it. (Not the
    per-condition test: it throws away how far each participant lies from chance, so a unanimous cell and one with
    every participant barely above chance get the same p; sign_flip_p keeps it.)"""
    above, below = sides(values, chance)
    return (stats.binom_p(above, above + below, 0.5) if above + below else math.nan), above, below


def _sum_distribution(parts):
    """The exact distribution of a sum of independent integer-valued variables, each given as (values,
    probabilities): (values, probabilities) of the sum; None when it would hold more than EXACT_SUPPORT distinct
    values."""
    values, probs = np.zeros(1, np.int64), np.ones(1)
    for v, p in parts:
        values = (values[:, None] + np.asarray(v, np.int64)[None, :]).ravel()
        probs = (probs[:, None] * np.asarray(p, float)[None, :]).ravel()
        values, inverse = np.unique(values, return_inverse=True)
        if len(values) > EXACT_SUPPORT:
            return None
        probs = np.bincount(inverse, weights=probs, minlength=len(values))
    return values, probs


@functools.lru_cache(maxsize=65536)
def _sign_flips(deviations):
    """The distribution of sum(+-d) over the equally likely sign patterns of the integer deviations d."""
    return _sum_distribution([((-d, d), (0.5, 0.5)) for d in deviations if d])


def sign_flip_p(k, n):
    """Exact two-sided sign-flip permutation p of the participants' shares k[i] / n[i] around 0.5: the share of the
    2^G sign patterns of (share - 0.5) whose sum is at least as far from 0 as the observed one (participants at 0.5
    add 0 either way). Exact when each participant's deviation is symmetric about 0 under the null (binomial
    answers at 0.5, or rates spread symmetrically about it); its smallest value is 2 / 2^G, reached when every
    participant lies as far as possible on one side (every answer one way: unanimous). The deviations are counted
    in integers (units of 1 / lcm(2 n)), so ties are exact."""
    k, n = [int(x) for x in k], [int(x) for x in n]
    if not n:
        return math.nan
    unit = math.lcm(*[2 * x for x in n])
    d = [(2 * a - b) * (unit // (2 * b)) for a, b in zip(k, n)]
    observed = abs(sum(d))
    # Participants with many different answer counts can put the common unit beyond 64-bit integers: sampled then.
    dist = _sign_flips(tuple(sorted(abs(x) for x in d))) if sum(abs(x) for x in d) < 2 ** 62 else None
    if dist is None:
        size = np.abs(np.array(d, dtype=float)) / unit
        target = observed / unit - 1e-9
        if len(d) <= 20:  # every sign pattern listed, in floats (ties to 1e-9 count as reached: a larger p)
            hits = 0
            for start in range(0, 2 ** len(d), 1 << 16):
                rows = np.arange(start, min(start + (1 << 16), 2 ** len(d)))[:, None] >> np.arange(len(d)) & 1
                hits += int(np.sum(np.abs((2.0 * rows - 1) @ size) >= target))
            return hits / 2 ** len(d)
        # Monte Carlo sign patterns, seeded: (1 + hits) / (1 + draws) is a valid p.
        rng = np.random.default_rng(MONTE_CARLO_SEED)
        signs = rng.choice((-1.0, 1.0), size=(MONTE_CARLO_DRAWS, len(d)))
        hits = int(np.sum(np.abs(signs @ size) >= target))
        return (1 + hits) / (1 + MONTE_CARLO_DRAWS)
    values, probs = dist
    return float(min(1.0, probs[np.abs(values) >= observed].sum()))


def binomial_null_p(k, n, chance):
    """Exact two-sided p of k[i] of n[i] answers per participant under every participant guessing at chance: then
    every answer is an independent Bernoulli(chance), so the answers' total is Binomial(sum n, chance) and the test
    is stats.binom_p of the totals (scipy's 'minlike' two-sided rule). Used where chance is not 0.5 (a guessing
    participant's share is skewed, so no sign flip is exact); it asks whether the participants guess, which a task
    with a correct answer asks (no one sees it below chance). Every answer correct is the least likely outcome when
    chance < 0.5, so its p, chance^N, is the smallest of any cell of N answers."""
    return stats.binom_p(int(np.sum(k)), int(np.sum(n)), chance)


def one_participant_test(k, n, chance):
    """One participant's k of n answers against chance: dict(test, p). The exact binomial test of the answers, and none
    for a single answer: it is one way or the other, and guessing gives either often (at chance 0.5 its p is 1
    whichever it is; a statistic is printed only where it means something). Where no count of n answers could reach
    p < 0.05 (n < 6 at chance 0.5), the words say how low p can go."""
    k, n = int(k), int(n)
    if n == 1:
        return {"test": "none: one answer cannot test anything (one way or the other, guessing gives either often)",
                "p": math.nan}
    words = "exact binomial, one participant's answers"
    floor = min(stats.binom_p(j, n, chance) for j in range(n + 1)) if n > 0 else math.nan
    if floor >= 0.05:
        words += f" (with {n} answers no p can be below {floor:.3g})"
    return {"test": words, "p": stats.binom_p(k, n, chance)}


def exact_test_words(chance, people):
    if abs(chance - 0.5) < 1e-12:
        floor = 2 / 2 ** people
        return (f"exact sign-flip permutation test of {people} participants' shares around 0.5 (all 2^{people} "
                f"sign patterns" + (f"; with {people} participants no p can be below {floor:.3g}" if floor >= 0.05
                                    else "") + ")")
    return (f"exact binomial test of {people} participants' answers against chance {chance:.3g} (null: every "
            f"participant guessing)")


def against_chance(m, chance, people=None):
    """The test of m's 0/1 measure (column y) against chance with participants as the unit (against_chance_counts
    on each participant's count of 1s and answers)."""
    pp = per_participant(m)
    n = pp["n"].to_numpy(int)
    return against_chance_counts(np.rint(pp["mean"].to_numpy(float) * n).astype(int), n, chance, people)


def participants_words(count):
    """The subject of a sentence saying they are too few: "1 participant is", "2 participants are"."""
    return f"{count} participant is" if count == 1 else f"{count} participants are"


def against_chance_counts(k, n, chance, people=None):
    """The test against chance of participants with k[i] of n[i] answers 1: dict(test, p, and for 3+ participants
    participant_mean, participant_low, participant_high - the participants' shares' mean with a t 95 % interval, a
    description - participants_above, participants_below). One p: sign_flip_p at chance 0.5, binomial_null_p
    otherwise (see the module's docstring). people: how many participants the whole analysis has (a table's rows
    are tested alike): one - the exact binomial test of that participant's answers."""
    k, n = np.asarray(k, int), np.asarray(n, int)
    shares = k / n
    n_people = len(shares)
    if (people or n_people) == 1:
        return one_participant_test(k.sum(), n.sum(), chance)
    if n_people < MIN_PARTICIPANTS_T:
        return {"test": f"none: {participants_words(n_people)} too few for a test across participants (needs "
                        f">= {MIN_PARTICIPANTS_T})", "p": math.nan}
    mean, sd = shares.mean(), shares.std(ddof=1)
    half = sps.t.ppf(0.975, n_people - 1) * sd / math.sqrt(n_people)
    above, below = sides(shares, chance)
    p = sign_flip_p(k, n) if abs(chance - 0.5) < 1e-12 else binomial_null_p(k, n, chance)
    return {"test": exact_test_words(chance, n_people), "p": p, "participant_mean": mean,
            "participant_low": max(0.0, mean - half), "participant_high": min(1.0, mean + half),
            "participants_above": above, "participants_below": below}


def summary_by_level(m, chance, what, by):
    """The summary per level of the factors `by` (their levels ask different questions: design.comparing_factors),
    never pooled across them; p Holm-adjusted over the levels. One line."""
    keys = [m[f].astype(str) for f in by]
    parts = list(m.groupby(keys if len(keys) > 1 else keys[0], sort=True))  # one factor: its level, not a 1-tuple
    raw = [chance_p(d, chance) for _, d in parts]
    adjusted = stats.holm(raw)
    words = []
    for (level, d), p in zip(parts, adjusted):
        name = ", ".join(f"{f} {v}" for f, v in zip(by, level if isinstance(level, tuple) else (level,)))
        words.append(f"{name}: " + summary_words(d, chance, what, p_holm=(p, len(parts))))
    table = pd.DataFrame([{"participants": d["participant"].nunique(), "n": len(d), "p": p}
                          for (_, d), p in zip(parts, raw)])
    floor = holm_floor_words(table, chance, m["participant"].nunique(), "levels")
    return (f"per {', '.join(by)}, no pooled figure ({', '.join(by)} changes which sources are compared, so a share "
            f"across its levels would average different questions): " + "; ".join(words) +
            (f"; {floor}" if floor else ""))


def smallest_p(participants, answers, chance, people):
    """The smallest p the test of one condition against chance can give (the sign-flip test's 2 / 2^G at 0.5, the
    binomial's at either extreme count otherwise or for one participant's answers); NaN where it gives no test."""
    if people == 1:
        return min(stats.binom_p(j, answers, chance) for j in range(answers + 1)) if answers > 1 else math.nan
    if participants < MIN_PARTICIPANTS_T:
        return math.nan
    if abs(chance - 0.5) < 1e-12:
        return 2 / 2 ** participants
    return min(stats.binom_p(0, answers, chance), stats.binom_p(answers, answers, chance))


def holm_floor_words(t, chance, people, what="conditions", alpha=0.05):
    """Where no row of a table tested against chance and Holm-adjusted over its rows can reach alpha: one sentence
    with the smallest p attainable after the correction (the number of tests times the smallest p any row's test can
    give); else "". t: rows with participants, n and p (NaN where untested); people: the analysis's participants."""
    if chance is None or t.empty or "p" not in t:
        return ""
    tested = t[t["p"].notna()]
    floors = [smallest_p(int(g), int(n), chance, people) for g, n in zip(tested["participants"], tested["n"])]
    floors = [f for f in floors if not math.isnan(f)]
    if len(tested) < 2 or not floors:
        return ""  # one test: its own words say how low its p can go
    best = min(1.0, len(tested) * min(floors))
    if best < alpha:
        return ""
    return (f"none of the {len(tested)} {what} can reach p < {alpha:g} after Holm's correction: the smallest p "
            f"attainable is {best:.3g} ({len(tested)} tests x {min(floors):.3g}, the smallest p one test of these "
            f"participants and answers can give)")


def chance_p(m, chance):
    """The p of summary_words' test of m against chance (NaN where it gives none)."""
    if chance is None:
        return math.nan
    if m["participant"].nunique() == 1:
        return one_participant_test(int(m["y"].sum()), len(m), chance)["p"]
    return against_chance(m, chance)["p"]


def summary_words(m, chance, what, p_holm=None):
    """One line for the report's summary: the measure over participants and its test against chance (None: no
    chance level, the share only). p_holm: (p, levels) where the line is one of a set of levels, Holm-adjusted."""
    def said(p):
        return p_text(p) if p_holm is None else f"{p_text(p_holm[0])} (Holm over {p_holm[1]} levels)"
    k, n = int(m["y"].sum()), len(m)
    people = m["participant"].nunique()
    if people == 1:
        p, lo, hi = stats.wilson(k, n)
        text = f"{what} {p:.2f} [{lo:.2f}, {hi:.2f}] of {n} answers (one participant)"
        if chance is not None:
            r = one_participant_test(k, n, chance)
            text += (f"; chance {chance:.2g}, {said(r['p'])} (exact binomial)" if not math.isnan(r["p"]) else
                     f"; chance {chance:.2g}: one answer cannot test anything")
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
        text += (f"; against chance {chance:.2g}: {r['test']}, {said(r['p'])}; {r['participants_above']} of "
                 f"{people} participants above chance, {r['participants_below']} below")
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
        # From two participants a t(1) interval is 12.7 of their SEs wide and no estimate of their spread: none.
        half = (sps.t.ppf(0.975, len(v) - 1) * v.std(ddof=1) / math.sqrt(len(v)) if len(v) >= MIN_PARTICIPANTS_T
                else math.nan)
        rows.append({"group": str(level), "participants": len(v), "answers": int(g["n"].sum()),
                     "participant_mean": v.mean(),
                     # Shares (column y) cannot leave [0, 1]: their t interval is cut there (np.clip keeps a NaN,
                     # where max(0.0, nan) gave 0 and a group without an interval read [0, 1]).
                     "ci_low": float(np.clip(v.mean() - half, 0.0, 1.0)) if column == "y" else v.mean() - half,
                     "ci_high": float(np.clip(v.mean() + half, 0.0, 1.0)) if column == "y" else v.mean() + half,
                     "participant_sd": v.std(ddof=1) if len(v) > 1 else math.nan})
    table = pd.DataFrame(rows)
    names = list(samples)
    notes = ["one value per participant (the share of their answers, or their mean), compared between the groups"]
    sizes = [len(samples[n]) for n in names]
    few = [n for n in names if len(samples[n]) < MIN_PARTICIPANTS_T]
    if few:
        notes.append(f"no interval for group{'s' if len(few) > 1 else ''} {', '.join(few)}: fewer than "
                     f"{MIN_PARTICIPANTS_T} participants (from two, a t(1) interval is no estimate of their spread)")
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
