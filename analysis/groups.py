"""A between-subject group crossed with a within-participant factor: the question a rendering-by-depth design asks
(does the group's difference change with depth, and at which depths do the groups differ?).

Per within factor F of a study with a group (design.Design: group, factors):
  interaction     the mixed model with the interaction, y ~ group * F + (random by participant), against the same
                  model without it, y ~ group + F + (...), fitted by lme4 (models.R group_job): a binomial GLMM for a
                  0/1 measure, tested by the likelihood-ratio chi-square; an LMM for a rating or an adjusted level,
                  tested by the Kenward-Roger F. The random part is the first of (1 + F | participant),
                  (1 | participant) + (1 | participant:F), (1 | participant) whose fit converges and is not singular
                  (the table says which and why). Other within factors enter as main effects.
                  With participants as the unit beside it (no R): the split-plot ANOVA of each participant's share
                  or mean per level, its interaction F with the Greenhouse-Geisser p (split_plot).
  per level       the groups' difference at each level of F: from the model with the interaction by emmeans (log-odds
                  for a 0/1 measure; a GLMM's Wald z against t with G - groups df), and with participants as the unit
                  (each participant's share or mean at that level, Welch's t between the groups), each Holm-adjusted
                  over the levels (and pairs of groups) of F.
A fit that fails, does not converge or is singular in every random part gives no test: "not determined", in words,
with why. Without R the model rows say so; the participants-as-the-unit rows need no R.
"""
import math
import os
import re
import tempfile

import numpy as np
import pandas as pd
from scipy import stats as sps

import mixed
import across_observers
import stats
import study_tests
from common import Chart, text

# A study's measure -> the model family (any_study.kind_of); an adaptive procedure's share correct is set by the
# procedure and gets none.
FAMILY = {"pair": "glmm", "odd": "glmm", "yes_no": "glmm", "rating": "lmm", "adjustment": "lmm"}
NUMBER = re.compile(r"[-+]?\d+(?:\.\d*)?(?:[eE][-+]?\d+)?")


def _levels(values):
    """Distinct levels as text, numbers in numeric order."""
    vals = sorted({v for v in values})
    if all(NUMBER.fullmatch(v) for v in vals):
        return sorted(vals, key=float)
    return vals


def _label(v):
    """A level as the tables write it: 3.0 as 3; an empty cell (the factor does not apply to the row) in words."""
    return v[:-2] if v.endswith(".0") else v if v else "(not applicable)"


def _named(words, factor):
    """models.R's words with its coded names (g: the participant, w: the factor) as the caller's."""
    return re.sub(r"\bw\b", factor, re.sub(r"\bg\b", "participant", words))


# A contrast's t needs this many df: t(1) (a GLMM's G - groups with 3 participants in 2 groups) has no variance, and
# its 95 % interval is 12.7 SEs wide; such a contrast keeps its estimate and gets no SE, df or p, in words.
MIN_CONTRAST_DF = 2


def few_df_words(df, family, people, n_groups):
    """Why a contrast on df below MIN_CONTRAST_DF has no SE or p, in words."""
    if family == "glmm":
        return (f"no SE or p: {people} participants in {n_groups} groups leave {people - n_groups} df for the groups' "
                f"difference (t(G - groups)), too few for a test; needs >= {n_groups + MIN_CONTRAST_DF} participants")
    return (f"no SE or p: the groups' difference has {df:.2g} Satterthwaite df (below {MIN_CONTRAST_DF}), too few "
            f"participants for a test")


def fit(m, column, factor, group, others=(), family="glmm"):
    """The interaction model of rows m (measure `column`, participants in `participant`) by lme4. Returns a dict:
    test (statistic, df, df2, p, engine, random, structure) or why (not determined, in words), contrasts (factor's level,
    group_a, group_b, estimate, se, df, p), emmeans (level, group, estimate, se)."""
    out = {"why": "", "test": None, "contrasts": pd.DataFrame(), "emmeans": pd.DataFrame(), "structure": "",
           "random": "", "engine": ""}
    people = text(m["participant"]).nunique()
    if people < across_observers.MIN_PARTICIPANTS_MODEL:
        out["why"] = (f"not determined: {people} participant{'s' if people != 1 else ''}: too few for a model across "
                      f"participants (a mixed model's spread between {people}, or a t({max(people - 1, 0)}) test, is "
                      f"not an estimate); no model fitted - a model needs >= {across_observers.MIN_PARTICIPANTS_MODEL}")
        return out
    exe = mixed.rscript()
    if exe is None:
        out["why"] = "not determined: R is not installed (no Rscript): no mixed model; install r-base-core and r-cran-lme4"
        return out
    levels = _levels(text(m[factor]).map(_label))
    groups = _levels(text(m[group]))
    w_code = {v: f"W{i:02d}" for i, v in enumerate(levels, 1)}
    g_code = {v: f"G{i:02d}" for i, v in enumerate(groups, 1)}
    frame = pd.DataFrame({"y": pd.to_numeric(m[column]).to_numpy(float), "g": text(m["participant"]).to_numpy(),
                          "grp": text(m[group]).map(g_code).to_numpy(), "w": text(m[factor]).map(_label).map(
                              w_code).to_numpy()})
    for i, other in enumerate(others):
        frame[f"C{i}"] = text(m[other]).map(lambda v: "L" + re.sub(r"[^A-Za-z0-9]", "_", v)).to_numpy()
    with tempfile.TemporaryDirectory(prefix="blurcue-groups-") as tmp:
        data_path, out_path = os.path.join(tmp, "data.csv"), os.path.join(tmp, "out.csv")
        frame.to_csv(data_path, index=False)
        try:
            mixed._server(exe).run(f"group_{family}", data_path, out_path, "")
        except mixed.Unavailable as e:
            out["why"] = f"not determined: {e}"
            return out
        table = pd.read_csv(out_path, keep_default_na=False, na_values=[""], dtype={"term": str, "note": str})
    table["note"] = table["note"].fillna("").astype(str)
    info = {r["term"]: r["note"] for _, r in table[table["row"] == "info"].iterrows()}
    back_w = {c: v for v, c in w_code.items()}
    back_g = {c: v for v, c in g_code.items()}
    out["engine"] = info.get("engine", "lme4")
    out["structure"] = _named(info.get("structure", ""), factor)
    out["random"] = _named(info.get("random", ""), factor)
    if "failed" in info:
        out["why"] = f"not determined: the model with the interaction: {_named(info['failed'], factor)}"
        return out
    if "failed_test" in info:
        out["why"] = f"not determined: {info['failed_test']}"
    if "null_singular" in info:
        out["structure"] += f"; {info['null_singular']}"
    test = table[table["row"] == "test"]
    if len(test) and math.isfinite(float(test["p"].iloc[0])):
        r = test.iloc[0]
        out["test"] = {"statistic": float(r["estimate"]), "df": float(r["df"]),
                       "df2": float(r["note"]) if r["note"] else math.nan, "p": float(r["p"])}
    elif not out["why"]:
        out["why"] = "not determined: the comparison of the two models gave no p"
    rows = []
    for _, r in table[table["row"] == "contrast"].iterrows():
        level, a, b = str(r["term"]).split("|")
        row = {"level": back_w[level], "group_a": back_g[a], "group_b": back_g[b], "estimate": r["estimate"],
               "se": r["se"], "df": r["df"], "p": r["p"], "says": ""}
        if not (r["df"] >= MIN_CONTRAST_DF):  # NaN too
            row.update(se=math.nan, df=math.nan, p=math.nan, says=few_df_words(r["df"], family, people, len(groups)))
        rows.append(row)
    out["contrasts"] = pd.DataFrame(rows)
    out["emmeans"] = pd.DataFrame([{"level": back_w[str(r["term"]).split("|")[0]],
                                    "group": back_g[str(r["term"]).split("|")[1]], "estimate": r["estimate"],
                                    "se": r["se"]} for _, r in table[table["row"] == "emmean"].iterrows()])
    if "missing" in info:
        out["missing"] = f"the R package {info['missing']} is not installed: no per-level comparison from the model; " \
                         f"install r-cran-{info['missing'].lower()}"
    return out


def per_level_participants(m, column, factor, group):
    """Per level of factor and pair of groups: each participant's share (or mean) at that level, Welch's t between
    the two groups' participants (>= 3 in each, else no test, said). Rows: level, group_a, group_b, mean_a, mean_b,
    n_a, n_b, difference (a - b), t, df, p, test."""
    d = m.assign(_level=text(m[factor]).map(_label), _group=text(m[group]))
    pp = d.groupby(["_level", "_group", "participant"])[column].mean().reset_index()
    groups = _levels(d["_group"])
    rows = []
    for level in _levels(d["_level"]):
        at = pp[pp["_level"] == level]
        for i, a in enumerate(groups):
            for b in groups[i + 1:]:
                va = at.loc[at["_group"] == a, column].to_numpy(float)
                vb = at.loc[at["_group"] == b, column].to_numpy(float)
                row = {"level": level, "group_a": a, "group_b": b, "n_a": len(va), "n_b": len(vb),
                       "mean_a": va.mean() if len(va) else math.nan, "mean_b": vb.mean() if len(vb) else math.nan}
                row["difference"] = row["mean_a"] - row["mean_b"]
                if min(len(va), len(vb)) < study_tests.MIN_PARTICIPANTS_T:
                    row.update(t=math.nan, df=math.nan, p=math.nan,
                               test=f"none: {min(len(va), len(vb))} participants in a group (needs >= "
                                    f"{study_tests.MIN_PARTICIPANTS_T} in each)")
                elif va.var(ddof=1) + vb.var(ddof=1) == 0:
                    row.update(t=math.nan, df=math.nan, p=math.nan, test="none: no spread within either group")
                else:
                    va_n, vb_n = va.var(ddof=1) / len(va), vb.var(ddof=1) / len(vb)
                    t = (va.mean() - vb.mean()) / math.sqrt(va_n + vb_n)
                    df = (va_n + vb_n) ** 2 / (va_n ** 2 / (len(va) - 1) + vb_n ** 2 / (len(vb) - 1))
                    row.update(t=t, df=df, p=float(2 * sps.t.sf(abs(t), df)),
                               test="Welch's t of the participants' values")
                rows.append(row)
    return pd.DataFrame(rows)


def split_plot(m, column, factor, group):
    """The group x factor interaction with participants as the unit, no R: the split-plot (mixed-design) ANOVA of each
    participant's share (or mean) per level. Each participant's profile over the k levels, less its own mean, as k - 1
    orthonormal contrasts; the interaction is the groups' difference in those contrasts: F = (SS between the groups'
    mean contrasts / (g - 1)(k - 1)) / (SS within the groups / (N - g)(k - 1)) - aov(y ~ group * F + Error(participant /
    F))'s within stratum - and its p with the Greenhouse-Geisser epsilon (tr S)^2 / ((k - 1) tr S^2) of the pooled
    within-group covariance S of the contrasts, which keeps the level where the levels' variances differ (no
    sphericity). Participants without an answer at every level are left out (counted). Returns a dict: F, df1, df2, p
    (Greenhouse-Geisser), p_uncorrected, epsilon, participants, left_out; or why (in words) without a test."""
    d = m.assign(_level=text(m[factor]).map(_label), _group=text(m[group]))
    levels = _levels(d["_level"])
    wide = d.pivot_table(index=["_group", "participant"], columns="_level", values=column, aggfunc="mean")
    wide = wide.reindex(columns=levels)
    full = wide.dropna()
    left_out = len(wide) - len(full)
    groups_of = full.index.get_level_values("_group")
    names = _levels(set(groups_of))
    k, n, g = len(levels), len(full), len(names)
    sizes = [int((groups_of == name).sum()) for name in names]
    if g < 2 or k < 2 or min(sizes) < 2:
        return {"why": f"no split-plot ANOVA: {g} group(s) with participants answering at all {k} levels "
                       f"({', '.join(f'{name}: {s}' for name, s in zip(names, sizes))}; needs >= 2 in each)",
                "left_out": left_out}
    # Orthonormal contrasts of the k levels (the columns of Q orthogonal to the constant).
    basis = np.linalg.qr(np.column_stack([np.ones(k), np.eye(k)[:, :k - 1]]))[0][:, 1:]
    z = full.to_numpy(float) @ basis
    grand = z.mean(axis=0)
    ss_between, resid = 0.0, []
    for name in names:
        zg = z[np.asarray(groups_of == name)]
        ss_between += len(zg) * float(np.sum((zg.mean(axis=0) - grand) ** 2))
        resid.append(zg - zg.mean(axis=0))
    resid = np.vstack(resid)
    ss_within = float(np.sum(resid ** 2))
    df1, df2 = (g - 1) * (k - 1), (n - g) * (k - 1)
    if ss_within <= 0:
        return {"why": "no split-plot ANOVA: the participants' profiles do not vary within the groups",
                "left_out": left_out}
    f_stat = (ss_between / df1) / (ss_within / df2)
    cov = resid.T @ resid / (n - g)
    eps = float(np.trace(cov) ** 2 / ((k - 1) * np.trace(cov @ cov))) if k > 2 else 1.0
    return {"F": f_stat, "df1": df1, "df2": df2, "p_uncorrected": float(sps.f.sf(f_stat, df1, df2)),
            "epsilon": eps, "p": float(sps.f.sf(f_stat, eps * df1, eps * df2)), "participants": n,
            "left_out": left_out, "why": ""}


def _p_words(p):
    return study_tests.p_text(p)


def _holm(values):
    """Holm over the finite p-values of a list (NaN stays NaN)."""
    values = list(values)
    finite = [i for i, p in enumerate(values) if isinstance(p, (int, float)) and math.isfinite(p)]
    out = [math.nan] * len(values)
    for i, q in zip(finite, stats.holm([values[i] for i in finite]) if finite else []):
        out[i] = q
    return out


def charts(m, kind, design, slug, note, what):
    """The interaction and per-level tables of rows m (one study with a between-subject group). Returns ([Chart],
    words for the summary)."""
    group = design.group
    family = FAMILY.get(kind)
    factors = [f for f in design.factors if f != group]
    if family is None or not factors:
        words = ("no group x factor model: " + ("an adaptive procedure sets the share correct; compare the groups' "
                                                "thresholds per cell in the tracks tables" if family is None else
                                                "no factor varies within participants"))
        return [Chart(f"{slug}-groups-interaction", None, None, None, [words])], ""
    column = "y" if family == "glmm" else "value"
    scale = "log-odds (group a - group b)" if family == "glmm" else f"{what} (group a - group b)"
    inter, per_level, findings = [], [], []
    for f in factors:
        others = [o for o in factors if o != f]
        r = fit(m, column, f, group, others, family)
        rhs = f"{group} * {f}" + "".join(f" + {o}" for o in others)
        model = (f"{'glmer' if family == 'glmm' else 'lmer'}({column} ~ {rhs} + "
                 f"{r['random'] or 'a random part by participant'}) against {group} + {f}" +
                 "".join(f" + {o}" for o in others))
        row = {"factor": f, "model": model, "term": f"{group} x {f} interaction (does the groups' difference change "
                                                    f"across the levels of {f}?)",
               "statistic": math.nan, "df": math.nan, "df2": math.nan, "p": math.nan, "engine": r["engine"],
               "random": r["structure"]}
        if r["test"]:
            t = r["test"]
            row.update(statistic=t["statistic"], df=t["df"], df2=t["df2"], p=t["p"])
            if family == "glmm":
                stat = f"likelihood-ratio chi2({t['df']:.0f}) = {t['statistic']:.2f}"
            else:
                stat = f"Kenward-Roger F({t['df']:.0f}, {t['df2']:.1f}) = {t['statistic']:.2f}" \
                    if math.isfinite(t["df2"]) else f"likelihood-ratio chi2({t['df']:.0f}) = {t['statistic']:.2f}"
            row["says"] = f"{stat}, {_p_words(t['p'])}"
            findings.append(f"group x {f} by the mixed model: {row['says']}")
        else:
            row["says"] = r["why"]
            findings.append(f"group x {f} by the mixed model: not determined (why: {slug}-groups-interaction)")
        inter.append(row)
        sp = split_plot(m, column, f, group)
        unit = "share" if family == "glmm" else "mean"
        row = {"factor": f, "model": f"aov({unit} ~ {group} * {f} + Error(participant / {f})), one {unit} per "
                                     f"participant per level" + (f", pooled over {', '.join(others)}" if others else ""),
               "term": row["term"], "statistic": sp.get("F", math.nan), "df": sp.get("df1", math.nan),
               "df2": sp.get("df2", math.nan), "p": sp.get("p", math.nan),
               "engine": "split-plot ANOVA, Greenhouse-Geisser (participants as the unit; scipy)",
               "random": "participants as the unit"}
        if sp["why"]:
            row["says"] = sp["why"]
        else:
            row["says"] = (f"F({sp['df1']}, {sp['df2']}) = {sp['F']:.2f}, Greenhouse-Geisser epsilon "
                           f"{sp['epsilon']:.2f}: {_p_words(sp['p'])} (uncorrected {_p_words(sp['p_uncorrected'])}), "
                           f"{sp['participants']} participants")
            findings.append(f"group x {f} with participants as the unit (split-plot ANOVA): {row['says']}")
        if sp["left_out"]:
            row["says"] += f"; {sp['left_out']} participant(s) without an answer at every level left out"
        inter.append(row)
        model_rows = r["contrasts"]
        part = per_level_participants(m, column, f, group)
        for _, pr in part.iterrows():
            out = {"factor": f, "level": pr["level"], "contrast": f"group {pr['group_a']} - group {pr['group_b']}"}
            hit = model_rows[(model_rows["level"] == pr["level"]) & (model_rows["group_a"] == pr["group_a"]) &
                             (model_rows["group_b"] == pr["group_b"])] if len(model_rows) else model_rows
            emm = r["emmeans"]
            for side in ("a", "b"):  # each group's estimate at the level (a probability for a 0/1 measure)
                at = emm[(emm["level"] == pr["level"]) & (emm["group"] == pr[f"group_{side}"])] if len(emm) else emm
                out[f"model_{'prob' if family == 'glmm' else 'mean'}_{side}"] = \
                    float(at["estimate"].iloc[0]) if len(at) else math.nan
            if len(hit):
                h = hit.iloc[0]
                out.update(model_estimate=h["estimate"], model_se=h["se"], model_df=h["df"], model_p=h["p"],
                           model_says="emmeans from the model with the interaction" +
                                      (" (Wald z against t(G - groups))" if family == "glmm" else
                                       " (Satterthwaite df)") + (f"; {h['says']}" if h["says"] else ""))
            else:
                out.update(model_estimate=math.nan, model_se=math.nan, model_df=math.nan, model_p=math.nan,
                           model_says=r.get("missing") or r["why"] or "not determined: no contrast from the model")
            out.update(participants_a=pr["n_a"], participants_b=pr["n_b"], mean_a=pr["mean_a"], mean_b=pr["mean_b"],
                       participant_difference=pr["difference"], welch_t=pr["t"], welch_df=pr["df"], welch_p=pr["p"],
                       welch_says=pr["test"])
            per_level.append(out)
    inter_t = pd.DataFrame(inter)
    level_t = pd.DataFrame(per_level)
    if not level_t.empty:
        level_t["model_p_holm"] = np.nan
        level_t["welch_p_holm"] = np.nan
        for f in factors:
            sel = level_t["factor"] == f
            level_t.loc[sel, "model_p_holm"] = _holm(level_t.loc[sel, "model_p"])
            level_t.loc[sel, "welch_p_holm"] = _holm(level_t.loc[sel, "welch_p"])
        for f in factors:
            for source, words in (("model", "model"), ("welch", "participants as the unit, Welch")):
                sel = level_t[(level_t["factor"] == f) & (level_t[f"{source}_p_holm"] < 0.05)]
                if len(sel):
                    pairs = level_t["contrast"].nunique() > 1  # more than two groups: say which pair
                    findings.append(f"groups differ ({words}, Holm) at {f} " + ", ".join(
                        f"{r['level']} ({r['contrast'] + ', ' if pairs else ''}{_p_words(r[f'{source}_p_holm'])})"
                        for _, r in sel.iterrows()))
    inter_notes = [f"{note}: the group x within-factor interaction (does the groups' difference change across the "
                   f"factor's levels?), two ways: the mixed model with it against the same model without it, "
                   f"participants as random effects (the random part fitted is in `random`; "
                   + ("a binomial GLMM of '" + what + "', likelihood-ratio chi-square" if family == "glmm" else
                      "a linear mixed model of the " + what + ", Kenward-Roger F (pbkrtest)") +
                   "; a fit that failed, did not converge or was singular in every random part says 'not "
                   "determined'), and with participants as the unit, the split-plot ANOVA of each participant's "
                   "value per level (Greenhouse-Geisser p)"]
    level_notes = [f"{note}: the groups' difference at each level of the factor, two ways: model_* from the mixed "
                   f"model with the interaction by emmeans ({scale}; model_{'prob' if family == 'glmm' else 'mean'}"
                   f"_a/_b: each group's estimate at the level, a typical participant's), welch_* with participants "
                   f"as the unit (each "
                   f"participant's {'share' if family == 'glmm' else 'mean'} at that level, Welch's t between the "
                   f"groups); *_p_holm: Holm-adjusted over the levels (and pairs of groups) of one factor"]
    return [Chart(f"{slug}-groups-interaction", None, None, inter_t, inter_notes),
            Chart(f"{slug}-groups-per-level", None, None, level_t, level_notes)], "; ".join(findings)
