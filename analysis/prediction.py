"""Observed against predicted: real participants beside what blurcue's simulated observer would answer to the same
trials, per condition, so an experimenter sees where people depart from the model.

The model (src/procedure/observer.h) is implemented here independently. Each session is predicted with the parameters
it recorded (trials.csv's observer_params, session::ToString(ObserverParams): "sim:model=arcmin,intrinsic=0.6,...";
"sim:jnd=..." from before model= existed is the pixel model); a person's session records none and is predicted with
the model's defaults (model=arcmin, DEFAULTS), and the chart says which it used.
model=arcmin reads the radii the export writes in visual angle (r_left_arcmin, r_right_arcmin, r_scene_arcmin;
blurcue's radius r is twice the line-spread function's std, so the literature's Gaussian s = r / 2). A blur is seen as
E(s) = (s^p + s_i^p)^(1/p); a comparison of two blurs has noise sd = ln(1 + weber) / z75 on ln E, so a 2AFC "which is
more blurred?" is right with probability Phi(z75 |ln E(a) - ln E(b)| / ln(1 + weber)) (ProbabilityCorrect2afc in the
C++; tests/data/observer-2afc.csv holds values both implementations must give). model=pixel reads the photo px radii
(r_left_px, ...): the seen blur is r itself and sd = jnd. Per trial:
  procedure / more blurred (a procedure's or 2IFC's question): left when S(left) - S(right) + side sd + sd N(0, 1) > 0
      (side: the arcmin model's side bias, 0 for pixel); P(correct) = lapse / 2 + (1 - lapse) P(the test side chosen)
  "which fits the scene?" (a pair): mismatch m = |S(side) - S(scene)| per side; D = m_right - m_left + bias + sd N(0, 1),
      bias = sd (blurrier x sign(r_left - r_right) + side) (pixel: bias_px x sign); left when D > c, right when D < -c,
      else can't tell (c = sd / 2 with a can't-tell key, 0 without); a lapse answers uniformly among the choices.
The measure is the one the study's own analysis reports (any_study.py): a pair - chose the more blurred side among
decisive answers between unequal radii; a procedure - correct. The predicted share of a condition is the mean of its
trials' predicted probabilities. A condition departs when the exact two-sided binomial test of its k of n against
that share, Holm-adjusted over the conditions of its chart (the cells compared), gives p < 0.05; the binomial is
conservative for trials of unequal probabilities (their count's variance is at most n p (1 - p)). The 95 % Wilson
interval is drawn, not tested.
"""
import math
import re

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
from scipy.stats import norm

import stats
from common import Chart, Skip, error_bars, factor_label, file_stem, participants_note, save, text

Z75 = 0.6744897501960817  # Phi^-1(0.75)
# The C++ model's defaults (procedure/observer.h ObserverParams, model=arcmin).
DEFAULTS = {"intrinsic_arcmin": 0.6, "weber": 0.35, "exponent": 2.0, "side_bias": 0.0, "blurrier_bias": 0.3,
            "lapse": 0.04}
# model=pixel's defaults, and each parameter's name in the recorded spec (procedure/observer.cc ParseObserver).
PIXEL_DEFAULTS = {"jnd_px": 0.6, "bias_px": 0.2, "lapse": 0.04}
SPEC_NAMES = {"intrinsic": "intrinsic_arcmin", "weber": "weber", "exponent": "exponent", "side": "side_bias",
              "blurrier": "blurrier_bias", "lapse": "lapse", "jnd": "jnd_px", "bias": "bias_px"}
PIXEL_ONLY = {"jnd", "bias", "cutoff1m", "slope", "sdlog", "tol"}
ALPHA = 0.05  # a condition departs when its Holm-adjusted p is below this


def observer_params(spec):
    """The model and parameters a session recorded (observer_params): {"model": "arcmin" | "pixel", ...} with the
    defaults of its model for what the spec does not name; a person's empty spec, or one that is not a simulated
    observer's, gives the arcmin model's defaults. Names the model does not predict with (rt, step, ...) are left out.
    ValueError for a value that is not a number."""
    spec = "" if spec is None or (isinstance(spec, float) and math.isnan(spec)) else str(spec).strip()
    items = []
    if spec.startswith("sim:"):
        for item in spec[4:].split(","):
            name, _, value = item.partition("=")
            items.append((name.strip(), value.strip()))
    named = dict(items)
    model = named.get("model") or ("pixel" if any(n in PIXEL_ONLY for n, _ in items) else "arcmin")
    out = {"model": model, **(PIXEL_DEFAULTS if model == "pixel" else DEFAULTS)}
    for name, value in items:
        key = SPEC_NAMES.get(name)
        if key in out:
            out[key] = float(value)
    return out


def params_words(p):
    """'model=arcmin, intrinsic_arcmin 0.6, ...': the parameters a prediction used."""
    return f"model={p['model']}, " + ", ".join(f"{k} {v:g}" for k, v in p.items() if k != "model")


def log_seen(s_arcmin, p=DEFAULTS):
    """ln E(s), E(s) = (s^p + s_i^p)^(1/p), for a Gaussian blur std s (arcmin; negative taken as 0)."""
    s = np.maximum(np.asarray(s_arcmin, float), 0.0)
    e, si = p["exponent"], p["intrinsic_arcmin"]
    return np.log(s ** e + si ** e) / e


def compare_sd(p=DEFAULTS):
    return math.log1p(p["weber"]) / Z75


def p_correct_2afc(r_a_arcmin, r_b_arcmin, p=DEFAULTS):
    """The probability of telling radii a and b (arcmin, blurcue's r) apart in a 2AFC, no lapse or bias."""
    d = np.abs(log_seen(np.asarray(r_a_arcmin, float) / 2, p) - log_seen(np.asarray(r_b_arcmin, float) / 2, p))
    return norm.cdf(d / compare_sd(p))


def match_choice(level_r_arcmin, real_r_arcmin, p=DEFAULTS, steps=4000):
    """Depth matching: the probability that the observer takes each level, levels' blurs and the real picture's
    (arcmin, blurcue's r). It compares every level once with the real picture, |D_i| with D_i = ln E(level i) -
    ln E(real) + sd N(0, 1), and takes the smallest: P_i = integral f_i(x) prod_(j != i) (1 - F_j(x)) dx over x >= 0,
    |D_j| folded normal (SimulatedObserver::Adjust; no lapse there). Simpson's rule on [0, max |mu| + 10 sd]."""
    sd = compare_sd(p)
    mu = log_seen(np.asarray(level_r_arcmin, float) / 2, p) - log_seen(float(real_r_arcmin) / 2, p)
    top = float(np.max(np.abs(mu))) + 10 * sd
    x = np.linspace(0, top, steps + 1)
    w = np.full(x.size, 2.0)
    w[1::2] = 4.0
    w[0] = w[-1] = 1.0
    w *= (top / steps) / 3
    z_hi, z_lo = (x[None, :] - mu[:, None]) / sd, (-x[None, :] - mu[:, None]) / sd
    survive = 1 - (norm.cdf(z_hi) - norm.cdf(z_lo))          # P(|D_j| > x), per level
    density = (norm.pdf(z_hi) + norm.pdf(z_lo)) / sd          # the density of |D_i| at x
    log_all = np.sum(np.log(np.maximum(survive, 1e-300)), axis=0)
    others = np.exp(log_all[None, :] - np.log(np.maximum(survive, 1e-300)))
    return np.sum(density * others * w[None, :], axis=1)


def _seen_and_sd(p):
    """The model's seen blur of a radius (arcmin radii for model=arcmin, photo px for pixel) and its comparison sd."""
    if p.get("model", "arcmin") == "pixel":
        return (lambda r: np.asarray(r, float)), p["jnd_px"]
    return (lambda r: log_seen(np.asarray(r, float) / 2, p)), compare_sd(p)


def p_choose_left_blurrier(r_left, r_right, p=DEFAULTS):
    """'Which is more blurred?' without the lapse: P(left) = Phi((S(left) - S(right)) / sd + side) (radii in the
    model's unit; side: the arcmin model's side bias, none for pixel)."""
    t, sd = _seen_and_sd(p)
    side = p.get("side_bias", 0.0) if p.get("model", "arcmin") == "arcmin" else 0.0
    return norm.cdf((t(r_left) - t(r_right)) / sd + side)


def pair_choice(r_left, r_right, r_scene, cant_tell=True, p=DEFAULTS):
    """'Which fits the scene?': probabilities of left, right and can't tell (arrays of radii: arcmin for
    model=arcmin, photo px for pixel)."""
    t, sd = _seen_and_sd(p)
    m_left, m_right = np.abs(t(r_left) - t(r_scene)), np.abs(t(r_right) - t(r_scene))
    more = np.sign(np.asarray(r_left, float) - np.asarray(r_right, float))
    bias = p["bias_px"] * more if p.get("model", "arcmin") == "pixel" else \
        sd * (p["blurrier_bias"] * more + p["side_bias"])
    mu = m_right - m_left + bias
    c = sd / 2 if cant_tell else 0.0
    lapse, k = p["lapse"], 3 if cant_tell else 2
    left = lapse / k + (1 - lapse) * norm.cdf((mu - c) / sd)
    right = lapse / k + (1 - lapse) * norm.cdf((-mu - c) / sd)
    return left, right, 1 - left - right


def _num(series):
    return pd.to_numeric(series.astype(str).replace({"": np.nan, "nan": np.nan}), errors="coerce")


def predicted(d):
    """Per answered pair or procedure row: y (observed 0/1) and predicted (the model's probability of y = 1) from the
    parameters the row's session recorded (observer_params; a person's: the defaults), with kind and model (the
    parameters used, in words); rows the model does not cover are dropped."""
    a = d[(d["status"] == "answered") & (d["task"] == "forced_choice")].copy()
    empty = a.iloc[0:0].assign(y=[], predicted=[], kind=[], model=[])
    if a.empty or "r_left_arcmin" not in a:
        return empty
    specs = text(a["observer_params"]) if "observer_params" in a else pd.Series("", index=a.index)
    # Whether a study offers can't tell is in its protocol, not its table: taken as offered when anyone used it.
    offers = a.groupby("study")["chosen_side"].transform(lambda c: (c == "cant_tell").any())
    out = []
    for spec, rows in a.groupby(specs, sort=True):
        try:
            p = observer_params(spec)
            said = "" if spec.startswith("sim") else " (no recorded parameters: the defaults)"
        except ValueError:  # not written by blurcue's ToString: said, and predicted with the defaults
            p, said = observer_params(""), f" (recorded {spec!r} unreadable: the defaults)"
        words = params_words(p) + said
        unit = "px" if p["model"] == "pixel" else "arcmin"
        part = _predicted_with(rows, p, unit, offers)
        if len(part):
            out.append(part.assign(model=words))
    if not out:
        return empty
    return pd.concat(out).dropna(subset=["y", "predicted"])


def _predicted_with(a, p, unit, offers):
    """predicted() for rows of one set of parameters; radii read in the model's unit (r_left_arcmin or r_left_px)."""
    def radius(side):
        column = f"r_{side}_{unit}"
        return _num(a[column]) if column in a else pd.Series(np.nan, index=a.index)
    rl, rr, rs = radius("left"), radius("right"), radius("scene")
    procedure = _num(a["level"]).notna() if "level" in a else pd.Series(False, index=a.index)
    odd = text(a["chosen_interval"]).ne("") if "chosen_interval" in a else pd.Series(False, index=a.index)
    out = []
    # A procedure's trial: correct = chose the test side (test_side; where not recorded, the more blurred one).
    pr = a[procedure & ~odd & rl.notna() & rr.notna()].copy()
    if len(pr):
        left = p_choose_left_blurrier(rl[pr.index], rr[pr.index], p)
        test = text(pr["test_side"]) if "test_side" in pr else pd.Series("", index=pr.index)
        test_left = np.where(test.isin(["left", "right"]), test == "left", (rl[pr.index] > rr[pr.index]).to_numpy())
        pr["predicted"] = p["lapse"] / 2 + (1 - p["lapse"]) * np.where(test_left, left, 1 - left)
        pr["y"] = _num(pr["correct"])
        pr["kind"] = "procedure: correct"
        out.append(pr)
    # A pair: chose the more blurred side, among decisive answers between unequal radii.
    pa = a[~procedure & ~odd & a["chosen_side"].isin(["left", "right"]) & rl.notna() & rr.notna() & rs.notna() &
           ((rl - rr).abs() > 1e-9)].copy()
    if len(pa):
        left, right, _ = pair_choice(rl[pa.index], rr[pa.index], rs[pa.index], cant_tell=False, p=p)
        left_c, right_c, _ = pair_choice(rl[pa.index], rr[pa.index], rs[pa.index], cant_tell=True, p=p)
        with_cant = offers[pa.index].to_numpy(bool)
        left, right = np.where(with_cant, left_c, left), np.where(with_cant, right_c, right)
        left_blurrier = (rl[pa.index] > rr[pa.index]).to_numpy()
        pa["predicted"] = np.where(left_blurrier, left, right) / (left + right)
        pa["y"] = _num(pa["chose_more_blurred"])
        pa["kind"] = "pair: chose the more blurred side"
        out.append(pa)
    return pd.concat(out) if out else a.iloc[0:0].assign(y=[], predicted=[], kind=[])


def condition_table(m, factors):
    import any_study
    keys = None if not factors else factors[0] if len(factors) == 1 else factors
    groups = m.groupby(keys, dropna=False) if keys else [((), m)]
    rows = []
    for key, g in groups:
        key = key if isinstance(key, tuple) else (key,)
        row = {f: any_study._label(v) for f, v in zip(factors, key)}
        n, k = len(g), int(g["y"].sum())
        share, lo, hi = stats.wilson(k, n)
        pred = float(g["predicted"].mean())
        row.update(n=n, k=k, observed=share, observed_low=lo, observed_high=hi, predicted=pred,
                   p=stats.binom_p(k, n, min(max(pred, 0.0), 1.0)), participants=g["participant"].nunique())
        rows.append(row)
    t = pd.DataFrame(rows)
    # The conditions of one chart are compared at once: Holm over them, so that 20 conditions do not flag one by chance.
    t["p_holm"] = stats.holm(t["p"].to_numpy(float)) if len(t) else []
    t["departs"] = [bool(q < ALPHA) for q in t["p_holm"]] if len(t) else []
    return t


def charts(df, out_dir, codebook, pool_simulated=False):
    """One chart and table per study and measure (people and simulated observers apart unless pooled), and per
    between-subject group: each group saw other conditions, so its rows are never pooled with another's."""
    import any_study
    from design import design_of
    d = df[df["practice"] != 1]
    m_all = predicted(d)
    if m_all.empty:
        raise Skip("no answered forced-choice trial with radii in arcmin (r_left_arcmin, r_right_arcmin): nothing "
                   "to predict")
    out = []
    for (study, kind), m in m_all.groupby(["study", "kind"]):
        kinds = ["all"] if pool_simulated else sorted(set(m["observer"]))
        for who in kinds:
            part = m if who == "all" else m[m["observer"] == who]
            label = "all" if who == "all" else ("people" if who == "person" else "simulated observers")
            # The study's name as its own stem (common.file_stem: "pilot 1" and "pilot/1" apart), then our words.
            slug = file_stem(study, 48) + re.sub(r"[^A-Za-z0-9_-]", "_",
                                                 f"-predicted-{kind.split(':')[0]}-{label.split()[0]}")
            group = design_of(part, codebook).group
            if not group:
                out.append(_chart(part, any_study.design_factors(part, codebook), study, kind, label, slug,
                                  out_dir))
                continue
            for level in any_study._sorted_levels(list(part[group].astype(str).unique())):
                rows = part[part[group].astype(str) == level]
                out.append(_chart(rows, any_study.design_factors(rows, codebook), study, kind,
                                  f"{label}, group {level}", f"{slug}-group-{file_stem(level, 32)}", out_dir))
    return out


def _chart(part, factors, study, kind, label, slug, out_dir):
    """The observed-vs-predicted chart and table of one set of rows (one study, measure, observer kind, group)."""
    t = condition_table(part, factors)
    fig, ax = plt.subplots(figsize=(max(5.0, 0.6 * len(t) + 3), 3.8))
    x = np.arange(len(t))
    ax.bar(x, t["observed"], 0.6, color="#0072B2", edgecolor="white", label="observed (95 % Wilson)")
    ax.errorbar(x, t["observed"], yerr=error_bars(t["observed"], t["observed_low"], t["observed_high"]),
                fmt="none", ecolor="#333333", lw=0.9)
    ax.plot(x, t["predicted"], "D", color="#D55E00", ms=6, label="the observer model predicts")
    for xi, dep in zip(x, t["departs"]):
        if dep:
            ax.text(xi, 1.04, "!", ha="center", va="bottom", color="#D55E00", fontsize=11, fontweight="bold")
    labels = [" ".join(str(r[f]) for f in factors) or "all" for _, r in t.iterrows()]
    ax.set_xticks(x)
    ax.set_xticklabels(labels, rotation=45 if len(labels) > 8 else 0, ha="right" if len(labels) > 8 else "center")
    ax.set_xlabel(", ".join(factor_label(f) for f in factors) or "all trials")
    ax.set_ylim(0, 1.12)
    ax.set_ylabel(f"share: {kind.split(': ')[1]}")
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0))
    ax.set_title(f"{study}: observed vs predicted ({label}, {participants_note(part)})", loc="left")
    png, svg = save(fig, out_dir, slug)
    departs = int(t["departs"].sum())
    used = sorted(set(part["model"])) if "model" in part else [params_words(observer_params(""))]
    notes = [f"{label}: {kind} per condition; bars observed with 95 % Wilson intervals, diamonds the "
             f"simulated observer's prediction for the same trials, each session with the parameters it recorded "
             f"({'; '.join(used)}); ! where the exact binomial test of the observed count against the prediction, "
             f"Holm-adjusted over the {len(t)} conditions, gives p < {ALPHA:g}",
             f"{departs} of {len(t)} conditions depart from the model (Holm over {len(t)})"]
    return Chart(slug, png, svg, t, notes)
