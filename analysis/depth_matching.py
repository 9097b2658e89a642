"""Pre-research depth matching (thesis 3.2, Fig. 3.3): the accepted blur against the real picture's.

Each observer accepted one of 22 Butterworth cut-offs (cycles per picture width) at each of 27 distances (0.4-4 m)
of a real picture photographed with the camera focused at 1 m. What the task measures is the match: the blur set
against the real picture's blur, both in arcmin at the eye (trials.csv's r_scene_arcmin; a level's blur as the
equivalent Gaussian's). The thesis's power law of cut-off over distance is kept as the replication of its Fig. 3.3,
with its limit said: the real blur is V-shaped around the focus, so one power law over distance flattens it.

Model table (across_observers.MODEL_COLUMNS), where the record allows:
  set on real       set_arcmin ~ real_arcmin: lmer with a random intercept and slope by participant (Satterthwaite
                    df; intercept-only when that is singular), and pooled OLS with SEs clustered by participant (CR1,
                    t(G-1); with two participants neither: said in words); needs r_scene_arcmin and
                    picture_width_arcmin. The slope is tested against 1 (set as
                    real: t = (b - 1) / SE on the fit's df) and, on a row beside it, against 0. The intercept (the
                    set blur at real blur 0) is not tested: 'set as real' there is a set blur of 0, which no level
                    can give (the sharpest level's blur, from the trials' adjust_levels, is said in its note)
  power law         log c ~ log d: per observer (OLS), pooled OLS clustered as above, and lmer as above
"""
import math
import warnings

import numpy as np
import pandas as pd
import matplotlib.pyplot as plt
from matplotlib.ticker import FixedLocator, NullLocator
from scipy import stats as sps

import mixed
import prediction
import across_observers
from common import Chart, Skip, STUDY_DEPTH, participants_note, save, study_rows


MIN_OBSERVERS_CI = across_observers.MIN_PARTICIPANTS_MODEL  # an interval or a model across observers needs this many


def charts(df, out_dir):
    d = study_rows(df, STUDY_DEPTH)
    if d.empty:
        raise Skip("depth matching: no trials in trials.csv")
    d["cutoff"] = pd.to_numeric(d["choice"].replace("", np.nan), errors="coerce")
    answered = d[d["answered"]]
    bad = int(answered["cutoff"].isna().sum() + (answered["cutoff"] <= 0).sum())
    a = answered[(answered["cutoff"] > 0) & answered["distance_m"].notna() & (answered["distance_m"] > 0)].copy()
    if a.empty:
        raise Skip(f"depth matching: 0 of {len(d)} trials answered with a cut-off")
    a["log_d"] = np.log(a["distance_m"])
    a["log_c"] = np.log(a["cutoff"])
    observers = sorted(a["participant"].unique())
    notes = [f"{participants_note(a)}; {len(a)} of {len(d)} planned trials answered (practice excluded)"]
    if bad:
        notes.append(f"{bad} answers without a positive numeric cut-off ignored")

    a["set_arcmin"] = (2 * EQUIVALENT_S * pd.to_numeric(a["picture_width_arcmin"], errors="coerce") / a["cutoff"]
                       if "picture_width_arcmin" in a else np.nan)
    a["real_arcmin"] = pd.to_numeric(a["r_scene_arcmin"], errors="coerce") if "r_scene_arcmin" in a else np.nan
    rows, pooled = fits(a, notes)
    table = across_observers.model_table(rows)
    # Per distance across observers: geometric mean (mean of log cut-off per observer, then across observers).
    per_obs = a.groupby(["distance_m", "participant"])["log_c"].mean().reset_index()
    summary = per_obs.groupby("distance_m")["log_c"].agg(["mean", "std", "count"]).reset_index()
    # An interval across observers needs three (a t(1) interval from two is 12.7 of their SEs wide and says nothing
    # of the spread): fewer get none, said in the table's note.
    tcrit = sps.t.ppf(0.975, np.maximum(summary["count"] - 1, 1))
    half = np.where(summary["count"] >= MIN_OBSERVERS_CI, tcrit * summary["std"] / np.sqrt(summary["count"]), np.nan)
    summary["geo_mean"] = np.exp(summary["mean"])
    summary["low"] = np.exp(summary["mean"] - half)
    summary["high"] = np.exp(summary["mean"] + half)

    fig, ax = plt.subplots(figsize=(8, 4.8))
    cmap = plt.get_cmap("tab10" if len(observers) <= 10 else "tab20")
    for i, p in enumerate(observers):
        g = a[a["participant"] == p].sort_values("distance_m")
        ax.plot(g["distance_m"], g["cutoff"], "o-", ms=3, lw=0.7, alpha=0.55, color=cmap(i % cmap.N),
                label=f"observer {p}" if len(observers) <= 12 else None)
    ax.errorbar(summary["distance_m"], summary["geo_mean"],
                yerr=np.vstack([np.nan_to_num(summary["geo_mean"] - summary["low"]),
                                np.nan_to_num(summary["high"] - summary["geo_mean"])]),
                fmt="s", color="black", ms=4.5, lw=1, zorder=5,
                label="geometric mean" + (" (95 % CI across observers)" if len(observers) >= MIN_OBSERVERS_CI
                                          else ""))
    if pooled is not None:
        grid = np.linspace(a["distance_m"].min(), a["distance_m"].max(), 200)
        aa, bb = pooled
        ax.plot(grid, np.exp(aa) * grid ** bb, color="#D55E00", lw=2, zorder=6,
                label=f"fit: $c = {math.exp(aa):.1f}\\, d^{{{bb:.2f}}}$ (d in m)")
    ax.set_yscale("log")
    ticks = [t for t in (1, 2, 5, 10, 20, 50, 100) if a["cutoff"].min() / 1.5 <= t <= a["cutoff"].max() * 1.5]
    ax.yaxis.set_major_locator(FixedLocator(ticks))
    ax.yaxis.set_minor_locator(NullLocator())
    ax.set_yticklabels([str(t) for t in ticks])
    ax.set_xlabel("distance of the real picture from the observer (m)")
    ax.set_ylabel("accepted cut-off (cycles / picture width)")
    ax.set_title(f"Pre-research depth matching (cf. thesis Fig. 3.3)\n{participants_note(a)}, {len(a)} answers; "
                 "lower cut-off = more blur", loc="left")
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8)
    png, svg = save(fig, out_dir, "depth-matching")
    notes.append("power law (the thesis's Fig. 3.3): log c = a + b log d (natural logs, d in m, c in cycles per "
                 "picture width); b < 0 means more blur is accepted farther away. Its limit: the real picture's blur "
                 "is V-shaped around the camera's 1 m focus (none at the focus, more nearer and farther), so one power "
                 "law over distance has a slope near 0 by construction; the match itself is the set blur against the "
                 "real blur, both in arcmin (the 'set on real' rows)")
    summary = summary.rename(columns={"mean": "mean_log_cutoff", "std": "sd_log_cutoff", "count": "observers"})
    out = [Chart("depth-matching", png, svg, table, notes),
           Chart("depth-matching-per-distance", None, None, summary,
                 ["geometric mean of the accepted cut-off per distance; low/high: 95 % t-interval across observers "
                  "of the observers' log cut-offs" + (
                      "" if summary["observers"].min() >= MIN_OBSERVERS_CI else
                      f"; none where fewer than {MIN_OBSERVERS_CI} observers answered at a distance (from two, a "
                      "t(1) interval is no estimate of their spread)")])]
    arcmin = _in_visual_angle(a, out_dir)
    if arcmin is not None:
        out.append(arcmin)
    return out


WORDS_POWER = {"Intercept": "a (log cut-off at 1 m)", "log_d": "b (per unit of log distance)"}
# a = 0 would be a cut-off of 1 cycle per picture width at 1 m: no one's hypothesis, so no p for it.
NO_P_POWER_A = "no p: a = 0 (a cut-off of 1 cycle per picture width at 1 m) is no hypothesis"


def _meaningful(term, words, p, note, floor_arcmin=None):
    """The p and note of a row: the power law's intercept gets no p (see NO_P_POWER_A), nor does the match's (see
    no_p_match_intercept)."""
    if words is WORDS_POWER and term == "Intercept":
        return math.nan, (note + "; " if note else "") + NO_P_POWER_A
    if words is WORDS_MATCH and term == "Intercept":
        return math.nan, (note + "; " if note else "") + no_p_match_intercept(floor_arcmin)
    return p, note


WORDS_MATCH = {"Intercept": "set blur at real blur 0 (arcmin)",
               "real_arcmin": "per arcmin of real blur, against 1 (set as real)"}
# The match's slope is tested against 1 - "set as real", the hypothesis the task is about - and, on a row of its own
# beside it, against 0 (any relation at all): the same estimate, SE and df, two tests, each labelled.
MATCH_SLOPE_AGAINST_0 = "per arcmin of real blur, against 0 (any relation)"


def no_p_match_intercept(floor_arcmin):
    """Why the match's intercept (the set blur at real blur 0) is not tested: 'set as real' there means a set blur of
    0, which no level can give (a Butterworth level's blur is 0 only at an infinite cut-off); the least the design
    can set is its sharpest level's blur (floor_arcmin; None when the record does not give the levels)."""
    floor = (f"the sharpest level the design offers sets {floor_arcmin:.4g}'" if floor_arcmin is not None and
             math.isfinite(floor_arcmin) else "every level the design offers sets more than 0'")
    return (f"no p: 'set as real' at real blur 0 would be a set blur of 0, which the design cannot reach ({floor}); "
            "the match is tested by the slope against 1")


def sharpest_level_arcmin(a):
    """The least blur any trial of rows a could set (arcmin): the blur of its highest cut-off among the trial's own
    levels (adjust_levels), the smallest over the trials; None when the record does not give the levels."""
    if "adjust_levels" not in a or "picture_width_arcmin" not in a:
        return None
    floors = []
    for levels, width in zip(a["adjust_levels"].astype(str), pd.to_numeric(a["picture_width_arcmin"], errors="coerce")):
        try:
            cutoffs = [float(c) for c in levels.split(";") if c.strip()]
        except ValueError:
            return None
        if not cutoffs or not math.isfinite(width) or max(cutoffs) <= 0:
            return None
        floors.append(2 * EQUIVALENT_S * width / max(cutoffs))
    return min(floors) if floors else None


def _rows_of(study, model, words, term, est, se, df, p, engine, note, floor_arcmin=None):
    """The model rows of one term: the match's slope twice (its p against 1 from the fit's own SE and df - t = (b -
    1) / SE on df - then the fit's p against 0), any other term once (the intercepts without p: _meaningful)."""
    if words is not WORDS_MATCH or term != "real_arcmin":
        p, note = _meaningful(term, words, p, note, floor_arcmin)
        return [across_observers.model_row(study, model, words[term], est, se, df, p, engine, note)]
    ok = math.isfinite(p) and se > 0 and df > 0
    p1 = float(2 * sps.t.sf(abs(est - 1) / se, df)) if ok else math.nan
    return [across_observers.model_row(study, model, words[term], est, se, df, p1, engine, note),
            across_observers.model_row(study, model, MATCH_SLOPE_AGAINST_0, est, se, df, p, engine, note)]


def _ols_rows(g, x, y, model, words, study):
    """OLS of one observer's y on x: intercept and slope with their t (n-2 df)."""
    if len(g) < 3 or g[x].nunique() < 2:
        return []
    res = sps.linregress(g[x], g[y])
    df = len(g) - 2
    out = []
    for term, est, se in (("Intercept", res.intercept, res.intercept_stderr), (x, res.slope, res.stderr)):
        out += _rows_of(study, model, words, term, est, se, df, 2 * sps.t.sf(abs(est / se), df) if se > 0
                        else math.nan, "scipy linregress (OLS)", "")
    return out


# Two participants: no model across them, in the forced choice's words (across_observers.observer_models).
TWO_PARTICIPANTS = ("{label}: two participants: too few for a model across participants (a cluster-robust SE from two "
                    "participants with t(1), or a mixed model's spread between two, is not an estimate); no model "
                    "fitted, no SE, no p - the answers per distance are in the tables, and a model needs >= {minimum}")


def _across(a, x, y, label, words, notes, study, floor_arcmin=None):
    """Pooled OLS clustered by participant and the lmer of y on x with a random intercept and slope by participant;
    rows and the pooled (intercept, slope). floor_arcmin: the least blur the design can set (the match's intercept's
    note says it)."""
    import statsmodels
    import statsmodels.api as sm
    rows, pooled = [], None
    X = pd.DataFrame({"Intercept": 1.0, x: a[x].to_numpy(float)}, index=a.index)
    groups = a["participant"].astype(str).to_numpy()
    n_groups = len(set(groups))
    version = statsmodels.__version__.split("+")[0]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        zero_se = {}
        if n_groups == 2:
            # Two clusters give a sandwich SE from two residual sums and a t(1) reference: no estimate of the
            # spread between participants (as across_observers.observer_models says for the forced choice). The pooled line
            # is still drawn, from plain OLS, and each observer's own fit is in the table where there is one.
            res = sm.OLS(a[y].to_numpy(float), X).fit()
            pooled = (float(res.params.iloc[0]), float(res.params.iloc[1]))
            notes.append(TWO_PARTICIPANTS.format(label=label, minimum=across_observers.MIN_PARTICIPANTS_MODEL))
            return rows, pooled
        if n_groups >= 3:
            t = across_observers.cluster_robust(a[y].to_numpy(float), X, groups, family=sm.families.Gaussian())
            pooled = (float(t["estimate"].iloc[0]), float(t["estimate"].iloc[1]))  # before any is said in words
            t, zero_se = across_observers.without_zero_se(t, words)
            engine = f"statsmodels {version} OLS cluster-robust CR1, t(G-1)"
            model = f"lm({y} ~ {x}), cluster-robust"
        else:
            res = sm.OLS(a[y].to_numpy(float), X).fit()
            t = pd.DataFrame({"term": list(X.columns), "estimate": res.params.to_numpy(), "se": res.bse.to_numpy(),
                              "df": res.df_resid, "p": res.pvalues.to_numpy()})
            engine = f"statsmodels {version} OLS (one observer)"
            model = f"lm({y} ~ {x}) (one observer)"
    for _, r in t.iterrows():
        rows += _rows_of(study, f"{label}: {model}", words, r["term"], r["estimate"], r["se"], r["df"], r["p"],
                         engine, zero_se.get(r["term"], ""), floor_arcmin)
    if pooled is None:
        pooled = (float(t["estimate"].iloc[0]), float(t["estimate"].iloc[1]))
    if n_groups >= 3:
        try:
            f = mixed.fit("lmm", a[y].to_numpy(float), X, groups, slopes=[x])
        except mixed.Unavailable as e:
            notes.append(f"{label}: mixed model not fitted: {e}")
            return rows, pooled
        random = f.random_text()
        model = f"{label}: lmer({y} ~ {x} + {random})"
        if f.failed:
            notes.append(f"{label}: mixed model {f.failed}")
            return rows, pooled
        status = f.structure + ("; singular fit" if f.singular else "")
        for _, r in across_observers.without_unheld_tests(f, [x]).iterrows():
            rows += _rows_of(study, model, words, r["term"], r["estimate"], r["se"], r["df"], r["p"], f.engine,
                             status + r["why"], floor_arcmin)
        # The SD of the participants' slopes is a spread, tested against nothing: named without a test's words.
        sd_words = {**words, x: "per arcmin of real blur"} if words is WORDS_MATCH else words
        rows += across_observers.variance_rows(study, model, f, sd_words, "arcmin" if y == "set_arcmin" else "log cut-off")
    return rows, pooled


def fits(a, notes):
    """The depth-matching model table's rows and the pooled power law (a, b) for the chart (None without one)."""
    rows, pooled = [], None
    study = STUDY_DEPTH
    m = a[a["set_arcmin"].notna() & a["real_arcmin"].notna()]
    if len(m) >= 3 and m["real_arcmin"].nunique() >= 2:
        r, _ = _across(m, "real_arcmin", "set_arcmin", "set on real", WORDS_MATCH, notes, study,
                       sharpest_level_arcmin(m))
        rows += r
    elif len(a):
        notes.append("no set-on-real model: trials.csv has no r_scene_arcmin / picture_width_arcmin (the real "
                     "picture's blur in visual angle); only the power law over distance")
    if a["log_d"].nunique() >= 2:
        if a["participant"].nunique() == 1:
            notes.append("one participant: no fit across observers; the pooled line is that observer's")
        r, pooled = _across(a, "log_d", "log_c", "power law", WORDS_POWER, notes, study)
        rows += r
        for p in sorted(a["participant"].unique()):
            rows += _ols_rows(a[a["participant"] == p], "log_d", "log_c", f"power law: observer {p}",
                              WORDS_POWER, study)
    return rows, pooled


def _model_median(v):
    """Per distance, the median set blur (arcmin) the arcmin observer's closed form predicts from each trial's own
    levels (adjust_levels, as recorded), its probabilities averaged over the distance's trials; None without them."""
    if "adjust_levels" not in v:
        return None
    rows = []
    for distance, g in v.groupby("distance_m"):
        mixture = {}
        for _, t in g.iterrows():
            try:
                cutoffs = np.array([float(c) for c in str(t["adjust_levels"]).split(";")])
            except ValueError:
                return None
            if not np.all(cutoffs > 0):
                return None
            level_r = 2 * EQUIVALENT_S * t["picture_width_arcmin"] / cutoffs
            for r, p in zip(level_r, prediction.match_choice(level_r, t["r_scene_arcmin"])):
                mixture[round(float(r), 9)] = mixture.get(round(float(r), 9), 0.0) + p / len(g)
        rs = np.array(sorted(mixture))
        cumulative = np.cumsum([mixture[r] for r in rs])
        rows.append({"distance_m": distance, "model_median": float(rs[np.searchsorted(cumulative, 0.5)])})
    return pd.DataFrame(rows)


# A Butterworth level c's blur as the equivalent Gaussian's (the one that halves contrast at the cut-off, s =
# sqrt(ln 2 / 2) / (pi c) picture widths; blurcue's r = 2 s), as scene::ButterworthEquivalentSigma states it.
EQUIVALENT_S = math.sqrt(math.log(2) / 2) / math.pi


def _in_visual_angle(a, out_dir):
    """The set blur against the real picture's, both in arcmin at the eye, where the record holds the real blur
    (content.real_camera): the match a blur-only observer would make lies on the diagonal above the eye's intrinsic
    blur and anywhere below it."""
    if "r_scene_arcmin" not in a or "picture_width_arcmin" not in a:
        return None
    v = a[a["r_scene_arcmin"].notna() & a["picture_width_arcmin"].notna()].copy()
    if v.empty:
        return None
    v["set_arcmin"] = 2 * EQUIVALENT_S * v["picture_width_arcmin"] / v["cutoff"]
    fig, ax = plt.subplots(figsize=(6.4, 4.8))
    top = max(v["set_arcmin"].max(), v["r_scene_arcmin"].max()) * 1.1
    intrinsic_r = 2 * prediction.DEFAULTS["intrinsic_arcmin"]  # blurcue's r of the eye's intrinsic blur
    ax.axvspan(0, intrinsic_r, facecolor="#dddddd", edgecolor="#aaaaaa", zorder=0,
               label=f"below the eye's intrinsic blur (r {intrinsic_r:g}')")
    ax.plot([0, top], [0, top], color="#D55E00", lw=1.5, label=f"set = real (the dipper's match above {intrinsic_r:g}')")
    ax.scatter(v["r_scene_arcmin"], v["set_arcmin"], s=12, alpha=0.5, color="#0072B2", label="answers")
    med = v.groupby("distance_m").agg(real=("r_scene_arcmin", "first"), set_median=("set_arcmin", "median"),
                                      answers=("set_arcmin", "size")).reset_index()
    model = _model_median(v)
    if model is not None:
        med = med.merge(model, on="distance_m", how="left")
        order = med.sort_values("real")
        ax.plot(order["real"], order["model_median"], "-", color="#009E73", lw=1.5, zorder=4,
                label="the model's median (arcmin observer, defaults)")
    ax.plot(med["real"], med["set_median"], "s", color="black", ms=4, label="median per distance")
    ax.set_xlim(0, top)
    ax.set_ylim(0, top)
    ax.set_xlabel("the real picture's blur r (arcmin at the eye)")
    ax.set_ylabel("the accepted level's blur r (arcmin, equivalent Gaussian)")
    ax.set_title(f"Depth matching in visual angle\n{participants_note(v)}, {len(v)} answers", loc="left")
    ax.legend(loc="upper left", fontsize=8)
    png, svg = save(fig, out_dir, "depth-matching-arcmin")
    rho = sps.spearmanr(v["r_scene_arcmin"], v["set_arcmin"]).correlation if len(v) > 2 else math.nan
    notes = [f"a level c's blur r = 2 x {EQUIVALENT_S:.4f} x the picture's width (arcmin) / c: the Gaussian that also "
             "halves contrast at the cut-off; the real blur is the thin lens of the protocol's content.real_camera",
             f"rank correlation of set and real blur over the answers: {rho:.2f}"]
    if model is not None:
        notes.append("model_median: the median blur the simulated observer (model=arcmin, its default parameters) "
                     "would set at that distance from the same levels - each level compared once with the real "
                     "picture, the closest-looking one taken (analysis/prediction.py match_choice, the closed form)")
    return Chart("depth-matching-arcmin", png, svg, med, notes)
