"""Any study, analysed from what its trials declare - not from its name.

What a study measures follows from its rows of trials.csv (their task and the columns the export filled):
  pair        forced choice between two sides (side by side or two intervals): did the participant choose the side
              that showed the larger blur radius (chose_more_blurred)? chance 0.5
  odd         odd one out of n intervals: was the odd interval named (correct)? chance 1/n
  procedure   an adaptive procedure (staircase, QUEST+): correct at the level shown; chance 0.5 (1/n odd one out)
  yes_no      one object: the share of "yes"
  rating      one object: the rating (1..n)
  adjustment  the level accepted
The design comes from the record (design.py: the codebook's roles, the rows' procedure cells). Per study: a table per
condition (the crossing of the within factors and cells) with Wilson 95 % intervals and tests against chance with
participants as the unit (study_tests.py, Holm-adjusted; none for an adaptive procedure, whose share correct the
procedure sets), a chart per factor, a psychometric function where the design defines a correct answer - per
procedure cell over its level, an odd one out's over the blur difference on screen in arcmin - with guess and lapse
rates and a bootstrap band (none for a preference question), logistic models across participants (a GLMM where there
are three or more), the level tracks of adaptive procedures with a threshold
and interval per track and cell (tracks.py), and the side bias. A between-subject group
is a factor: everything per group, then the groups compared with participants as the unit. People and simulated
observers are analysed apart (report.py --pool-simulated pools them), and so are protocol versions and repeated
sessions (report.py, common.study_parts). A study that cannot be analysed raises Skip saying why.
"""
import math
import re

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

import criteria
import crossed
import groups
import across_observers
import stats
import study_tests
import tracks
from common import (UNKNOWN_UNIT, Chart, Skip, axis_label, distinct_stems, error_bars, factor_label, file_stem, level_text,
                    level_unit, participants_note, save, stars, text)
from design import comparing_factors, design_of

KIND_TITLES = {"pair": "forced choice between two", "odd": "odd one out",
               "procedure": "adaptive procedure", "yes_no": "yes / no", "rating": "rating",
               "adjustment": "method of adjustment"}


# Why a share gets no test against chance, by the kind of answer (a yes/no study was told an adaptive procedure
# set its share).
NO_CHANCE_WHY = {"procedure": "; no test against chance: an adaptive procedure sets the share correct",
                 "yes_no": "; no test against chance: a share of 'yes' has no chance level (it is the answer itself, "
                           "compared between conditions and groups)"}


def design_factors(d, codebook):
    """The design's factors that vary within these rows (within-subject factors and procedure cells), in column
    order; the between-subject group is not one of them (see design.Design)."""
    return list(design_of(d, codebook).factors)


def kind_of(d):
    tasks = set(d["task"])
    for task in ("adjustment", "rating", "yes_no"):
        if task in tasks:
            return task
    if "odd_interval" in d and text(d["odd_interval"]).ne("").any():
        return "procedure" if _has(d, "procedure_cell") else "odd"
    return "procedure" if _has(d, "procedure_cell") else "pair"


def _has(d, column):
    return column in d and text(d[column]).ne("").any()


def _num(series):
    return pd.to_numeric(series.astype(str).replace({"": np.nan, "nan": np.nan}), errors="coerce")


def measured(d, kind):
    """The answered rows with the study's measure: y (0/1) for binary kinds or value, and chance (None without one)."""
    a = d[d["status"] == "answered"].copy()
    n_alternatives = _num(a["intervals"]).dropna() if "intervals" in a else pd.Series(dtype=float)
    odd_chance = 1 / n_alternatives.iloc[0] if len(n_alternatives) else None
    if kind == "pair":
        a = a[a["chosen_side"].isin(["left", "right"])]
        a["y"] = _num(a["chose_more_blurred"])
        return a.dropna(subset=["y"]), 0.5, "chose the more blurred side"
    if kind in ("odd", "procedure"):
        a["y"] = _num(a["correct"])
        chance = odd_chance if odd_chance else 0.5
        return a.dropna(subset=["y"]), chance, "correct"
    if kind == "yes_no":
        a["y"] = (a["yes_no"] == "yes").astype(float)
        return a, None, "answered yes"
    if kind == "rating":
        a["value"] = _num(a["rating"])
        return a.dropna(subset=["value"]), None, "rating"
    a["value"] = _num(a["adjusted_level"])
    return a.dropna(subset=["value"]), None, "level accepted"


def _label(value):
    """A level as the tables write it (common.level_text): 3.0 as 3, 0.2 as the protocol gave it, a side's radius with
    its unit (object=4 photo px), a level the row does not have (NaN: not applicable) blank."""
    return level_text(value)


def condition_table(m, factors, chance):
    """One row per condition: n, k, share with its Wilson interval (descriptive: answers pooled), the participants,
    and with a chance level the test against it with participants as the unit (study_tests.against_chance),
    Holm-adjusted over the conditions that have one."""
    keys = None if not factors else factors[0] if len(factors) == 1 else factors
    groups = m.groupby(keys, dropna=False) if keys is not None else [((), m)]
    rows = []
    for key, g in groups:
        key = key if isinstance(key, tuple) else (key,)
        row = {f: _label(v) for f, v in zip(factors, key)}
        n, k = len(g), int(g["y"].sum())
        p, lo, hi = stats.wilson(k, n)
        row.update(n=n, k=k, share=p, share_low=lo, share_high=hi, participants=g["participant"].nunique())
        if chance is not None:
            row["chance"] = chance
            row.update(study_tests.against_chance(g, chance, people=m["participant"].nunique()))
        rows.append(row)
    t = pd.DataFrame(rows)
    if chance is not None and not t.empty:
        t["p_holm"] = stats.holm(list(t["p"]))
    return t


def _sorted_levels(values):
    numeric = pd.to_numeric(pd.Series(values), errors="coerce")
    if numeric.notna().all():
        return [values[i] for i in np.argsort(numeric.to_numpy(), kind="stable")]
    # Cells such as edge=10 and edge=2 in the order of their numbers (text order put a depth 10 before 2).
    import re

    def key(v):
        return [(0, float(part), "") if re.fullmatch(r"[-+]?\d+(?:\.\d*)?(?:[eE][-+]?\d+)?", part) else (1, 0.0, part)
                for part in re.split(r"([-+]?\d+(?:\.\d*)?(?:[eE][-+]?\d+)?)", str(v)) if part]
    return sorted(values, key=key)


def _pooled(m, factors):
    """The factors of `factors` that vary in m, each with its levels ("pattern (1, 2, 3)"), and the title's words
    for them: a chart per level of one factor pools the others' levels (a pattern comparing two blurred balls pooled
    with ones against a sharp ball is a mixture), and says so."""
    over = [f"{g} ({', '.join(_label(v) for v in _sorted_levels(list(m[g].dropna().unique())))})"
            for g in factors if g in m and m[g].nunique() > 1]
    title = (f", pooled over {over[0].split(' (')[0]}" if len(over) == 1 else
             ", pooled over the other factors" if over else "")
    return over, title


def factor_chart(m, factor, chance, what, study, out_dir, name, group_note, pooled_over=(), mixed=()):
    """Bars per level of `factor`; each pools the answers over the levels of the factors in pooled_over (said). Where
    `mixed` names factors among them whose levels change which sources a pair compares (design.comparing_factors),
    the caller passes chance None: such a bar averages different questions, so it is not tested (said)."""
    t = condition_table(m, [factor], chance)
    over, pooled_title = _pooled(m, pooled_over)
    t = t.set_index(factor).loc[_sorted_levels(list(t[factor]))].reset_index()
    fig, ax = plt.subplots(figsize=(max(4.5, 0.7 * len(t) + 2.5), 3.6))
    x = np.arange(len(t))
    ax.bar(x, t["share"], 0.6, color="#0072B2", edgecolor="white")
    ax.errorbar(x, t["share"], yerr=error_bars(t["share"], t["share_low"], t["share_high"]), fmt="none",
                ecolor="#333333", lw=0.9)
    if chance is not None:
        ax.axhline(chance, color="#999999", lw=1, ls="--", label=f"chance {chance:.2g}")
        for xi, p, hi in zip(x, t["p_holm"], t["share_high"]):
            if stars(p):
                ax.text(xi, hi + 0.03, stars(p), ha="center", va="bottom")
        # Beside the axes, not on them: inside, it covered a bar (a first-time experimenter's finding).
        ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0))
    ax.set_xticks(x)
    # Each bar's answers under its level: a share of 1 answer and one of 40 look alike as bars.
    ax.set_xticklabels([f"{level}\nn = {int(n)}" for level, n in zip(t[factor], t["n"])])
    ax.set_xlabel(factor_label(factor))
    ax.set_ylim(0, 1.12)
    ax.set_ylabel(f"share: {what}")
    ax.grid(axis="x", visible=False)
    ax.set_title(f"{study}: {what} per {factor}{pooled_title}\n{group_note}, {int(t['n'].sum())} answers", loc="left")
    png, svg = save(fig, out_dir, name)
    tests = sorted(set(t["test"])) if "test" in t else []
    notes = ["bars: share of answers with Wilson 95 % intervals (answers pooled: a description, not a test)" +
             (f"; each bar pools the levels of {' and '.join(over)}: the per-condition table has each crossing"
              if over else "") +
             (f"; * p < 0.05, ** < 0.01, *** < 0.001 against chance, Holm-adjusted over the chart's bars, with "
              f"participants as the unit: {'; '.join(tests)}" if chance is not None else "") +
             (f"; no test against chance: each bar pools the levels of {' and '.join(mixed)}, which compare "
              "other sources (different questions); the per-condition table tests each crossing" if mixed else "")]
    floor = study_tests.holm_floor_words(t, chance, m["participant"].nunique(), "bars")
    return Chart(name, png, svg, t, notes + ([floor] if floor else []))


def value_chart(m, factor, what, study, out_dir, name, group_note, pooled_over=()):
    """Rating or adjusted level per level of a factor: mean with a t 95 % interval, every answer as a dot; each level
    pools the levels of the factors in pooled_over (said)."""
    over, pooled_title = _pooled(m, pooled_over)
    rows = []
    for level, g in m.groupby(factor, dropna=False):
        v = g["value"].to_numpy(float)
        half = stats.sps.t.ppf(0.975, len(v) - 1) * v.std(ddof=1) / math.sqrt(len(v)) if len(v) > 1 else math.nan
        rows.append({factor: _label(level), "n": len(v), "mean": v.mean(), "ci_low": v.mean() - half,
                     "ci_high": v.mean() + half, "median": float(np.median(v))})
    t = pd.DataFrame(rows)
    t = t.set_index(factor).loc[_sorted_levels(list(t[factor]))].reset_index()
    fig, ax = plt.subplots(figsize=(max(4.5, 0.7 * len(t) + 2.5), 3.6))
    x = np.arange(len(t))
    for xi, level in zip(x, t[factor]):
        v = m.loc[m[factor].map(_label) == level, "value"]
        jitter = np.random.default_rng(1).uniform(-0.12, 0.12, len(v))
        ax.plot(xi + jitter, v, "o", ms=3, color="#999999", alpha=0.6)
    ax.errorbar(x, t["mean"], yerr=error_bars(t["mean"], t["ci_low"], t["ci_high"]), fmt="o", color="#0072B2",
                ecolor="#0072B2", ms=6)
    ax.set_xticks(x)
    ax.set_xticklabels(list(t[factor]))
    ax.set_xlabel(factor_label(factor))
    ax.set_ylabel(what)
    ax.set_title(f"{study}: {what} per {factor}{pooled_title}\n{group_note}, {int(t['n'].sum())} answers", loc="left")
    png, svg = save(fig, out_dir, name)
    return Chart(name, png, svg, t, ["points: every answer; blue: the mean with its t 95 % interval" +
                                     (f"; each pools the levels of {' and '.join(over)}" if over else "")])


def models(m, factors, study, group_note, what, additive_note=""):
    """Logistic models across participants of the 0/1 measure against the factors (added), terms in words, and which
    to trust where the GLM and the GLMM disagree. additive_note: said where the factors could interact."""
    d = m.copy()
    for f in factors:
        d[f] = d[f].map(_label)
    rhs = " + ".join(f"C({f}, levels={_sorted_levels(list(d[f].unique()))!r})" for f in factors) if factors else "1"
    table, notes = across_observers.observer_models(d, "y", rhs, study=study)
    if table.empty:
        return Chart(f"{study}-models", None, None, table, notes)
    notes.insert(0, f"{group_note}: logistic models of '{what}' across participants; estimates in log-odds, each "
                    f"term against the baseline it names" + (f"; {additive_note}" if additive_note else ""))
    return Chart(f"{study}-models", None, None, table, notes)


def within_models(m, table, factors, chance, what, study, out_dir, slug, note):
    """The models of a 0/1 measure across participants; where two within factors cross, the shares drawn by both and
    the model with their interaction beside the additive one (crossed.py). table: the conditions table."""
    if len(factors) < 2:
        return [models(m, factors, slug, note, what)]
    crossed_note = crossed.NO_INTERACTION_NOTE.format(
        others="s" if len(factors) > 2 else "",
        name=f"{slug}-models-interaction" if len(factors) == 2 else "no table: with more than two factors none is "
                                                                    "fitted")
    charts = [models(m, factors, slug, note, what, crossed_note)]
    if len(factors) != 2:
        return charts
    a, b = sorted(factors, key=lambda f: -m[f].nunique())  # the factor of more levels along the x axis
    levels = {f: _sorted_levels(list(m[f].map(_label).unique())) for f in factors}
    t = table.assign(_a=table[a].map(levels[a].index), _b=table[b].map(levels[b].index)).sort_values(["_b", "_a"])
    charts.append(crossed.crossing_chart(t, a, b, chance, what, study, out_dir, f"{slug}-per-{a}-by-{b}", note))
    d = m.copy()
    for f in factors:
        d[f] = d[f].map(_label)
    charts.append(crossed.interaction_models(d, factors, slug, note, what, levels))
    return charts


def psychometric_chart(m, xcol, xlabel, chance, study, out_dir, name, group_note, n_boot, seed, what, cell="",
                       crit=None, tested=None):
    """A Weibull with the guess rate at chance over one procedure cell's (or one odd one out's) answers; raises Skip
    with too few levels or answers. crit: the threshold's criteria.Criterion (the cell's procedure's own; fixed
    levels' by default), tested: the tested range (criteria.tested_range; the levels shown by default). Returns
    (Chart, words): the threshold and slope as the summary says them - a number only where determined (the threshold
    inside the tested range with its interval too, the slope with an interval off its range's bounds), else words."""
    where = f" ({cell})" if cell else ""
    d = m.dropna(subset=[xcol])
    x, k = d[xcol].to_numpy(float), d["y"].to_numpy(float)
    if len(np.unique(x)) < 3 or len(x) < 20:
        raise Skip(f"{study}{where}: psychometric function needs >= 3 stimulus levels and >= 20 answers "
                   f"(has {len(np.unique(x))} levels, {len(x)} answers)")
    fit = stats.fit_psychometric(x, k, None, kind="weibull", gamma=chance, lam=(0.0, 0.1))
    # One bootstrap, --boot samples: the band and the threshold's interval come from the same refits.
    grid, lo, hi = stats.bootstrap(x, k, np.ones_like(k), fit, n_boot=n_boot, seed=seed)
    crit = crit or criteria.criterion("", None, chance)
    said = fitted_threshold(fit, crit, tested or criteria.tested_range(None, x))
    levels = pd.DataFrame({"x": x, "y": k}).groupby("x")["y"].agg(["sum", "count"]).reset_index()
    fig, ax = plt.subplots(figsize=(5.5, 3.8))
    ax.fill_between(grid, lo, hi, color="#0072B2", alpha=0.2, lw=0, label="95 % bootstrap band")
    ax.plot(grid, fit(grid), color="#0072B2", label="Weibull fit")
    sizes = 12 + 60 * levels["count"] / levels["count"].max()
    ax.scatter(levels["x"], levels["sum"] / levels["count"], s=sizes, color="#333333", zorder=3,
               label="share per level (size: answers)")
    ax.axhline(chance, color="#999999", ls="--", lw=1)
    label = crit.label(fit.gamma, fit.lam)
    if said["determined"]:
        ax.axvline(said["th"], color="#D55E00", lw=1, ls=":", label=f"threshold ({label}): {said['th']:.3g}")
    else:  # no line where no value is: the legend says why in words
        ax.plot([], [], " ", label=f"threshold ({label}): not determined")
    ax.set_xlabel(xlabel)
    ax.set_ylabel(f"share: {what}")
    ax.set_ylim(min(chance, 0.4) - 0.05, 1.05)
    ax.legend(loc="lower right", fontsize=8)
    ax.set_title(f"{study}: psychometric function{' - cell ' + cell if cell else ''}\n{group_note}, {len(x)} answers",
                 loc="left")
    png, svg = save(fig, out_dir, name)
    th_ok, beta_ok = said["determined"], said["slope_determined"]
    t = pd.DataFrame([{**({"cell": cell} if cell else {}), "threshold": said["th"] if th_ok else math.nan,
                       "threshold_low": said["low"] if th_ok else math.nan,
                       "threshold_high": said["high"] if th_ok else math.nan, "threshold_note": said["note"],
                       "on_bound": ", ".join(f"{k} at its {v[1]} bound {v[0]:.3g}" for k, v in fit.on_bound.items()),
                       "criterion": crit.short(), "criterion_fitted": label,
                       "criterion_share_correct": crit.psi(fit.gamma, fit.lam),
                       # The Weibull's scale is the threshold's other name: not a number where that is not one.
                       "alpha": fit.alpha if th_ok else math.nan, "beta_slope": fit.beta if beta_ok else math.nan,
                       "beta_low": fit.ci["beta"][0] if beta_ok else math.nan,
                       "beta_high": fit.ci["beta"][1] if beta_ok else math.nan, "slope_note": said["slope_note"],
                       "guess": fit.gamma, "lapse": fit.lam if "lam" not in fit.on_bound else math.nan, "answers": len(x),
                       "participants": d["participant"].nunique()}])
    p_mid = crit.psi(fit.gamma, fit.lam)
    notes = [f"Weibull with the guess rate fixed at chance ({chance:.3g}) and a lapse rate fitted in [0, 0.1]; "
             f"threshold at {crit.words}" + (f" (the fitted function gives {100 * p_mid:.1f} % there, lapse "
                                              f"{fit.lam:.2g})" if label != crit.short() else "") + ": " +
             said["words"] + "; " + said["slope_words"]]
    if fit.on_bound:
        names = {"lam": "lapse rate", "beta": "slope", "alpha": "scale (threshold)", "gamma": "guess rate"}
        notes.append("on a bound of its range: " + ", ".join(f"{names.get(k, k)} ({v[1]})"
                                                             for k, v in fit.on_bound.items()))
    if "procedure_cell" in d and d["procedure_cell"].astype(str).str.strip().isin(["", "nan"]).eq(False).any():
        # An adaptive track's levels follow its own answers and participants differ in threshold: the pooled fit
        # describes the answers, the study's result is each participant's track threshold (the tracks tables).
        notes.append("a description of the answers pooled over participants, not the study's result: an adaptive "
                     "procedure's thresholds are each participant's track's (the tracks and thresholds tables), "
                     "summarised across participants there")
    return Chart(name, png, svg, t, notes), said["words"]


def fitted_threshold(fit, crit, tested):
    """The threshold of a bootstrapped fit (stats.bootstrap) at crit over the tested range (low, high), and its slope,
    each as a number only where determined, else in words: a threshold beyond the range is an extrapolation, one whose
    interval reaches beyond it (or that the refits could not bound) is not determined by the answers, and so is a
    slope on a bound of its range or whose interval reaches one. Returns a dict: th, low, high, determined, note (the
    table's words, empty when determined), words (the threshold with its interval, or why not), slope_determined,
    slope_note, slope_words."""
    x_lo, x_hi = tested
    th = stats.threshold(fit, crit.psi(fit.gamma, fit.lam))
    boot_th = np.array([stats.threshold(r, crit.psi(r.gamma, r.lam)) for r in fit.refits])
    boot_th = boot_th[~np.isnan(boot_th)]
    th_lo, th_hi = (np.percentile(boot_th, [2.5, 97.5]) if len(boot_th) else (math.nan, math.nan))
    inside = criteria.inside(th, x_lo, x_hi)
    determined = inside and not math.isnan(th_lo) and x_lo <= th_lo and th_hi <= x_hi
    side = "below" if not math.isnan(th) and th < x_lo else "above" if not math.isnan(th) else "beyond"
    refits = f"{len(boot_th)} refits" + (f" of {fit.n_boot} samples" if len(boot_th) != fit.n_boot else "")
    note = ("" if determined else
            f"not determined: its 95 % interval reaches beyond {criteria.range_words(x_lo, x_hi)} (parametric "
            f"bootstrap, {refits})" if inside else
            criteria.beyond_words(side, x_lo, x_hi, "an extrapolation, not an estimate"))
    words = f"{th:.3g} [{th_lo:.3g}, {th_hi:.3g}] (parametric bootstrap, {refits})" if determined else note
    b_lo, b_hi = fit.ci.get("beta", (math.nan, math.nan))
    b_bounds = fit.options.get("beta_bounds") or (0.0, math.inf)
    on_bound = "beta" in fit.on_bound
    slope_ok = not on_bound and not math.isnan(b_lo) and b_lo > b_bounds[0] * 1.001 + 1e-9 and \
        b_hi < b_bounds[1] * 0.999
    slope_note = ("" if slope_ok else "not determined: on a bound of its range" if on_bound else
                  "not determined: its 95 % interval reaches a bound of its range")
    return {"th": th, "low": th_lo, "high": th_hi, "determined": determined, "note": note, "words": words,
            "slope_determined": slope_ok, "slope_note": slope_note,
            "slope_words": (f"slope {fit.beta:.3g} [{b_lo:.3g}, {b_hi:.3g}]" if slope_ok else "slope " + slope_note)}


def side_bias_table(m, study, group_note):
    """The share of decisive answers choosing the left side: pooled (Wilson, descriptive) and its test against 0.5
    with participants as the unit."""
    d = m[m["chosen_side"].isin(["left", "right"])].copy()
    n, k = len(d), int((d["chosen_side"] == "left").sum())
    p, lo, hi = stats.wilson(k, n)
    row = {"answers": n, "chose_left": k, "share_left": p, "share_left_low": lo, "share_left_high": hi,
           "participants": d["participant"].nunique()}
    d["y"] = (d["chosen_side"] == "left").astype(float)
    row.update(study_tests.against_chance(d, 0.5))
    return Chart(f"{study}-side-bias", None, None, pd.DataFrame([row]),
                 [f"{group_note}: share of decisive answers choosing the left side, against 0.5 (no side bias), "
                  f"tested with participants as the unit"])


def _safe(text):
    return re.sub(r"[^A-Za-z0-9_-]", "_", str(text))


def analyse(df, study, codebook, out_dir, n_boot=200, seed=1, group="", part=""):
    """Charts for one study (the rows of one observer group; part: which protocol version or session number they
    are, "" for a study's first sessions of its only version); returns ([Chart], finding) - finding: one line for the
    report's summary. Blocks of different tasks (yes/no and rating, say) are analysed apart. Raises Skip when nothing
    can be analysed."""
    d = df[(df["study"] == study) & (df["practice"] != 1)].copy()
    if d.empty:
        raise Skip(f"{study}: no trials outside practice")
    # Blocks of one task but of two kinds - an adaptive procedure beside fixed levels - are two analyses too: the
    # fixed block's answers used to be dropped unsaid (a procedure's measure is `correct`, which they lack).
    adaptive = text(d["procedure_cell"]).ne("") if "procedure_cell" in d \
        else pd.Series(False, index=d.index)
    keys = d["task"].astype(str).where(~adaptive, d["task"].astype(str) + " adaptive")
    if adaptive.any() and not adaptive.all():
        keys = keys.where(adaptive, d["task"].astype(str) + " fixed levels")
    tasks = sorted(set(keys))
    if len(tasks) == 1:
        return _analyse(d, study, codebook, out_dir, n_boot, seed, group, "", part)
    charts, findings, skips = [], [], []
    for task in tasks:
        try:
            c, f = _analyse(d[keys == task], study, codebook, out_dir, n_boot, seed, group, task, part)
            charts += c
            findings.append(f)
        except Skip as e:
            skips.append(str(e))
            charts.append(Chart(f"{study}-{task}", None, None, None, [f"not analysed: {e}"]))
    if not findings:
        raise Skip("; ".join(skips))
    return charts, "; ".join(findings)


def _analyse(d, study, codebook, out_dir, n_boot, seed, group, task, part):
    kind = kind_of(d)
    m, guess, what = measured(d, kind)
    if m.empty:
        answered = int((d["status"] == "answered").sum())
        raise Skip(f"{study} ({KIND_TITLES[kind]}): no answers to analyse ({answered} answered of {len(d)}"
                   + ("; none chose a side between unequal radii" if kind == "pair" and answered else "") + ")")
    design = design_of(m, codebook)
    left_out = _left_out_words(d, m, kind)
    # The study's name is the record's (anything a person typed: its own stem, hashed when not plain, so "pilot 1" and
    # "pilot/1" get charts of their own); what follows is this script's words.
    slug = file_stem(study, 48) + _safe((f"-{task}" if task else "")
                                        + (f"-{part.replace(', ', '-').replace(' ', '')}" if part else "")
                                        + (f"-{group.split()[0]}" if group else ""))
    note = participants_note(m) + (f" ({group})" if group else "") + (f", {part}" if part else "")
    if "session_status" in m and (m["session_status"] == "running").any():
        n_running = m.loc[m["session_status"] == "running", "session_id"].nunique()
        note += f", incl. {n_running} unfinished session{'s' if n_running != 1 else ''} (partial data)"
    if not design.group:
        declared = _text_values(m, "group")
        if len(declared) == 1:  # a group study of which these rows hold one group: say which
            note += f", group {declared[0]}"
        charts, finding = _analyse_rows(m, kind, guess, what, design, codebook, study, out_dir, slug, note, n_boot,
                                        seed, left_out)
        return charts, finding + left_out
    # A between-subject group is a factor: each group analysed on its own, then the groups compared with
    # participants as the unit.
    charts, findings = [], []
    levels = _sorted_levels(list(m[design.group].astype(str).unique()))
    for level in levels:
        rows = m[m[design.group].astype(str) == level]
        c, f = _analyse_rows(rows, kind, guess, what, design_of(rows, codebook), codebook, study, out_dir,
                             f"{slug}-group-{file_stem(level, 32)}", f"group {level}: {participants_note(rows)}"
                             f"{note[len(participants_note(m)):]}", n_boot, seed,
                             _left_out_words(d[d[design.group].astype(str) == level], rows, kind))
        charts += c
        findings.append(f"group {level}: {f}")
    c, f = group_section(m, kind, what, design, codebook, study, out_dir, slug, note)
    return charts + c, "; ".join(findings + [f]) + left_out


def more_blurred_words(m, factors):
    """What "chose the more blurred side" means in these rows, per pair of sources compared: which source was the more
    blurred one (by the radii shown, r_left_arcmin / r_right_arcmin), and where that changes between the conditions
    (the crossing of factors) - there the same share means choosing a different source. "" without the columns."""
    need = {"left_source", "right_source", "r_left_arcmin", "r_right_arcmin"}
    if not need <= set(m.columns) or m.empty:
        return ""
    left, right = text(m["left_source"]), text(m["right_source"])
    r_l, r_r = _num(m["r_left_arcmin"]), _num(m["r_right_arcmin"])
    blurrier = np.where(r_l > r_r, left, np.where(r_r > r_l, right, "neither"))
    pair = pd.Series([" and ".join(sorted(p)) for p in zip(left, right)], index=m.index)
    condition = (m[list(factors)].astype(str).apply(lambda r: ", ".join(f"{f} {v}" for f, v in r.items()), axis=1)
                 if factors else pd.Series([""] * len(m), index=m.index))
    words = []
    for name, rows in pd.DataFrame({"pair": pair, "blurrier": blurrier, "condition": condition}).groupby("pair"):
        sources = rows.groupby("condition", sort=False)["blurrier"].agg(lambda v: " or ".join(sorted(set(v))))
        if sources.nunique() == 1:
            words.append(f"between {name}, the more blurred side showed {sources.iloc[0]}" +
                         (" in every condition" if factors else ""))
        else:
            where = "; ".join(f"{src} at {', '.join(c for c in sources.index[sources == src])}"
                              for src in dict.fromkeys(sources))
            words.append(f"between {name}, the more blurred side showed {where}: the share means choosing a "
                         f"different source where that changes")
    return "; " + "; ".join(words) if words else ""


def _left_out_words(d, m, kind):
    """The answered rows a pair's shares leave out, said (", 14 of 60 answers can't tell, left out of the shares"):
    a "can't tell" chooses no side, and a pair of equal radii has no more blurred side."""
    if kind != "pair":
        return ""
    answered = d[d["status"] == "answered"]
    cant = int((answered["chosen_side"] == "cant_tell").sum()) if "chosen_side" in answered else 0
    equal = len(answered) - cant - len(m)
    parts = ([f"{cant} of {len(answered)} answers can't tell"] if cant else []) + \
            ([f"{equal} between equal radii (no more blurred side)"] if equal > 0 else [])
    return (", " + " and ".join(parts) + ", left out of the shares") if parts else ""


def _text_values(m, column):
    """The distinct non-empty values of a column, as text ([] without the column)."""
    if column not in m:
        return []
    return sorted({v for v in text(m[column]) if v})


def group_section(m, kind, what, design, codebook, study, out_dir, slug, note):
    """The group effect with participants as the unit: a chart of every participant's share (or mean) per group
    with the groups' means, Welch's t and Mann-Whitney's U (study_tests.group_effect), for a 0/1 measure the
    logistic models across participants with the group as a fixed effect, and the group x within-factor interaction
    with the groups' difference per level (groups.charts). Returns ([Chart], finding)."""
    group = design.group
    if kind == "procedure":
        words = ("groups not compared on the share correct: an adaptive procedure sets it; compare the groups' "
                 "thresholds in the tracks tables")
        return [Chart(f"{slug}-per-group", None, None, None, [words])], words
    column = "value" if kind in ("rating", "adjustment") else "y"
    table, notes, words = study_tests.group_effect(m, group, column)
    pp = study_tests.per_participant(m, column, by=[group])
    fig, ax = plt.subplots(figsize=(max(4.5, 1.2 * len(table) + 2.5), 3.6))
    x = np.arange(len(table))
    rng = np.random.default_rng(1)
    for xi, level in zip(x, table["group"]):
        v = pp.loc[pp[group].astype(str) == level, "mean"]
        ax.plot(xi + rng.uniform(-0.1, 0.1, len(v)), v, "o", ms=4, color="#999999", alpha=0.8)
    ax.errorbar(x, table["participant_mean"], yerr=error_bars(table["participant_mean"], table["ci_low"],
                                                               table["ci_high"]),
                fmt="s", color="#0072B2", ecolor="#0072B2", ms=7)
    ax.set_xticks(x)
    ax.set_xticklabels([f"group {g}" for g in table["group"]])
    ax.set_xlim(-0.6, len(table) - 0.4)
    ax.set_ylabel(f"{'mean ' + what if column == 'value' else 'share: ' + what}\nper participant")
    if column == "y":
        ax.set_ylim(-0.03, 1.03)
    ax.set_title(f"{study}: {what} per group (grey: each participant)\n{note}", loc="left")
    png, svg = save(fig, out_dir, f"{slug}-per-group")
    notes = notes + ["blue: the mean of the participants' values with its t 95 % interval (none with fewer than 3 participants)"]
    charts = [Chart(f"{slug}-per-group", png, svg, table, notes)]
    if column == "y":
        shared = [f for f in design.factors if f != group]
        charts.append(models(m, shared + [group], f"{slug}-groups", note, what))
    # What a design that crosses a group with a within factor asks: does the groups' difference change across the
    # factor's levels, and at which levels do they differ (groups.py).
    c, crossed = groups.charts(m, kind, design, slug, note, what)
    charts += c
    return charts, f"group effect: {words}" + (f"; {crossed}" if crossed else "")


def _analyse_rows(m, kind, guess, what, design, codebook, study, out_dir, slug, note, n_boot, seed, left_out=""):
    """The charts of one set of rows that the design lets be pooled (one group, one version, one session number)."""
    factors = list(design.factors)
    charts = []
    if kind in ("rating", "adjustment"):
        for f in factors:
            charts.append(value_chart(m, f, what, study, out_dir, f"{slug}-{what.replace(' ', '-')}-per-{f}", note,
                                      [g for g in factors if g != f]))
        people = study_tests.per_participant(m, "value")["mean"]
        finding = (f"{KIND_TITLES[kind]}: mean {what} {m['value'].mean():.3g} (median {m['value'].median():.3g}) over "
                   f"{len(m)} answers" + (f", {len(people)} participants' means from {people.min():.3g} to "
                                          f"{people.max():.3g}" if len(people) > 1 else "") +
                   (f"; per {', '.join(factors)} in the charts" if factors else ""))
        if not factors:
            charts.append(Chart(f"{slug}-{what.replace(' ', '-')}", None, None,
                                m["value"].describe().to_frame().T.reset_index(drop=True), [note]))
        return charts, finding
    # An adaptive procedure chooses each level from the answers so far: its share correct is what the procedure
    # aims at, so testing it against chance says nothing. Its thresholds are its result.
    chance = None if kind == "procedure" else guess
    table = condition_table(m, factors, chance)
    charts.append(Chart(f"{slug}-conditions", None, None, table,
                        [f"{note}{left_out}: {what} per condition (the crossing of {', '.join(factors) or 'no factors'}); "
                         "Wilson 95 % intervals of the answers pooled (a description)" +
                         ("; against chance with participants as the unit (test column), Holm-adjusted over the "
                          "conditions" if chance is not None else
                          NO_CHANCE_WHY.get(kind, "; no test against chance: the design defines no chance "
                                                  "level for it"))] +
                        [w for w in [study_tests.holm_floor_words(table, chance, m["participant"].nunique()),
                                     crossed.missing_words(table, factors)] if w]))
    if kind != "procedure":
        apart = comparing_factors(m, factors)  # levels that ask different questions are summarised apart
        for f in factors:
            # A bar pooling the levels of a factor that changes which sources are compared averages the answers to
            # different questions: drawn (a description), not tested against chance.
            mixed = [g for g in apart if g != f]
            charts.append(factor_chart(m, f, None if mixed else chance, what, study, out_dir, f"{slug}-per-{f}",
                                       note, [g for g in factors if g != f], mixed))
        finding = f"{KIND_TITLES[kind]}: " + (study_tests.summary_by_level(m, chance, what, apart) if apart else
                                              study_tests.summary_words(m, chance, what))
        if kind == "pair":
            finding += more_blurred_words(m, factors)
    else:
        finding = (f"{KIND_TITLES[kind]}: {participants_note(m)}, {len(m)} answers (share correct set by the "
                   f"procedure, not tested)")
    if kind in ("procedure", "odd"):
        c, words = psychometric_cells(m, kind, guess, what, design, study, out_dir, slug, note, n_boot, seed)
        charts += c
        if kind == "procedure":
            # The procedure's own result first (each participant's track), then the pooled fit at the same criterion.
            m["level"] = _num(m["level"])
            track_charts = tracks.charts(m, study, out_dir, slug, note)
            summary = [t.table for t in track_charts if t.name == f"{slug}-thresholds"]
            if summary:
                finding += "; tracks: " + tracks.summary_words(summary[0])
            # The pooled fit mixes participants of different thresholds (and a track's levels depend on its own
            # answers): a description in its chart, not a result beside the per-participant thresholds.
            words = ""
        finding += "; " + words if words else ""
    else:
        # Why there is none, in the words of what was asked (a pair's preference, a yes/no question, ...).
        asked = ("the question has no correct answer (a preference: which fits the scene), so a guess rate of 0.5 "
                 "would be a claim the design does not make; the shares of choosing the more blurred side per "
                 "condition are in the tables") if kind == "pair" else \
            (f"a {KIND_TITLES[kind]} answer has no correct one and no guess rate; the {what} per condition is in "
             "the tables")
        charts.append(Chart(f"{slug}-psychometric", None, None, None, ["no psychometric function: " + asked]))
    if kind == "procedure":
        charts += track_charts
    else:
        charts += within_models(m, table, factors, chance, what, study, out_dir, slug, note)
    if "chosen_side" in m and m["chosen_side"].isin(["left", "right"]).any():
        charts.append(side_bias_table(m, slug, note))
    return charts, finding


def psychometric_cells(m, kind, guess, what, design, study, out_dir, slug, note, n_boot, seed):
    """A psychometric function per procedure cell (never pooled across cells; labelled by the cell's levels), over
    the procedure's level; an odd one out's over the blur difference on screen. Returns ([Chart], words)."""
    m = m.copy()
    if kind == "procedure":
        xcol, xlabel = "level", axis_label("level shown", level_unit(m))
        m["level"] = _num(m["level"])
        cells = design.cell_of(m)
    else:
        m["difference"] = (_num(m["r_right_arcmin"]) - _num(m["r_left_arcmin"])).abs()
        xcol, xlabel = "difference", "blur difference between the two, |r_right - r_left| (arcmin)"
        cells = pd.Series([""] * len(m), index=m.index)
    names = list(dict.fromkeys(cells))
    stems = distinct_stems(names)  # readable ("edge_3"); hashed only where two cells' plain forms meet
    charts, words = [], []
    for cell in _sorted_levels(names) if all(names) else names:
        rows = m[cells == cell]
        name = f"{slug}-psychometric" + (f"-{stems[cell]}" if len(names) > 1 else "")
        # A procedure cell's threshold is read at its procedure's own criterion over what it could show, so the
        # fit and the tracks give one quantity (criteria.py).
        params = tracks.parameters(rows) if kind == "procedure" else None
        crit = criteria.criterion((params or {}).get("procedure", ""), params, guess)
        try:
            dx = rows[xcol].dropna().to_numpy(float)
            chart, said = psychometric_chart(
                rows, xcol, xlabel, guess, study, out_dir, name, note, n_boot, seed, what, cell=cell, crit=crit,
                tested=criteria.tested_range(params, dx) if len(dx) else None)
            charts.append(chart)
            # The threshold's unit beside it in the table: the procedure's variable's (common.level_unit).
            unit_words = (level_unit(rows) or UNKNOWN_UNIT) if kind == "procedure" else "arcmin"
            chart.table.insert(chart.table.columns.get_loc("threshold") + 1, "unit", unit_words)
            where = f"{tracks.cell_label(rows) if kind == 'procedure' else cell}: " if cell else ""
            # Said as the fitted function gives it (its lapse lowers QUEST+'s 81.6 %), with the level's unit.
            determined = not math.isnan(chart.table["threshold"].iloc[0])
            words.append(f"{where}threshold at {chart.table['criterion_fitted'].iloc[0]} " +
                         (said.replace(" [", f" {unit_words} [", 1) if determined else said))
        except Skip as e:
            charts.append(Chart(name, None, None, None, [str(e)]))
        except ValueError as e:
            charts.append(Chart(name, None, None, None, [f"no psychometric fit{' in ' + cell if cell else ''}: {e}"]))
    return charts, "; ".join(words)
