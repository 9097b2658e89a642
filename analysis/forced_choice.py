"""Forced-choice studies (tests 1-3): answers per edge, per pattern and per section, and a psychometric function.

Figures (thesis chapter 5):
  test 1 per edge             Fig. 5.2   measured / estimated / can't tell at each of the 11 edges
  tests 2, 3 per pattern      Fig. 5.9, 5.13   task 1: the two sources of each of the 6 patterns, and can't tell
  tests 2, 3 per section      Fig. 5.10-5.12   task 2: patterns 2, 4, 6 over sections 1-10
  psychometric                share choosing the more-blurred stimulus against |r_left - r_right|, pooled
  side bias                   share of decisive answers choosing the LEFT side per study, pooled and per participant
                              (the counterbalancing check: a side preference cancels out of the source comparisons)

Every bar is a share of the answered trials with its Wilson 95 % interval. The test asks whether, among the answers
that picked a side (not can't tell), the first source of the pair was chosen more or less often than half the time,
with participants as the unit (study_tests.against_chance: the exact sign-flip permutation test of the participants'
shares around 0.5; an exact binomial only where there is one participant); p-values are two-sided and Holm-adjusted
over the cells of one chart, and the stars show the adjusted p of that one test.
"""
import math

import numpy as np
import pandas as pd

import matplotlib.pyplot as plt

import across_observers
import stats
import study_tests
from common import (Chart, Skip, SOURCE_COLORS, SOURCE_LABELS, STUDY_TEST1, STUDY_TEST2, STUDY_TEST3, STUDY_TITLES,
                    FORCED_CHOICE_STUDIES, error_bars, forced_choice, p_text, participants_note, save, stars,
                    study_rows, wilson_columns)

SECTION_PATTERNS = (2, 4, 6)


# --------------------------------------------------------------------------------------------------------------------
# Counting


def _prepare(df, study):
    """Non-practice forced-choice rows of one study; Skip when there are none or none answered."""
    d = study_rows(df, study)
    title = STUDY_TITLES[study]
    if d.empty:
        raise Skip(f"{title}: no trials in trials.csv")
    d = forced_choice(d)
    if not d["answered"].any():
        raise Skip(f"{title}: 0 of {len(d)} trials answered")
    return d


def _notes(d):
    notes = [f"{participants_note(d)}; {int(d['answered'].sum())} of {len(d)} planned trials answered "
             f"(practice excluded)"]
    if d["invalid"].any():
        notes.append(f"{int(d['invalid'].sum())} answers other than left/right/cant_tell ignored")
    return notes


def count_table(d, key):
    """Per value of `key`: planned, answered, answers for the pair's first and second source and can't tell, their
    shares of the answered trials with Wilson 95 % intervals (descriptive: answers pooled), and the test of first vs
    second with participants as the unit (study_tests.against_chance on each participant's share of the first source
    among their decisive answers: the exact sign-flip permutation test across participants; the exact binomial of the
    answers only where the chart has one participant), Holm-adjusted over the chart's cells."""
    rows = []
    people = d["participant"].nunique()
    for value, g in d.groupby(key, sort=True):
        a = g[g["answered"]]
        first = g["first"].dropna().iloc[0] if g["first"].notna().any() else ""
        second = g["second"].dropna().iloc[0] if g["second"].notna().any() else ""
        n_first = int((a["chosen_source"] == first).sum())
        n_second = int((a["chosen_source"] == second).sum())
        row = {key: value, "first": first, "second": second, "planned": len(g), "answered": len(a),
               "n_first": n_first, "n_second": n_second, "n_cant_tell": int((a["chosen_source"] == "cant_tell").sum()),
               "observers": g["participant"].nunique()}
        dec = a[a["chosen_source"].isin([first, second])]
        if dec.empty:
            row.update(test="none: no decisive answer", p=math.nan)
        else:
            row.update(study_tests.against_chance(dec.assign(y=(dec["chosen_source"] == first).astype(float)), 0.5,
                                                  people=people))
        rows.append(row)
    t = pd.DataFrame(rows)
    for what in ("first", "second", "cant_tell"):
        wilson_columns(t, f"n_{what}", "answered", f"share_{what}")
    t["decisive"] = t["n_first"] + t["n_second"]
    t["share_first_of_decisive"] = [k / n if n else math.nan for k, n in zip(t["n_first"], t["decisive"])]
    t["p_holm"] = stats.holm(t["p"])
    return t


def _bars(ax, t, key, xlabels):
    """Three bars per cell (first source, second source, can't tell), coloured by source, with Wilson intervals."""
    x = np.arange(len(t))
    width = 0.26
    handles = {}
    for j, what in enumerate(("first", "second", "cant_tell")):
        p, lo, hi = t[f"share_{what}"], t[f"share_{what}_low"], t[f"share_{what}_high"]
        sources = t[what] if what != "cant_tell" else ["cant_tell"] * len(t)
        colors = [SOURCE_COLORS.get(s, "#555555") for s in sources]
        ax.bar(x + (j - 1) * width, p, width, color=colors, edgecolor="white", linewidth=0.5)
        ax.errorbar(x + (j - 1) * width, p, yerr=error_bars(p, lo, hi), fmt="none", ecolor="#333333", lw=0.9)
        for s in sources:
            handles.setdefault(s, plt.Rectangle((0, 0), 1, 1, color=SOURCE_COLORS.get(s, "#555555")))
    # Holm-adjusted significance of first vs second above each cell.
    for xi, (p_adj, hi1, hi2) in enumerate(zip(t["p_holm"], t["share_first_high"], t["share_second_high"])):
        mark = stars(p_adj)
        if mark:
            ax.text(xi, np.nanmax([hi1, hi2]) + 0.03, mark, ha="center", va="bottom", fontsize=10)
    ax.set_xticks(x)
    ax.set_xticklabels(xlabels)
    ax.set_ylim(0, 1.12)
    ax.set_yticks(np.linspace(0, 1, 6))
    ax.set_ylabel("share of answers")
    ax.grid(axis="x", visible=False)
    order = [s for s in ("measured", "estimated", "fitted", "none", "cant_tell") if s in handles]
    order += [s for s in handles if s not in order]
    # Outside the axes, so it never covers a bar or a significance mark.
    ax.legend([handles[s] for s in order], [SOURCE_LABELS.get(s, s) for s in order], title="answer",
              loc="upper left", bbox_to_anchor=(1.01, 1.0), handlelength=1.2, alignment="left")


def _caption_note():
    return ("bars: share of answered trials with Wilson 95 % intervals (answers pooled, descriptive); * p < 0.05, "
            "** p < 0.01, *** p < 0.001: first vs second source with participants as the unit - each participant's "
            "share of the first source among their decisive answers (not can't tell), the exact sign-flip permutation "
            "test of those shares around 0.5 (3 or more participants; with 3-5 no p can reach 0.05), or with one "
            "participant the exact binomial test of their answers (said in the column test); Holm-adjusted over the "
            "chart's cells (p_holm: the p the stars show)")


def _model(d, formula_rhs, title, extra=None):
    """Logistic models across observers of 'chose the first source' among decisive answers (see across_observers.observer_models)."""
    dec = d[d["answered"] & d["decisive"]].copy()
    dec["chose_first"] = (dec["chosen_source"] == dec["first"]).astype(float)
    study = str(dec["study"].iloc[0]) if "study" in dec and len(dec) else ""
    table, notes = across_observers.observer_models(dec, "chose_first", formula_rhs, study=study)
    if extra is not None and not table.empty:  # e.g. the pattern, named in the model column (the columns are fixed)
        table["model"] = ", ".join(f"{k} {v}" for k, v in extra.items()) + ": " + table["model"]
    return table, [f"{title}: {n}" for n in notes]


# --------------------------------------------------------------------------------------------------------------------
# Charts


def test1_per_edge(df, out_dir):
    """Fig. 5.2: test 1 answers per edge, and a model of 'chose measured' against edge across observers."""
    d = _prepare(df, STUDY_TEST1)
    d["first"], d["second"] = "measured", "estimated"
    d = d[d["edge"].notna()]
    t = count_table(d, "edge")
    t["edge"] = t["edge"].astype(int)
    fig, ax = plt.subplots(figsize=(9, 4.2))
    # Each edge with the grids' depth there (trials.csv's u_left_mm, the calibration's geometry), where recorded.
    depth = pd.to_numeric(d["u_left_mm"], errors="coerce").groupby(d["edge"]).mean() if "u_left_mm" in d else None
    _bars(ax, t, "edge", [f"{e}\n{depth[e]:.0f} mm" if depth is not None and e in depth and np.isfinite(depth[e])
                          else str(e) for e in t["edge"]])
    ax.set_xlabel("edge of the board (1 = nearest, in focus; 11 = farthest)" +
                  (" and the grids' depth u (mm)" if depth is not None and depth.notna().any() else ""))
    ax.set_title(f"Test 1, static grids: which grid fits the scene? ({participants_note(d)}, "
                 f"{int(t['answered'].sum())} answers)", loc="left")
    png, svg = save(fig, out_dir, "test1-per-edge")
    notes = _notes(d) + [_caption_note()]
    # Edge centred at 6 so the intercept is the preference at the middle edge.
    d["edge_c"] = d["edge"] - 6
    model, model_notes = _model(d, "edge_c", "test 1")
    charts = [Chart("test1-per-edge", png, svg, t, notes)]
    charts.append(Chart("test1-model", None, None, model,
                        ["log-odds of choosing measured among decisive answers = baseline + (per edge) x (edge - 6); "
                         "the baseline is the log-odds at edge 6 (0 = no preference), 'per edge' the change from one "
                         "edge to the next"] + model_notes))
    return charts


def _designed_pair(d):
    """Sets first/second for pattern rows: the designed pair, the on-screen sides with their swap undone."""
    swapped = d["swapped"] == 1
    d["first"] = np.where(swapped, d["right"], d["left"])
    d["second"] = np.where(swapped, d["left"], d["right"])
    return d


def _pattern_frame(df, study):
    d = _designed_pair(_prepare(df, study))
    if "pattern_id" not in d or d["pattern_id"].isna().all():
        raise Skip(f"{STUDY_TITLES[study]}: no readable pattern cells")
    d = d[d["pattern_id"].notna()].copy()
    d["pattern_id"] = d["pattern_id"].astype(int)
    # Task 1 rows have no section (one answer per run); task 2 rows have sections 1-10.
    d["task"] = np.where(d["section"].notna() if "section" in d else False, 2, 1)
    return d


def _pattern_label(row):
    speed = f"{row['speed_cm_s']:g} cm/s" if not pd.isna(row.get("speed_cm_s", math.nan)) else ""
    return f"{row['pattern_id']}\n{speed}\n{SOURCE_LABELS.get(row['first'], row['first'])} |\n" \
           f"{SOURCE_LABELS.get(row['second'], row['second'])}"


def per_pattern(df, out_dir, study):
    """Fig. 5.9 (test 2) / 5.13 (test 3): task 1 answers per pattern."""
    d = _pattern_frame(df, study)
    d = d[d["task"] == 1]
    if d.empty or not d["answered"].any():
        raise Skip(f"{STUDY_TITLES[study]}: no answered task-1 trials")
    t = count_table(d, "pattern_id")
    speeds = d.groupby("pattern_id")["speed_cm_s"].first()
    t.insert(1, "speed_cm_s", t["pattern_id"].map(speeds))
    fig, ax = plt.subplots(figsize=(8.5, 4.6))
    _bars(ax, t, "pattern_id", [_pattern_label(r) for _, r in t.iterrows()])
    ax.set_xlabel("pattern (id, speed, the two blur sources compared)")
    num = 5.9 if study == STUDY_TEST2 else 5.13
    ax.set_title(f"{STUDY_TITLES[study].capitalize()}, task 1 (cf. thesis Fig. {num}): which ball fits the scene?\n"
                 f"{participants_note(d)}, {int(t['answered'].sum())} answers", loc="left")
    name = f"{study.split('-')[0]}-per-pattern"
    png, svg = save(fig, out_dir, name)
    notes = _notes(d) + [_caption_note(), "first source = the pattern's left source as designed (before swapping)"]
    model, model_notes = _model(d, "0 + C(pattern_id)", f"{study} task 1")
    return [Chart(name, png, svg, t, notes),
            Chart(name + "-model", None, None, model,
                  ["logit P(chose the first source | decisive) per pattern; 0 = no preference; SEs account for "
                   "repeated answers of one observer"] + model_notes)]


def per_section(df, out_dir, study):
    """Fig. 5.10-5.12: task 2 answers per section for patterns 2, 4, 6 (one chart each) and a trend model."""
    d = _pattern_frame(df, study)
    d = d[d["task"] == 2]
    if d.empty or not d["answered"].any():
        raise Skip(f"{STUDY_TITLES[study]}: no answered task-2 (per section) trials")
    charts = []
    models, model_notes = [], []
    prefix = study.split("-")[0]
    for pattern in sorted(d["pattern_id"].unique()):
        g = d[d["pattern_id"] == pattern].copy()
        if not g["answered"].any():
            charts.append(Chart(f"{prefix}-pattern{pattern}-per-section", None, None, pd.DataFrame(),
                                [f"pattern {pattern}: no answered trials"]))
            continue
        t = count_table(g, "section")
        t["section"] = t["section"].astype(int)
        first, second = t["first"].iloc[0], t["second"].iloc[0]
        fig, ax = plt.subplots(figsize=(9, 4.2))
        _bars(ax, t, "section", [str(s) for s in t["section"]])
        ax.set_xlabel("section (k = ball rolling from edge k to edge k + 1)")
        fig_num = {2: "5.10", 4: "5.11", 6: "5.12"}.get(int(pattern))
        ax.set_title(f"{STUDY_TITLES[study].capitalize()}, task 2, pattern {pattern}: "
                     f"{SOURCE_LABELS.get(first, first)} vs {SOURCE_LABELS.get(second, second)}"
                     f"{f' (cf. thesis Fig. {fig_num})' if fig_num and study == STUDY_TEST2 else ''}\n"
                     f"{participants_note(g)}, {int(t['answered'].sum())} answers", loc="left")
        name = f"{prefix}-pattern{pattern}-per-section"
        png, svg = save(fig, out_dir, name)
        charts.append(Chart(name, png, svg, t, _notes(g) + [_caption_note()]))
        g["section_c"] = g["section"] - 5.5
        m, n = _model(g, "section_c", f"pattern {pattern}", extra={"pattern": int(pattern)})
        models.append(m)
        model_notes += n
    model = pd.concat([m for m in models if not m.empty], ignore_index=True) if any(
        not m.empty for m in models) else pd.DataFrame()
    charts.append(Chart(f"{prefix}-per-section-model", None, None, model,
                        ["logit P(chose the first source | decisive) = Intercept + section_c x (section - 5.5), per "
                         "pattern; section_c > 0: the first source is chosen more often farther away"] + model_notes))
    return charts


def psychometric(df, out_dir, n_boot=200, seed=1):
    """Share choosing the more-blurred stimulus against the blur difference, pooled over the forced-choice studies.

    The question of tests 1-3 ("which fits the scene better?") is a preference: it has no correct answer, so no
    psychometric function with a 2AFC guess rate is fitted (it would assume the choice tends to the more blurred one
    as the difference grows, a direction the data must show instead). Drawn: the share in equal-count bins of the
    difference with Wilson 95 % intervals; tested: a logistic model of choosing the more blurred one on the difference
    across participants (across_observers.observer_models: GLM clustered by participant, GLMM by lme4), whose slope says whether
    and which way the choice moves with the difference. Only decisive answers (left/right) with a non-zero difference
    count: can't tell is not a choice of either stimulus, and with equal blur neither is the more blurred.
    n_boot and seed are kept for the caller; nothing here resamples.
    """
    parts = [forced_choice(study_rows(df, s)) for s in FORCED_CHOICE_STUDIES if (df["study"] == s).any()]
    if not parts:
        raise Skip("blur difference: no forced-choice trials")
    d = pd.concat(parts, ignore_index=True)
    if "r_left_px" not in d or "r_right_px" not in d:
        raise Skip("blur difference: trials.csv has no r_left_px / r_right_px columns")
    a = d[d["answered"]]
    dec = a[a["decisive"] & a["r_left_px"].notna() & a["r_right_px"].notna()].copy()
    dec["diff"] = (dec["r_left_px"] - dec["r_right_px"]).abs()
    ties = int((dec["diff"] < 1e-9).sum())
    dec = dec[dec["diff"] >= 1e-9]
    dec["more_blurred"] = np.where(dec["r_left_px"] > dec["r_right_px"], "left", "right")
    dec["y"] = (dec["choice"].str.strip() == dec["more_blurred"]).astype(float)
    n = len(dec)
    if n < 20 or dec["diff"].nunique() < 3:
        raise Skip(f"blur difference: {n} decisive answers at {dec['diff'].nunique()} blur differences "
                   f"(needs >= 20 at >= 3)")

    # Equal-count bins of the difference, for the chart; the model uses every answer.
    n_bins = int(min(10, max(4, n // 40)))
    dec["bin"] = pd.qcut(dec["diff"], n_bins, duplicates="drop")
    b = dec.groupby("bin", observed=True).agg(diff_mean=("diff", "mean"), n=("y", "size"), k=("y", "sum")).reset_index()
    b["k"] = b["k"].astype(int)
    wilson_columns(b, "k", "n", "share")
    b["bin"] = b["bin"].astype(str)
    model, model_notes = across_observers.observer_models(dec, "y", "diff", study="tests 1-3 pooled")

    fig, ax = plt.subplots(figsize=(7.2, 4.6))
    ax.axhline(0.5, color="#888888", lw=0.8, ls=":", label="no preference (0.5)")
    sizes = 15 + 60 * b["n"] / b["n"].max()
    ax.errorbar(b["diff_mean"], b["share"], yerr=error_bars(b["share"], b["share_low"], b["share_high"]), fmt="none",
                ecolor="#222222", lw=0.9, zorder=3)
    ax.plot(b["diff_mean"], b["share"], "-", color="#0072B2", lw=1, zorder=2)
    ax.scatter(b["diff_mean"], b["share"], s=sizes, color="#222222", zorder=4,
               label="answers, equal-count bins (Wilson 95 %; size ∝ n)")
    ax.set_xlim(0, float(dec["diff"].max()) * 1.02)
    ax.set_ylim(0, 1)
    ax.set_xlabel("blur difference |r_left − r_right| (photo px)")
    ax.set_ylabel("share choosing the more-blurred stimulus")
    studies = ", ".join(sorted(dec["study"].unique()))
    ax.set_title(f"Choosing the more blurred one against the blur difference, pooled over forced-choice studies\n"
                 f"{participants_note(dec)}, {n} decisive answers (a preference: no psychometric function fitted)",
                 loc="left")
    ax.legend(loc="lower right", fontsize=8)
    png, svg = save(fig, out_dir, "psychometric")
    notes = [f"studies pooled: {studies}",
             f"{n} decisive answers used; {int((a['chosen_source'] == 'cant_tell').sum())} can't-tell answers and "
             f"{ties} decisive answers with equal blur on both sides left out",
             "the question (which fits the scene better?) has no correct answer, so no psychometric function with a "
             "guess rate is fitted and no threshold is given; the model's slope on the difference says whether the "
             "choice of the more blurred one moves with it, and which way"] + model_notes
    return [Chart("psychometric", png, svg, model, notes),
            Chart("psychometric-bins", None, None, b, ["the binned points drawn in the chart above"])]


SIDE_BIAS_POOLED = "pooled"


def _side_frame(df):
    """Decisive answers (left / right, practice excluded) of every forced-choice study in df, with chose_left (0/1)
    and first_on_left (the pair's first source was the one shown on the left)."""
    parts = []
    for study in FORCED_CHOICE_STUDIES:
        d = study_rows(df, study)
        if d.empty:
            continue
        d = forced_choice(d)
        d = d[d["answered"] & d["decisive"]].copy()
        if study == STUDY_TEST1:
            d["first"] = "measured"
        else:
            d = _designed_pair(d)
        d["chose_left"] = (d["choice"].str.strip() == "left").astype(int)
        d["first_on_left"] = (d["left"] == d["first"]).astype(int)
        parts.append(d)
    return pd.concat(parts, ignore_index=True) if parts else pd.DataFrame()


def side_table(dec, by):
    """Per group of `by` (columns of the decisive answers): decisive, n_left, n_right, share_left with its Wilson
    95 % interval, the exact two-sided binomial test of n_left against 0.5, and the share of the answers whose
    left side showed the pair's first source (the counterbalancing of the design)."""
    rows = []
    for key, g in dec.groupby(by if len(by) > 1 else by[0], sort=False):
        key = key if isinstance(key, tuple) else (key,)
        n_left = int(g["chose_left"].sum())
        rows.append({**dict(zip(by, key)), "participants": g["participant"].nunique(), "decisive": len(g),
                     "n_left": n_left, "n_right": len(g) - n_left, "first_on_left": g["first_on_left"].mean()})
    t = pd.DataFrame(rows)
    wilson_columns(t, "n_left", "decisive", "share_left")
    # One decisive answer cannot test anything (its p is 1 whichever side it is): no p, not p = 1.
    t["p_binom"] = [stats.binom_p(k, n) if n > 1 else math.nan for k, n in zip(t["n_left"], t["decisive"])]
    return t


def side_bias(df, out_dir):
    """Side bias: among decisive answers, the share choosing the LEFT side per forced-choice study and pooled (Wilson
    95 % of the answers pooled; tested against 0.5 with participants as the unit), and per participant (exact
    binomial test of their answers).

    The studies counterbalance the sides (test 1 by participant, tests 2 and 3 with swapped copies of every pair), so
    a preference for one side cancels out of the source comparisons and shows up only here; `first_on_left` checks
    that the counterbalancing held among the answers actually given.
    """
    dec = _side_frame(df)
    if dec.empty:
        present = [s for s in FORCED_CHOICE_STUDIES if (df["study"] == s).any()]
        raise Skip("side bias: " + ("no forced-choice trials in trials.csv" if not present else
                                    "no decisive (left / right) answers in the forced-choice studies"))
    order = [s for s in FORCED_CHOICE_STUDIES if (dec["study"] == s).any()]
    pooled = dec.assign(study=SIDE_BIAS_POOLED)
    both = pd.concat([dec, pooled], ignore_index=True)
    t = side_table(both, ["study"]).drop(columns="p_binom")
    # A study's (and the pooled) row is tested with participants as the unit, as every other share of the report:
    # the binomial test of the answers pooled took 45 answers of 7 observers as independent. One participant: the
    # exact binomial test of that participant's answers (study_tests.against_chance says which).
    tests = []
    for study in t["study"]:
        g = both[both["study"] == study].assign(y=lambda x: x["chose_left"].astype(float))
        r = study_tests.against_chance(g, 0.5)
        tests.append({"test": r["test"], "p": r["p"], "participant_mean": r.get("participant_mean", math.nan),
                      "participant_low": r.get("participant_low", math.nan),
                      "participant_high": r.get("participant_high", math.nan)})
    t = pd.concat([t.reset_index(drop=True), pd.DataFrame(tests)], axis=1)
    t["p_holm"] = stats.holm(t["p"])
    per_p = side_table(pd.concat([dec, pooled], ignore_index=True).sort_values(["participant"], kind="stable"),
                       ["study", "participant"])
    per_p["p_holm"] = np.nan
    for study, idx in per_p.groupby("study").groups.items():
        per_p.loc[idx, "p_holm"] = stats.holm(per_p.loc[idx, "p_binom"])
    rank = {s: i for i, s in enumerate(order + [SIDE_BIAS_POOLED])}
    per_p = per_p.sort_values(["study", "participant"], key=lambda c: c.map(rank) if c.name == "study" else c)
    per_p = per_p.drop(columns="participants").reset_index(drop=True)

    fig, ax = plt.subplots(figsize=(6.6, 3.9))
    x = np.arange(len(t))
    ax.axhline(0.5, color="#888888", lw=0.9, ls="--", label="no side preference (0.5)", zorder=1)
    rng = np.random.default_rng(0)  # a fixed jitter, so the chart does not change between runs
    for xi, study in zip(x, t["study"]):
        g = per_p[per_p["study"] == study]
        ax.scatter(xi + rng.uniform(-0.17, 0.17, len(g)), g["share_left"],
                   s=8 + 40 * g["decisive"] / per_p["decisive"].max(), color="#999999", alpha=0.6, lw=0, zorder=2,
                   label="one participant (size ∝ answers)" if xi == 0 else None)
    colors = ["#0072B2"] * (len(t) - 1) + ["#222222"]
    bars = error_bars(t["share_left"], t["share_left_low"], t["share_left_high"])
    for xi, color in zip(x, colors):
        ax.errorbar([xi], t["share_left"].iloc[xi:xi + 1], yerr=bars[:, xi:xi + 1], fmt="none", ecolor=color, lw=1.4,
                    capsize=4, zorder=3)
    ax.scatter(x, t["share_left"], s=46, color=colors, zorder=4, label="study (Wilson 95 %)")
    for xi, row in zip(x, t.itertuples()):
        ax.text(xi, 0.97, f"{row.n_left}/{row.decisive} left\n{p_text(row.p_holm)} (Holm)", fontsize=8, va="top",
                ha="center", color="#333333")
    labels = {STUDY_TEST1: "test 1\nstatic grids", STUDY_TEST2: "test 2\nmoving balls",
              STUDY_TEST3: "test 3\nno board", SIDE_BIAS_POOLED: "pooled"}
    ax.set_xticks(x)
    ax.set_xticklabels([labels.get(s, s) for s in t["study"]])
    ax.set_xlim(-0.5, len(t) - 0.5)
    ax.set_ylim(0, 1.02)
    ax.set_yticks(np.linspace(0, 1, 6))
    ax.set_ylabel("share choosing the left side")
    ax.grid(axis="x", visible=False)
    ax.set_title(f"Side bias among decisive answers (practice excluded)\n{participants_note(dec)}, "
                 f"{len(dec)} decisive answers", loc="left")
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), handlelength=1.2, alignment="left")
    png, svg = save(fig, out_dir, "side-bias")

    notes = [f"{participants_note(dec)}; {len(dec)} decisive answers (left / right; can't tell and practice left out)",
             "share_left: share of the decisive answers choosing the left side, Wilson 95 % interval (a "
             "description of the answers pooled); test, p: against 0.5 with participants as the unit (the exact "
             "sign-flip permutation test of the participants' shares, from 3 participants; one participant: "
             "the exact binomial test of that participant's answers); p_holm: Holm-adjusted over the chart's rows "
             "(the pooled row included); the chart prints the adjusted p",
             "the studies counterbalance the sides (test 1 by participant, tests 2 and 3 with a swapped copy of every "
             "pair), so a side preference cancels out of the source comparisons and shows up only here; "
             "first_on_left: share of these answers whose left side showed the pair's first source (0.5 = balanced)"]
    for row in t.itertuples():
        if abs(row.first_on_left - 0.5) > 0.1:
            notes.append(f"{row.study}: the first source was on the left in {row.first_on_left:.0%} of the decisive "
                         f"answers - the sides are not balanced there, so a side preference would bias its source "
                         f"comparison")
        if not math.isnan(row.p_holm) and row.p_holm < 0.05:
            notes.append(f"{row.study}: {row.share_left:.0%} chose the left side ({p_text(row.p_holm)}, Holm) - "
                         f"a side preference")
    fixed = per_p[(per_p["study"] != SIDE_BIAS_POOLED) & per_p["first_on_left"].isin([0.0, 1.0])
                  & (per_p["decisive"] > 1)]
    participant_notes = []
    for study, g in fixed.groupby("study", sort=False):
        participant_notes.append(
            f"{study}: {len(g)} participant{'s' if len(g) != 1 else ''} saw the first source always on the same side "
            f"(counterbalanced across participants, not within): their share_left is their source preference as "
            f"much as a side preference")
    return [Chart("side-bias", png, svg, t, notes),
            Chart("side-bias-per-participant", None, None, per_p,
                  ["per participant within each study and pooled over the studies; p_binom: the exact binomial test "
                   "of the participant's decisive answers against 0.5, empty for one answer (one answer cannot test "
                   "anything); p_holm: Holm-adjusted over the participants of one study (or of the pooled rows)"]
                  + participant_notes)]


def charts(df, out_dir, n_boot=200):
    """Every forced-choice chart (for callers that want them all at once; report.py runs them step by step)."""
    out = []
    for step in (lambda: test1_per_edge(df, out_dir),
                 lambda: per_pattern(df, out_dir, STUDY_TEST2), lambda: per_pattern(df, out_dir, STUDY_TEST3),
                 lambda: per_section(df, out_dir, STUDY_TEST2), lambda: per_section(df, out_dir, STUDY_TEST3),
                 lambda: psychometric(df, out_dir, n_boot=n_boot), lambda: side_bias(df, out_dir)):
        try:
            out += step()
        except Skip as e:
            out.append(Chart("skipped", None, None, pd.DataFrame(), [str(e)]))
    return out
