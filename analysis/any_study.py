"""Any study, analysed from what its trials declare - not from its name.

What a study measures follows from its rows of trials.csv (their task and the columns the export filled):
  pair        forced choice between two sides (side by side or two intervals): did the participant choose the side
              that showed the larger blur radius (chose_more_blurred)? chance 0.5
  odd         odd one out of n intervals: was the odd interval named (correct)? chance 1/n
  procedure   an adaptive procedure (staircase, QUEST+): correct at the level shown; chance 0.5 (1/n odd one out)
  yes_no      one object: the share of "yes"
  rating      one object: the rating (1..n)
  adjustment  the level accepted
The design's factors are the columns the export's codebook.csv calls "a level of the protocol's design" (constant
ones left out). Per study: a table per condition (the crossing of the factors) with Wilson 95 % intervals and exact
binomial tests against chance (Holm-adjusted), a chart per factor, a psychometric function over the stimulus variable
(the level of a procedure, else the blur difference on screen in arcmin) with guess and lapse rates and a bootstrap
band, logistic models across participants (a GLMM where there are three or more), the level tracks of adaptive
procedures with a threshold and interval per track (tracks.py), and the side bias. People and simulated observers are
analysed apart (report.py --pool-simulated pools them). A study that cannot be analysed raises Skip saying why.
"""
import math
import os
import re

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

import stats
import tracks
from common import Chart, Skip, error_bars, p_text, participants_note, save, stars

DESIGN_MEANING = "a level of the protocol's design"
# Columns that identify a level rather than vary the stimulus (a pattern's id beside the pattern itself).
NOT_FACTORS = {"id"}
KIND_TITLES = {"pair": "forced choice between two", "odd": "odd one out",
               "procedure": "adaptive procedure", "yes_no": "yes / no", "rating": "rating",
               "adjustment": "method of adjustment"}


def load_codebook(trials_path):
    """codebook.csv beside trials.csv as {column: meaning}; {} when there is none."""
    path = os.path.join(os.path.dirname(os.path.abspath(trials_path)), "codebook.csv")
    if not os.path.isfile(path):
        return {}
    book = pd.read_csv(path, dtype=str, keep_default_na=False)
    book = book[book["table"] == "trials.csv"]
    return dict(zip(book["column"], book["meaning"]))


def design_factors(d, codebook):
    """The design's factors that vary within these rows, in column order."""
    out = []
    for column in d.columns:
        if column in NOT_FACTORS or not codebook.get(column, "").startswith(DESIGN_MEANING):
            continue
        values = d[column].astype(str).replace("nan", "")
        if values.replace("", np.nan).dropna().nunique() > 1:
            out.append(column)
    return out


def kind_of(d):
    tasks = set(d["task"])
    for task in ("adjustment", "rating", "yes_no"):
        if task in tasks:
            return task
    if "odd_interval" in d and d["odd_interval"].astype(str).str.strip().replace("nan", "").ne("").any():
        return "procedure" if _has(d, "procedure_cell") else "odd"
    return "procedure" if _has(d, "procedure_cell") else "pair"


def _has(d, column):
    return column in d and d[column].astype(str).str.strip().replace("nan", "").ne("").any()


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
    text = str(value)
    return text[:-2] if text.endswith(".0") else text


def condition_table(m, factors, chance):
    """One row per condition: n, k, share with its Wilson interval, and (with a chance level) the exact binomial test
    against it, Holm-adjusted over the conditions."""
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
            row["p_binomial"] = stats.binom_p(k, n, chance)
        rows.append(row)
    t = pd.DataFrame(rows)
    if chance is not None and not t.empty:
        t["p_holm"] = stats.holm(list(t["p_binomial"]))
    return t


def _sorted_levels(values):
    numeric = pd.to_numeric(pd.Series(values), errors="coerce")
    if numeric.notna().all():
        return [values[i] for i in np.argsort(numeric.to_numpy(), kind="stable")]
    return sorted(values)


def factor_chart(m, factor, chance, what, study, out_dir, name, group_note):
    t = condition_table(m, [factor], chance)
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
        ax.legend(loc="lower right")
    ax.set_xticks(x)
    ax.set_xticklabels(list(t[factor]))
    ax.set_xlabel(factor)
    ax.set_ylim(0, 1.12)
    ax.set_ylabel(f"share: {what}")
    ax.grid(axis="x", visible=False)
    ax.set_title(f"{study}: {what} per {factor}\n{group_note}, {int(t['n'].sum())} answers", loc="left")
    png, svg = save(fig, out_dir, name)
    notes = ["bars: share of answers with Wilson 95 % intervals" +
             ("; * p < 0.05, ** < 0.01, *** < 0.001: exact binomial test against chance, Holm-adjusted over the "
              "chart's bars" if chance is not None else "")]
    return Chart(name, png, svg, t, notes)


def value_chart(m, factor, what, study, out_dir, name, group_note):
    """Rating or adjusted level per level of a factor: mean with a t 95 % interval, every answer as a dot."""
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
    ax.set_xlabel(factor)
    ax.set_ylabel(what)
    ax.set_title(f"{study}: {what} per {factor}\n{group_note}, {int(t['n'].sum())} answers", loc="left")
    png, svg = save(fig, out_dir, name)
    return Chart(name, png, svg, t, ["points: every answer; blue: the mean with its t 95 % interval"])


def models(m, factors, study, group_note, what):
    """Logistic models across participants of the 0/1 measure against the factors, terms in words, and which to
    trust where the GLM and the GLMM disagree."""
    d = m.copy()
    for f in factors:
        d[f] = d[f].map(_label)
    rhs = " + ".join(f"C({f}, levels={_sorted_levels(list(d[f].unique()))!r})" for f in factors) if factors else "1"
    table, notes = stats.observer_models(d, "y", rhs)
    if table.empty:
        return Chart(f"{study}-models", None, None, table, notes)
    notes.insert(0, f"{group_note}: logistic models of '{what}' across participants; estimates in log-odds, each "
                    f"term against the baseline it names")
    return Chart(f"{study}-models", None, None, table, notes)


def psychometric_chart(m, xcol, xlabel, chance, study, out_dir, name, group_note, n_boot, seed, what):
    d = m.dropna(subset=[xcol])
    x, k = d[xcol].to_numpy(float), d["y"].to_numpy(float)
    if len(np.unique(x)) < 3 or len(x) < 20:
        raise Skip(f"{study}: psychometric function needs >= 3 stimulus levels and >= 20 answers "
                   f"(has {len(np.unique(x))} levels, {len(x)} answers)")
    fit = stats.fit_psychometric(x, k, None, kind="weibull", gamma=chance, lam=(0.0, 0.1))
    grid, lo, hi = stats.bootstrap(x, k, np.ones_like(k), fit, n_boot=n_boot, seed=seed)
    p_mid = chance + (1 - chance) / 2
    th = stats.threshold(fit, p_mid)
    boot_th = []
    rng = np.random.default_rng(seed)
    for _ in range(max(50, n_boot // 2)):
        kb = rng.binomial(1, np.clip(fit(x), 0, 1)).astype(float)
        try:
            boot_th.append(stats.threshold(stats.fit_psychometric(x, kb, None, kind="weibull", gamma=chance,
                                                                  lam=(0.0, 0.1), starts=[(fit.alpha, fit.beta)]),
                                           p_mid))
        except ValueError:
            pass
    boot_th = np.array([b for b in boot_th if not math.isnan(b)])
    th_lo, th_hi = (np.percentile(boot_th, [2.5, 97.5]) if len(boot_th) else (math.nan, math.nan))
    levels = pd.DataFrame({"x": x, "y": k}).groupby("x")["y"].agg(["sum", "count"]).reset_index()
    fig, ax = plt.subplots(figsize=(5.5, 3.8))
    ax.fill_between(grid, lo, hi, color="#0072B2", alpha=0.2, lw=0, label="95 % bootstrap band")
    ax.plot(grid, fit(grid), color="#0072B2", label="Weibull fit")
    sizes = 12 + 60 * levels["count"] / levels["count"].max()
    ax.scatter(levels["x"], levels["sum"] / levels["count"], s=sizes, color="#333333", zorder=3,
               label="share per level (size: answers)")
    ax.axhline(chance, color="#999999", ls="--", lw=1)
    if not math.isnan(th):
        ax.axvline(th, color="#D55E00", lw=1, ls=":", label=f"threshold ({p_mid:.0%}): {th:.3g}")
    ax.set_xlabel(xlabel)
    ax.set_ylabel(f"share: {what}")
    ax.set_ylim(min(chance, 0.4) - 0.05, 1.05)
    ax.legend(loc="lower right", fontsize=8)
    ax.set_title(f"{study}: psychometric function\n{group_note}, {len(x)} answers", loc="left")
    png, svg = save(fig, out_dir, name)
    t = pd.DataFrame([{"threshold": th, "threshold_low": th_lo, "threshold_high": th_hi, "criterion": p_mid,
                       "alpha": fit.alpha, "beta_slope": fit.beta, "beta_low": fit.ci.get("beta", (math.nan,))[0],
                       "beta_high": fit.ci.get("beta", (math.nan, math.nan))[1], "guess": fit.gamma,
                       "lapse": fit.lam, "answers": len(x)}])
    inside = not math.isnan(th) and x.min() <= th <= x.max()
    notes = [f"Weibull with the guess rate fixed at chance ({chance:.3g}) and a lapse rate fitted in [0, 0.1]; "
             f"threshold = the stimulus at {p_mid:.0%}: " +
             (f"{th:.3g} [{th_lo:.3g}, {th_hi:.3g}] (parametric bootstrap, {n_boot} samples)" if inside else
              f"beyond the tested range {x.min():.3g} to {x.max():.3g} (an extrapolation, not an estimate)") +
             f"; slope {fit.beta:.3g}"]
    if fit.on_bound:
        notes.append("on a bound of its range: " + ", ".join(f"{k} ({v[1]})" for k, v in fit.on_bound.items()))
    return Chart(name, png, svg, t, notes), ((th, th_lo, th_hi, fit.beta) if inside else
                                             (math.nan, x.min(), x.max(), fit.beta))


def side_bias_table(m, study, group_note):
    d = m[m["chosen_side"].isin(["left", "right"])]
    n, k = len(d), int((d["chosen_side"] == "left").sum())
    p, lo, hi = stats.wilson(k, n)
    t = pd.DataFrame([{"answers": n, "chose_left": k, "share_left": p, "share_left_low": lo, "share_left_high": hi,
                       "p_binomial": stats.binom_p(k, n, 0.5)}])
    return Chart(f"{study}-side-bias", None, None, t,
                 [f"{group_note}: share of decisive answers choosing the left side, against 0.5 (no side bias)"])


def analyse(df, study, codebook, out_dir, n_boot=200, seed=1, group=""):
    """Charts for one study (the rows of one observer group); returns ([Chart], finding) - finding: one line for the
    report's summary. Blocks of different tasks (yes/no and rating, say) are analysed apart. Raises Skip when nothing
    can be analysed."""
    d = df[(df["study"] == study) & (df["practice"] != 1)].copy()
    if d.empty:
        raise Skip(f"{study}: no trials outside practice")
    tasks = sorted(set(d["task"]))
    if len(tasks) == 1:
        return _analyse(d, study, codebook, out_dir, n_boot, seed, group, "")
    charts, findings, skips = [], [], []
    for task in tasks:
        try:
            c, f = _analyse(d[d["task"] == task], study, codebook, out_dir, n_boot, seed, group, task)
            charts += c
            findings.append(f)
        except Skip as e:
            skips.append(str(e))
            charts.append(Chart(f"{study}-{task}", None, None, None, [f"not analysed: {e}"]))
    if not findings:
        raise Skip("; ".join(skips))
    return charts, "; ".join(findings)


def _analyse(d, study, codebook, out_dir, n_boot, seed, group, part):
    kind = kind_of(d)
    m, chance, what = measured(d, kind)
    if m.empty:
        answered = int((d["status"] == "answered").sum())
        raise Skip(f"{study} ({KIND_TITLES[kind]}): no answers to analyse ({answered} answered of {len(d)}"
                   + ("; none chose a side between unequal radii" if kind == "pair" and answered else "") + ")")
    factors = design_factors(m, codebook)
    slug = re.sub(r"[^A-Za-z0-9_-]", "_", study + (f"-{part}" if part else "") +
                  (f"-{group.split()[0]}" if group else ""))
    group_note = participants_note(m) + (f" ({group})" if group else "")
    charts = []
    finding = ""
    if kind in ("rating", "adjustment"):
        for f in factors or []:
            charts.append(value_chart(m, f, what, study, out_dir, f"{slug}-{what.replace(' ', '-')}-per-{f}", group_note))
        summary = m["value"].describe()
        finding = f"{KIND_TITLES[kind]}: mean {what} {summary['mean']:.3g} (median {m['value'].median():.3g}) over " \
                  f"{len(m)} answers" + (f"; per {', '.join(factors)} in the charts" if factors else "")
        if not factors:
            charts.append(Chart(f"{slug}-{what.replace(' ', '-')}", None, None,
                                m["value"].describe().to_frame().T.reset_index(drop=True), [group_note]))
        return charts, finding
    table = condition_table(m, factors, chance)
    charts.append(Chart(f"{slug}-conditions", None, None, table,
                        [f"{group_note}: {what} per condition (the crossing of {', '.join(factors) or 'no factors'}); "
                         "Wilson 95 % intervals" + ("; exact binomial test against chance, Holm-adjusted over the "
                                                    "conditions" if chance is not None else "")]))
    for f in factors:
        charts.append(factor_chart(m, f, chance, what, study, out_dir, f"{slug}-per-{f}", group_note))
    k, n = int(m["y"].sum()), len(m)
    p, lo, hi = stats.wilson(k, n)
    finding = f"{KIND_TITLES[kind]}: {what} {p:.2f} [{lo:.2f}, {hi:.2f}] of {n} answers"
    if chance is not None:
        finding += f" (chance {chance:.2g}, {p_text(stats.binom_p(k, n, chance))})"
    # The psychometric function over the stimulus variable: a procedure's level, else the blur difference on screen.
    if chance is not None:
        if kind == "procedure":
            xcol, xlabel = "level", "level shown (the procedure's variable)"
            m["level"] = _num(m["level"])
        else:
            m["difference"] = (_num(m["r_right_arcmin"]) - _num(m["r_left_arcmin"])).abs()
            xcol, xlabel = "difference", "blur difference between the two, |r_right - r_left| (arcmin)"
        try:
            chart, (th, th_lo, th_hi, slope) = psychometric_chart(m, xcol, xlabel, chance, study, out_dir,
                                                                   f"{slug}-psychometric", group_note, n_boot, seed,
                                                                   what)
            charts.append(chart)
            finding += f"; threshold {th:.3g} [{th_lo:.3g}, {th_hi:.3g}]" if not math.isnan(th) else \
                f"; threshold beyond the tested range {th_lo:.3g} to {th_hi:.3g}"
        except Skip as e:
            charts.append(Chart(f"{slug}-psychometric", None, None, None, [str(e)]))
        except ValueError as e:
            charts.append(Chart(f"{slug}-psychometric", None, None, None, [f"no psychometric fit: {e}"]))
    if kind == "procedure":
        m["level"] = _num(m["level"])
        charts += tracks.charts(m, study, out_dir, slug, group_note)
    if kind in ("pair", "procedure", "odd"):
        charts.append(models(m, factors, slug, group_note, what))
    if "chosen_side" in m and m["chosen_side"].isin(["left", "right"]).any():
        charts.append(side_bias_table(m, slug, group_note))
    return charts, finding
