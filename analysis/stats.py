"""Statistics for the blurcue analyses: proportions, tests against chance, psychometric fits, models across observers.

Everything here works on plain numbers / arrays / DataFrames and draws nothing, so the tests can check it against
hand-computed answers.
"""
import math
import warnings
from dataclasses import dataclass, field

import numpy as np
import pandas as pd
from scipy import optimize, special
from scipy import stats as sps

Z95 = sps.norm.ppf(0.975)  # 1.959963984540054


# --------------------------------------------------------------------------------------------------------------------
# Proportions


def wilson(k, n, conf=0.95):
    """Wilson score interval for k successes of n: (proportion, low, high); NaNs when n == 0.

    Preferred to the Wald interval because it stays inside [0, 1] and keeps its coverage at k = 0 or k = n and at the
    small counts a psychophysics cell has (10-20 answers).
    """
    if n <= 0:
        return (math.nan, math.nan, math.nan)
    z = sps.norm.ppf(0.5 + conf / 2)
    p = k / n
    denom = 1 + z * z / n
    centre = (p + z * z / (2 * n)) / denom
    half = z / denom * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n))
    # At k = 0 and k = n the bound is exactly 0 or 1 (the closed form leaves rounding dust such as 2.8e-17).
    lo = 0.0 if k == 0 else max(0.0, centre - half)
    hi = 1.0 if k == n else min(1.0, centre + half)
    return (p, lo, hi)


def binom_p(k, n, p=0.5):
    """Exact two-sided binomial test of k of n against probability p (scipy's 'minlike' two-sided rule); NaN if n == 0."""
    if n <= 0:
        return math.nan
    return float(sps.binomtest(int(k), int(n), p, alternative="two-sided").pvalue)


def holm(pvalues):
    """Holm step-down adjustment of a list of p-values (NaNs pass through untouched)."""
    p = np.asarray(pvalues, dtype=float)
    out = np.full_like(p, np.nan)
    ok = ~np.isnan(p)
    m = int(ok.sum())
    if m == 0:
        return out
    idx = np.where(ok)[0]
    order = idx[np.argsort(p[idx])]
    running = 0.0
    for rank, i in enumerate(order):
        running = max(running, min(1.0, (m - rank) * p[i]))
        out[i] = running
    return out


# --------------------------------------------------------------------------------------------------------------------
# Psychometric functions: psi(x) = gamma + (1 - gamma - lam) * F(x; alpha, beta)
#   logistic: F = 1 / (1 + exp(-(x - alpha) / beta))   alpha = 50 % point of F, beta = spread (> 0)
#   weibull:  F = 1 - exp(-(x / alpha) ** beta), x >= 0  alpha = 63 % point of F, beta = shape (> 0)
# gamma is the guess rate (the floor), lam the lapse rate (1 - lam is the ceiling).
#
# beta is bounded: with stimulus levels in clusters, the likelihood keeps rising as the curve turns into a step that
# falls between (or inside) clusters, and the ML fit runs off to beta -> 0 (logistic) or beta -> inf (Weibull).
# Such a step is not a finding - the data cannot tell a transition much sharper than the level spacing from an
# instant one, and no observer discriminates blur perfectly on one side of a value and not at all on the other. So:
#   logistic: beta >= span of the levels / 50 (10-90 % of F then spans >= ~9 % of the tested range)
#   Weibull:  beta <= 10 (10-90 % of F then spans >= ~29 % of alpha)
# A fit that ends on a bound says so (PsychometricFit.on_bound).

KINDS = ("logistic", "weibull")
LOGISTIC_MIN_SPREAD = 1 / 50   # of the span of the stimulus levels
WEIBULL_MAX_SHAPE = 10.0


def default_beta_bounds(kind, x):
    """(low, high) allowed for beta, given the stimulus levels x (see above)."""
    x = np.asarray(x, float)
    if kind == "logistic":
        span = float(x.max() - x.min()) if len(x) else 0.0
        return (LOGISTIC_MIN_SPREAD * (span or 1.0), math.inf)
    return (0.0, WEIBULL_MAX_SHAPE)


def core(kind, x, alpha, beta):
    x = np.asarray(x, dtype=float)
    if kind == "logistic":
        return special.expit((x - alpha) / beta)
    if kind == "weibull":
        # (x/alpha)^beta overflows to inf for far-out trial parameters; exp(-inf) = 0 is then the right answer.
        with np.errstate(over="ignore"):
            return -np.expm1(-np.power(np.clip(x, 0, None) / alpha, beta))
    raise ValueError(f"unknown psychometric function {kind!r}")


def psi(kind, x, alpha, beta, gamma, lam):
    return gamma + (1 - gamma - lam) * core(kind, x, alpha, beta)


@dataclass
class PsychometricFit:
    kind: str
    alpha: float
    beta: float
    gamma: float
    lam: float
    nll: float        # negative log-likelihood at the optimum (binomial, without the constant)
    n_params: int     # free parameters
    n_trials: int
    converged: bool
    options: dict = field(default_factory=dict)  # the gamma / lam / beta_bounds arguments of the fit, for refits
    ci: dict = field(default_factory=dict)   # parameter -> (low, high), filled by bootstrap()

    @property
    def aic(self):
        return 2 * self.n_params + 2 * self.nll

    @property
    def on_bound(self):
        """Fitted parameters that ended on a bound of their range: {name: (bound value, 'lower' or 'upper')}."""
        out = {}
        ranges = {"beta": self.options.get("beta_bounds")}
        if not np.isscalar(self.options.get("lam", 0.0)):
            ranges["lam"] = self.options["lam"]
        for name, bounds in ranges.items():
            if bounds is None:
                continue
            lo, hi = bounds
            v = getattr(self, name)
            tol = 1e-3 * max(abs(lo), abs(hi) if math.isfinite(hi) else 0.0, 1e-6)
            if v <= lo + tol:
                out[name] = (lo, "lower")
            elif math.isfinite(hi) and v >= hi - tol:
                out[name] = (hi, "upper")
        return out

    def __call__(self, x):
        return psi(self.kind, x, self.alpha, self.beta, self.gamma, self.lam)


def _aggregate(x, k, n):
    """Sum k and n over equal x (faster likelihoods, same fit)."""
    levels, inverse = np.unique(np.asarray(x, float), return_inverse=True)
    return (levels, np.bincount(inverse, weights=np.asarray(k, float), minlength=len(levels)),
            np.bincount(inverse, weights=np.asarray(n, float), minlength=len(levels)))


def _nll(p, k, n):
    p = np.clip(p, 1e-9, 1 - 1e-9)
    return -float(np.sum(k * np.log(p) + (n - k) * np.log1p(-p)))


def fit_psychometric(x, k, n=None, kind="weibull", gamma=0.5, lam=(0.0, 0.1), starts=None, beta_bounds=None):
    """Maximum-likelihood fit of psi to k successes of n at stimulus levels x.

    gamma: a number fixes the guess rate (0.5 for two alternatives); None fits it within [0, 0.95).
    lam:   a number fixes the lapse rate; a (low, high) pair fits it within those bounds.
    beta_bounds: (low, high) for beta; None takes default_beta_bounds(kind, x) (bootstrap refits pass the original's).
    starts: optional list of (alpha, beta) starting points; by default a small grid over the data's range, since the
    likelihood of a psychometric function has flat regions where a single start can stall.
    """
    if kind not in KINDS:
        raise ValueError(f"unknown psychometric function {kind!r}")
    n = np.ones_like(np.asarray(k, float)) if n is None else n
    x, k, n = _aggregate(x, k, n)
    if len(x) == 0 or n.sum() == 0:
        raise ValueError("no trials to fit")
    if kind == "weibull" and np.any(x < 0):
        raise ValueError("the Weibull function needs stimulus levels >= 0")
    fit_gamma = gamma is None
    fit_lam = not np.isscalar(lam)
    lam_lo, lam_hi = (lam if fit_lam else (lam, lam))
    gamma_hi = 0.95
    b_lo, b_hi = beta_bounds if beta_bounds is not None else default_beta_bounds(kind, x)
    b_lo, b_hi = float(b_lo), float(b_hi)

    # beta in [b_lo, b_hi]: b_lo + exp(t) without an upper bound, else logit-scaled between the bounds.
    def beta_of(t):
        if math.isinf(b_hi):
            return b_lo + math.exp(min(t, 700.0))  # a search that runs off (all answers one way) stays finite
        return b_lo + (b_hi - b_lo) * special.expit(t)

    def t_of(b):
        if math.isinf(b_hi):
            return math.log(max(b - b_lo, 1e-9 * max(b_lo, 1.0)))
        f = min(max((b - b_lo) / (b_hi - b_lo), 1e-9), 1 - 1e-9)
        return float(special.logit(f))

    # Unconstrained coordinates: location (log for Weibull), bounded spread, logit-scaled gamma and lapse.
    def unpack(theta):
        i = 0
        a = math.exp(min(theta[i], 700.0)) if kind == "weibull" else theta[i]
        b = beta_of(theta[i + 1])
        i += 2
        g = gamma
        if fit_gamma:
            g = gamma_hi * special.expit(theta[i])
            i += 1
        l = lam
        if fit_lam:
            l = lam_lo + (lam_hi - lam_lo) * special.expit(theta[i])
        return a, b, g, l

    def objective(theta):
        a, b, g, l = unpack(theta)
        if g + l >= 1:
            return 1e12
        return _nll(psi(kind, x, a, b, g, l), k, n)

    span = float(x.max() - x.min()) or 1.0
    if starts is None:
        positive = x[x > 0]
        lo = float(positive.min()) if kind == "weibull" and len(positive) else float(x.min())
        hi = float(x.max()) if x.max() > lo else lo + 1
        alphas = np.linspace(lo + 0.15 * (hi - lo), hi, 4) if kind == "logistic" else np.geomspace(max(lo, 1e-3), hi, 4)
        betas = [span / 10, span / 4] if kind == "logistic" else [1.0, 3.0]
        starts = [(a, b) for a in alphas for b in betas]
    extra = ([0.0] if fit_gamma else []) + ([-2.0] if fit_lam else [])
    best = None
    for a0, b0 in starts:
        theta0 = [math.log(a0) if kind == "weibull" else a0, t_of(b0)] + extra
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            res = optimize.minimize(objective, theta0, method="Nelder-Mead",
                                    options={"xatol": 1e-6, "fatol": 1e-8, "maxiter": 4000, "maxfev": 8000})
        if best is None or res.fun < best.fun:
            best = res
    a, b, g, l = unpack(best.x)
    return PsychometricFit(kind=kind, alpha=a, beta=b, gamma=g, lam=l, nll=float(best.fun),
                           n_params=2 + int(fit_gamma) + int(fit_lam), n_trials=int(n.sum()),
                           converged=bool(best.success),
                           options={"gamma": gamma, "lam": lam, "beta_bounds": (b_lo, b_hi)})


def bootstrap(x, k, n, fit, method="parametric", n_boot=200, seed=0, grid=None, level=0.95, **fit_kwargs):
    """Percentile bootstrap of a psychometric fit; fills fit.ci and returns (grid, band_low, band_high).

    parametric: new k at every level drawn from Binomial(n, fitted psi), then refitted.
    nonparametric: the (x, k, n) rows resampled with replacement (pass one row per trial for a trial bootstrap).
    The generator is seeded, so the same data give the same intervals.
    """
    rng = np.random.default_rng(seed)
    x = np.asarray(x, float)
    k = np.asarray(k, float)
    n = np.asarray(n, float)
    grid = np.linspace(x.min(), x.max(), 100) if grid is None else np.asarray(grid, float)
    for key, value in fit.options.items():
        fit_kwargs.setdefault(key, value)
    # Refits start from the point estimate only: the bootstrap samples sit close to the data.
    fit_kwargs["starts"] = [(fit.alpha, fit.beta)]
    params, curves = [], []
    for _ in range(n_boot):
        if method == "parametric":
            xb, nb = x, n
            kb = rng.binomial(n.astype(int), np.clip(fit(x), 0, 1)).astype(float)
        elif method == "nonparametric":
            idx = rng.integers(0, len(x), len(x))
            xb, kb, nb = x[idx], k[idx], n[idx]
        else:
            raise ValueError(f"unknown bootstrap method {method!r}")
        try:
            fb = fit_psychometric(xb, kb, nb, kind=fit.kind, **fit_kwargs)
        except ValueError:
            continue
        params.append((fb.alpha, fb.beta, fb.gamma, fb.lam))
        curves.append(fb(grid))
    if not params:
        raise ValueError("every bootstrap sample failed to fit")
    params = np.array(params)
    curves = np.array(curves)
    q = [(1 - level) / 2 * 100, (1 + level) / 2 * 100]
    for i, name in enumerate(("alpha", "beta", "gamma", "lam")):
        lo, hi = np.percentile(params[:, i], q)
        fit.ci[name] = (float(lo), float(hi))
    lo, hi = np.percentile(curves, q, axis=0)
    return grid, lo, hi


def threshold(fit, p=0.75):
    """Stimulus level where psi reaches p (NaN when p is outside the fitted range)."""
    top = 1 - fit.lam
    if not fit.gamma < p < top:
        return math.nan
    f = (p - fit.gamma) / (top - fit.gamma)
    if fit.kind == "logistic":
        return fit.alpha + fit.beta * math.log(f / (1 - f))
    return fit.alpha * (-math.log(1 - f)) ** (1 / fit.beta)


# --------------------------------------------------------------------------------------------------------------------
# Models across observers


MIN_ANSWERS = 10        # fewer decisive answers than this: no model, a note instead
MIN_EACH_OUTCOME = 2    # and at least this many of each outcome (else the log-odds run off to infinity)
SEPARATION_LOGODDS = 10  # |log-odds| beyond this (odds 22000:1) from a GLM means separation, not an estimate


# What the model terms mean, in words, for the page (patsy's names are for programs): centred covariates by their
# centring, factors by level against their baseline.
CENTRED = {"edge_c": "per edge (edge centred at 6)", "section_c": "per section (section centred at 5.5)"}


def term_in_words(term, data):
    """'C(pattern_id)[1]' -> 'pattern_id 1'; 'C(edge, levels=[3, 6])[T.6]' -> 'edge 6 (against edge 3)';
    'Intercept' -> 'baseline (intercept)'; a centred covariate -> what one step of it means."""
    import re
    if term == "Intercept":
        return "baseline (intercept)"
    if term in CENTRED:
        return CENTRED[term]
    match = re.fullmatch(r"C\((\w+)(?:, levels=\[(.*)\])?\)\[(T\.)?(.+)\]", term)
    if not match:
        return term
    name, levels, treatment, level = match.groups()
    level = level[:-2] if level.endswith(".0") else level
    if not treatment:
        return f"{name} {level}"
    if levels:
        base = levels.split(",")[0].strip().strip("'\"")
    else:
        values = sorted(data[name].dropna().unique(), key=lambda v: (not isinstance(v, (int, float)), v)) \
            if name in data else []
        base = str(values[0]) if len(values) else "its first level"
    base = base[:-2] if base.endswith(".0") else base
    return f"{name} {level} (against {name} {base})"


def observer_models(data, response, formula_rhs, group="participant"):
    """Logistic models of a 0/1 response across observers; returns (table, notes).

    Two models where the data allow, one row per (model, term):
      - 'GLM, cluster-robust SE': a logistic GLM whose standard errors are clustered by observer, so repeated answers
        of one observer do not count as independent evidence (sandwich estimator; optimistic with < 5 observers).
      - 'GLMM (random intercept, VB)': statsmodels' BinomialBayesMixedGLM with a random intercept per observer, fitted
        by variational Bayes; estimate = posterior mean, se = posterior SD, p from the normal approximation. Its
        'observer SD' row is the posterior mean SD of the observers' intercepts (log-odds).
    With one observer only a plain logistic GLM is fitted (its SEs treat the answers as independent), and said so.
    """
    import statsmodels.api as sm
    import statsmodels.formula.api as smf
    from statsmodels.genmod.bayes_mixed_glm import BinomialBayesMixedGLM

    notes = []
    rows = []
    d = data.dropna(subset=[response]).copy()
    d[response] = d[response].astype(float)
    n = len(d)
    ones = int(d[response].sum())
    groups = d[group].astype(str)
    n_groups = groups.nunique()
    if n < MIN_ANSWERS or min(ones, n - ones) < MIN_EACH_OUTCOME:
        notes.append(f"no model across observers: {n} decisive answers ({ones} of one kind, {n - ones} of the other); "
                     f"needs >= {MIN_ANSWERS} with >= {MIN_EACH_OUTCOME} of each")
        return pd.DataFrame(rows), notes
    formula = f"{response} ~ {formula_rhs}"

    def add(model, term, est, se, note=""):
        z = est / se if se and se > 0 else math.nan
        p = 2 * sps.norm.sf(abs(z)) if not math.isnan(z) else math.nan
        rows.append({"model": model, "term": term, "estimate_logodds": est, "se": se, "z": z, "p": p,
                     "ci_low": est - Z95 * se, "ci_high": est + Z95 * se, "odds_ratio": math.exp(est)
                     if abs(est) < 700 else math.inf, "answers": n, "observers": n_groups, "note": note})

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            if n_groups >= 2:
                res = smf.glm(formula, d, family=sm.families.Binomial()).fit(
                    cov_type="cluster", cov_kwds={"groups": pd.factorize(groups)[0]})
                label = "GLM, cluster-robust SE"
                note = "few observers: robust SE optimistic" if n_groups < 5 else ""
            else:
                res = smf.glm(formula, d, family=sm.families.Binomial()).fit()
                label = "GLM (one observer)"
                note = "one observer: answers treated as independent"
                notes.append("one participant: no model across observers; plain logistic GLM instead")
            for term in res.params.index:
                est, se = float(res.params[term]), float(res.bse[term])
                if abs(est) > SEPARATION_LOGODDS:
                    # Every answer behind this term went one way: the ML estimate runs off to infinity and its SE
                    # means nothing. Say so rather than print a log-odds of 23.
                    rows.append({"model": label, "term": term, "answers": n, "observers": n_groups,
                                 "note": "separation: all answers one way, no finite estimate (see the binomial test)"})
                    continue
                add(label, term, est, se, note)
        except Exception as e:  # perfect separation, singular design: say so instead of a traceback
            notes.append(f"logistic GLM not fitted: {type(e).__name__}: {str(e).splitlines()[0] if str(e) else ''}")

        if n_groups >= 3:
            try:
                model = BinomialBayesMixedGLM.from_formula(formula, {"observer": f"0 + C({group})"}, d)
                vb = model.fit_vb()
                for i, term in enumerate(model.exog_names):
                    add("GLMM (random intercept, VB)", term, float(vb.fe_mean[i]), float(vb.fe_sd[i]))
                rows.append({"model": "GLMM (random intercept, VB)", "term": "observer SD",
                             "estimate_logodds": float(np.exp(vb.vcp_mean[0])), "answers": n, "observers": n_groups,
                             "note": "SD of observers' intercepts"})
            except Exception as e:
                notes.append(f"GLMM not fitted: {type(e).__name__}: {str(e).splitlines()[0] if str(e) else ''}")
        elif n_groups == 2:
            notes.append("two participants: too few for a random-intercept GLMM; cluster-robust GLM only")
    table = pd.DataFrame(rows)
    if not table.empty:
        table["term"] = [term_in_words(t, d) for t in table["term"]]
        notes += disagreements(table)
    return table, notes


def disagreements(table):
    """Where the GLM and the GLMM disagree on a term (one has no finite estimate, or one is significant at 0.05 and the
    other not), a note saying which to trust and why."""
    out = []
    glm = table[table["model"].str.startswith("GLM,") | table["model"].str.startswith("GLM (")]
    glmm = table[table["model"].str.startswith("GLMM")]
    for term in [t for t in glm["term"] if t in set(glmm["term"])]:
        a, b = glm[glm["term"] == term].iloc[0], glmm[glmm["term"] == term].iloc[0]
        separation = "separation" in str(a.get("note", ""))
        pa, pb = a.get("p", math.nan), b.get("p", math.nan)
        split = not separation and not (pd.isna(pa) or pd.isna(pb)) and (pa < 0.05) != (pb < 0.05)
        if separation or split:
            glm_text = "no finite estimate (every answer behind it went one way)" if separation else \
                ("p < 0.001" if pa < 0.001 else f"p = {pa:.3f}")
            glmm_text = "p < 0.001" if pb < 0.001 else f"p = {pb:.3f}"
            out.append(f"{term}: the GLM says {glm_text}, the GLMM {glmm_text} - trust the GLMM: it shrinks each "
                       f"participant's estimate toward the group, so it has an estimate where every answer of a cell "
                       f"went one way, and it does not count one participant's repeated answers as independent")
    return out
