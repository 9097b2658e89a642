"""Statistics for the blurcue analyses: proportions, tests against chance, psychometric fits (models across observers:
across_observers.py).

Everything here works on plain numbers / arrays / DataFrames and draws nothing, so the tests can check it against
hand-computed answers.
"""
import math
import warnings
from dataclasses import dataclass, field

import numpy as np
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
    if kind not in KINDS:
        raise ValueError(f"unknown psychometric function {kind!r}")
    # (x/alpha)^beta overflows to inf for far-out trial parameters; exp(-inf) = 0 is then the right answer.
    with np.errstate(over="ignore"):
        return _core(kind, np.maximum(x, 0.0) if kind == "weibull" else x, alpha, beta)


def _core(kind, x, alpha, beta):
    """core() on levels already checked (Weibull: x >= 0), without its per-call overhead: the fit's inner loop."""
    if kind == "logistic":
        return special.expit((x - alpha) / beta)
    return -np.expm1(-np.power(x / alpha, beta))


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
    refits: list = field(default_factory=list, repr=False)  # bootstrap()'s refitted PsychometricFits, for any quantity
    n_boot: int = 0                          # the samples bootstrap() drew (refits that failed are not in refits)

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


def _nll(p, k, misses):
    """Binomial negative log-likelihood (without the constant) of k hits and `misses` misses at probabilities p."""
    p = np.minimum(np.maximum(p, 1e-9), 1 - 1e-9)
    return -float((k * np.log(p) + misses * np.log1p(-p)).sum())


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

    x_core = np.maximum(x, 0.0) if kind == "weibull" else x
    misses = n - k

    def objective(theta):  # called some 400 times a fit: psi and _nll inlined on prepared arrays
        a, b, g, l = unpack(theta)
        if g + l >= 1:
            return 1e12
        return _nll(g + (1 - g - l) * _core(kind, x_core, a, b), k, misses)

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
        with warnings.catch_warnings(), np.errstate(over="ignore"):
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
    """Percentile bootstrap of a psychometric fit; fills fit.ci, fit.refits (every refit, so a derived quantity
    such as a threshold takes its interval from the same n_boot samples) and fit.n_boot, and returns (grid, band_low,
    band_high).

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
    fit.refits, fit.n_boot = [], n_boot
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
        fit.refits.append(fb)
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
