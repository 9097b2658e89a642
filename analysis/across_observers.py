"""Models across observers for the blurcue analyses: logistic GLMs with cluster-robust SEs and lme4's GLMMs (through
mixed.py), the separation found before any fit, and the model table every report draws (MODEL_COLUMNS).

Everything here works on plain numbers / arrays / DataFrames and draws nothing (split from stats.py, which keeps
proportions, tests against chance and psychometric fits).
"""
import math
import re
import warnings

import numpy as np
import pandas as pd
from scipy import stats as sps


MIN_ANSWERS = 10        # fewer decisive answers than this: no model, a note instead
MIN_PARTICIPANTS_MODEL = 3  # fewer (but more than one): no model across participants, said in words
MIN_EACH_OUTCOME = 2    # and at least this many of each outcome (else the log-odds run off to infinity)


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
    parts = _interaction_parts(term)
    if len(parts) > 1:  # 'C(a)[T.x]:C(b)[T.y]': how far that crossing departs from the two effects added
        inner = [re.sub(r" \(against .*\)$", "", term_in_words(p, data)) for p in parts]
        return " x ".join(inner) + " (interaction: beyond the effects added)"
    match = re.fullmatch(r"C\((\w+)(?:, levels=\[(.*)\])?\)\[(T\.)?(.+)\]", term)
    if not match:
        return term
    name, levels, treatment, level = match.groups()
    level = level[:-2] if level.endswith(".0") else level
    if not treatment:
        return f"{name} {level}"
    if levels:
        # The levels as patsy was given them (a Python list): a level may hold a comma ('naïve, µ'), which a split at
        # commas cut off (the baseline read 'label=naïve').
        import ast
        try:
            base = str(ast.literal_eval(f"[{levels}]")[0])
        except (ValueError, SyntaxError):
            base = levels.split(",")[0].strip().strip("'\"")
    else:
        values = sorted(data[name].dropna().unique(), key=lambda v: (not isinstance(v, (int, float)), v)) \
            if name in data else []
        base = str(values[0]) if len(values) else "its first level"
    base = base[:-2] if base.endswith(".0") else base
    return f"{name} {level} (against {name} {base})"


def _interaction_parts(term):
    """A patsy column name split at its ':' outside brackets and parentheses ('C(a)[T.x]:C(b)[T.y]' -> two parts;
    a level holding ':' stays whole)."""
    parts, depth, start = [], 0, 0
    for i, ch in enumerate(term):
        depth += 1 if ch in "([" else -1 if ch in ")]" else 0
        if ch == ":" and depth == 0:
            parts.append(term[start:i])
            start = i + 1
    return parts + [term[start:]]


# Every model table has these columns and no others: one row per (model, term), terms in words, the engine that
# fitted it, and a note where a value is missing or needs words (separation, a singular fit, a fallback).
MODEL_COLUMNS = ["study", "model", "term", "estimate", "se", "df", "p", "engine", "note"]
SEPARATION_NOTE = ("separation: every answer behind this term went one way, so it has no finite estimate and no p "
                   "(found by the linear program of Konis 2007, not by the size of a fit); see the binomial test of "
                   "its cell")


EMPTY_NOTE = ("not determined: no answers at this crossing (it was not shown, or nothing there was answered), so "
              "nothing estimates how far it departs from the effects added; no estimate, no p")


# A cluster-robust SE below this (log-odds) is 0 to rounding: a real one this small needs some 10^12 answers.
SE_ZERO = 1e-6


def zero_se_note(words, estimate):
    """Why a cluster-robust term with an SE of 0 (to rounding) gets no SE and no p, and with an estimate of 0 (to
    rounding) no estimate either, in words. The sandwich SE is the spread of the participants' pulls on a term; it is 0
    when no participant's answers pull the term from its estimate - as when, in each participant, its level's answers
    come out as its baseline's once the other terms are fitted (an estimate of 0 by construction, printed as digits
    such as -2e-15 that are rounding), or when the participants agree exactly. Its t is then rounding over rounding,
    and a p from it says nothing."""
    import re
    against = re.fullmatch(r"(.+) \(against (.+)\)", words)
    if abs(estimate) <= SE_ZERO:
        alike = (f"the answers at {against[1]} come out as those at {against[2]}" if against else
                 "the answers along this term come out as the other terms predict")
        return (f"not determined: no participant's answers pull it away from 0 (as when, in each participant, {alike} "
                f"once the other terms are fitted), so the estimate is 0 by construction and its cluster-robust SE 0 "
                f"- a fit prints rounding noise there, not an estimate; no estimate, no p (compare the shares of its "
                f"cells)")
    return ("SE not determined: no participant's answers pull it away from this estimate (as when every participant's "
            "answers alone give the same value), so its cluster-robust SE is 0 and a p would be rounding noise; no SE, "
            "no p")


def without_zero_se(table, words):
    """A cluster_robust() table with se, df and p blanked where the SE is 0 to rounding (or not a number: a variance
    rounded below 0), the estimate too where it is 0 to rounding; returns (table, {term: note in words})."""
    table = table.copy()
    notes = {}
    for i, r in table.iterrows():
        if math.isfinite(r["se"]) and r["se"] > SE_ZERO:
            continue
        notes[r["term"]] = zero_se_note(words.get(r["term"], r["term"]), r["estimate"])
        table.loc[i, ["se", "df", "p"]] = math.nan
        if abs(r["estimate"]) <= SE_ZERO:
            table.loc[i, "estimate"] = math.nan
    return table, notes


def model_row(study, model, term, estimate=math.nan, se=math.nan, df=math.nan, p=math.nan, engine="", note=""):
    return {"study": study, "model": model, "term": term, "estimate": estimate, "se": se, "df": df, "p": p,
            "engine": engine, "note": note}


def model_table(rows):
    return pd.DataFrame(rows, columns=MODEL_COLUMNS)


def separation(X, y, tol=1e-6):
    """Which coefficients of a logistic model of y (0/1) on the design X have no finite maximum-likelihood estimate,
    and which answers they predict perfectly: (infinite column indices, boolean mask of separated rows).

    A direction b with s_i x_i.b >= 0 for every answer (s_i = +1 for y = 1, -1 for y = 0) and > 0 for some raises the
    likelihood without end along b (Albert & Anderson 1984); Konis (2007) finds such directions by linear programming
    with b in [-1, 1]. Coefficient j is infinite when some such direction has b_j != 0: two programs per column (max
    and min b_j), plus Konis's own (max sum_i s_i x_i.b) for the rows. A large finite effect (49 answers one way, 3 the
    other) has no such direction and is not flagged, however large its log-odds."""
    from scipy.optimize import linprog
    X = np.asarray(X, float)
    s = 2 * np.asarray(y, float) - 1
    A = s[:, None] * X
    n, k = A.shape
    scale = max(1.0, float(np.abs(X).max(initial=0.0)))
    bounds = [(-1.0, 1.0)] * k
    infinite, total = set(), np.zeros(k)
    objectives = [-A.sum(axis=0)]
    for j in range(k):
        for sign in (1.0, -1.0):
            c = np.zeros(k)
            c[j] = -sign
            objectives.append(c)
    for c in objectives:
        res = linprog(c, A_ub=-A, b_ub=np.zeros(n), bounds=bounds, method="highs")
        if res.status != 0 or -res.fun <= tol * scale:
            continue
        margin = A @ res.x
        if margin.max() <= tol * scale:  # a direction along a collinear design, not a separating one
            continue
        total += res.x
        infinite |= {j for j in range(k) if abs(res.x[j]) > tol}
    rows = (A @ total) > tol * scale if infinite else np.zeros(n, bool)
    return sorted(infinite), rows


def cluster_robust(y, X, groups, family=None):
    """A GLM (logistic by default) with standard errors clustered by group: sandwich with the CR1 small-sample factor
    G/(G-1) (N-1)/(N-K) (statsmodels' correction), and t with G-1 df for the p-values - with 3-4 participants a normal
    reference would call t = 5 'p < 1e-6' where t(3) gives 0.015. Returns a DataFrame term, estimate, se, df, p."""
    import statsmodels.api as sm
    family = family or sm.families.Binomial()
    codes = pd.factorize(np.asarray(groups))[0]
    G = int(codes.max()) + 1
    res = sm.GLM(np.asarray(y, float), X, family=family).fit(
        cov_type="cluster", cov_kwds={"groups": codes, "use_correction": True})
    est, se = np.asarray(res.params, float), np.asarray(res.bse, float)
    t = est / se
    return pd.DataFrame({"term": list(X.columns), "estimate": est, "se": se, "df": float(G - 1),
                         "p": 2 * sps.t.sf(np.abs(t), G - 1)})


def _formula_text(response, rhs, random=None):
    """The model as R users write it: patsy's C(f, levels=[...]) as f, the random part beside it."""
    import re
    text = re.sub(r"C\((\w+)(?:, levels=\[[^\]]*\])?\)", r"\1", rhs)
    return f"{response} ~ {text}" + (f" + {random}" if random else "")


def _term_sources(X):
    """Design column -> the variable it comes from, in R's words ('C(edge)[T.6]' -> 'edge')."""
    import re
    out = {}
    for term, sl in X.design_info.term_slices.items():
        name = term.name()
        name = re.sub(r"C\((\w+)(?:, levels=\[[^\]]*\])?\)", r"\1", name)
        for col in X.columns[sl]:
            out[col] = name
    return out


def _kept_basis(Xk, infinite_cols):
    """The columns to fit on the answers separation leaves (Xk): the finite terms first, each kept where it adds to
    the rank (a finite term in the span of the others is not estimable), then the infinite terms that the rest still
    needs to span Xk. On those answers the separating direction changes nothing, so an infinite column may be
    collinear with the others there (a separated baseline cell: the intercept is the sum of the other cells'
    indicators) - dropping it loses nothing, while keeping every column left the design rank-deficient and no term
    was fitted. The finite terms' estimates are the limit of the maximum-likelihood fit whichever basis is taken."""
    chosen = []
    finite = [c for c in Xk.columns if c not in infinite_cols]
    for c in finite + [c for c in Xk.columns if c in infinite_cols]:
        if not np.any(Xk[c] != 0):
            continue
        trial = chosen + [c]
        if np.linalg.matrix_rank(Xk[trial].to_numpy(float)) == len(trial):
            chosen = trial
    return [c for c in Xk.columns if c in chosen]


def reference_not_separated(d, response, formula_rhs):
    """formula_rhs with each treatment-coded factor's reference level (its first) moved to its first level whose
    answers did not all go one way, and a note per move. A reference level whose answers all went one way makes the
    intercept and every contrast against it infinite (separation), which hid the contrasts between the other levels
    that the answers do estimate (a yes/no study whose first blur level was all 'yes' had no term left); against an
    estimable reference they are printed, and only the separated level's own contrast is said to be separation. A
    factor of a cell-means design (0 + C(f): no reference) is left as it is."""
    import ast
    import re
    notes = []
    cell_means = re.match(r"\s*0\s*\+\s*C\((\w+)", formula_rhs)

    def move(match):
        name, listed = match.group(1), match.group(2)
        if name not in d or (cell_means and cell_means.group(1) == name):
            return match.group(0)
        levels = ast.literal_eval(f"[{listed}]") if listed else sorted(d[name].dropna().unique())
        one_way = d.groupby(name)[response].agg(lambda v: v.nunique() <= 1)
        mixed_levels = [v for v in levels if v in one_way.index and not one_way[v]]
        if not mixed_levels or mixed_levels[0] == levels[0] or levels[0] not in one_way.index:
            return match.group(0)
        new = [mixed_levels[0]] + [v for v in levels if v != mixed_levels[0]]
        notes.append(f"{name}: the reference level is {mixed_levels[0]}, not {levels[0]} - every answer at "
                     f"{name} {levels[0]} went one way (separation), so contrasts against it have no estimate, and "
                     f"the other levels are compared with the first whose answers went both ways")
        return f"C({name}, levels={new!r})"
    return re.sub(r"C\((\w+)(?:, levels=\[([^\]]*)\])?\)", move, formula_rhs), notes


def observer_models(data, response, formula_rhs, group="participant", study=""):
    """Logistic models of a 0/1 response across observers; returns (table, notes), the table in MODEL_COLUMNS.

    - GLM, cluster-robust: a logistic GLM (statsmodels) with SEs clustered by participant (CR1) and p from t(G-1).
      Population-averaged; needs no R.
    - GLMM by lme4 (>= 3 participants): glmer, Laplace, with the maximal by-participant random part (intercept and
      slopes of the within-participant terms), reduced step by step when that is singular or not determined (the
      note says which and why; mixed.fit); p from the Wald statistic against t(G-1), since with a handful of
      participants the normal reference is far too liberal. Its 'observer SD' rows are the SDs of the participants'
      effects; one estimated at 0 (a singular fit) is said in words. A fit that two optimizers do not agree on, that
      fails lme4's convergence checks or has an SD beyond 10 log-odds is "not determined" in words, never numbers.
    - A factor whose reference level's answers all went one way is compared with its first level whose answers went
      both ways (reference_not_separated), so its estimable contrasts are printed whatever the level order given.
    - one participant: a plain logistic GLM (answers treated as independent), said so; two: no model, said so.
    Separation (a term whose answers all went one way) is found before any fit (separation()); such a term gets no
    estimate and no p in either model, and the other terms are fitted on the answers it does not predict perfectly
    (the limit of the maximum-likelihood fit). Without R the table has the GLM and a note saying the GLMM is missing.
    """
    import patsy
    import statsmodels
    import statsmodels.api as sm
    import mixed

    notes, rows = [], []
    d = data.dropna(subset=[response]).copy()
    d[response] = d[response].astype(float)
    n = len(d)
    ones = int(d[response].sum())
    if n < MIN_ANSWERS or min(ones, n - ones) < MIN_EACH_OUTCOME:
        notes.append(f"no model across observers: {n} decisive answers ({ones} of one kind, {n - ones} of the other); "
                     f"needs >= {MIN_ANSWERS} with >= {MIN_EACH_OUTCOME} of each")
        return model_table(rows), notes
    formula_rhs, moved = reference_not_separated(d, response, formula_rhs)
    notes += moved
    y, X = patsy.dmatrices(f"{response} ~ {formula_rhs}", d, return_type="dataframe")
    d = d.loc[X.index]
    y = y.iloc[:, 0].to_numpy(float)
    groups = d[group].astype(str).to_numpy()
    n_groups = len(set(groups))
    if n_groups == 2:
        # Two clusters give a sandwich SE from two residual sums and a t(1) reference, and a spread between
        # participants from two: neither is an estimate, so no model across them (one participant: a plain GLM).
        notes.append(f"two participants: too few for a model across participants (a cluster-robust SE from two "
                     f"participants with t(1), or a GLMM's spread between two, is not an estimate); no model fitted - "
                     f"the shares per condition are in the tables, and a model needs >= {MIN_PARTICIPANTS_MODEL}")
        return model_table(rows), notes
    sources = _term_sources(X)
    words = {c: term_in_words(c, d) for c in X.columns}

    # A column no answer has (a crossing of two factors never answered) is not determined by anything: said so, and
    # kept out of the separation check (whose linear program could set its coefficient freely and call it
    # separation).
    empty_cols = [c for c in X.columns if not np.any(X[c].to_numpy() != 0)]
    if empty_cols:
        notes.append(f"no answers at {', '.join(words[c] for c in empty_cols)}: "
                     f"{'these terms are' if len(empty_cols) > 1 else 'this term is'} not determined (nothing was "
                     f"answered there), and the other terms are fitted without {'them' if len(empty_cols) > 1 else 'it'}")
    # Separation first: its terms are missing from every model, the rest fitted on the answers it leaves.
    present = [c for c in X.columns if c not in empty_cols]
    infinite, separated = separation(X[present].to_numpy(float), y)
    infinite_cols = [present[j] for j in infinite]
    keep = ~separated
    Xr = X.loc[keep, _kept_basis(X.loc[keep], infinite_cols)]
    yr, gr = y[keep], groups[keep]
    fit_cols = [c for c in Xr.columns if c not in infinite_cols]
    estimable = len(fit_cols) > 0 and min(yr.sum(), len(yr) - yr.sum()) >= 1
    if infinite_cols:
        notes.append(f"separation in {', '.join(words[c] for c in infinite_cols)}: "
                     f"{int(separated.sum())} answer{'s' if int(separated.sum()) != 1 else ''} that those terms "
                     f"predict perfectly left out of the other terms' fits" + ("" if estimable else "; no other term can be estimated apart from them"))
    sm_version = statsmodels.__version__.split("+")[0]

    def add_fit(model, engine, table, note_of):
        by_term = {r["term"]: r for _, r in table.iterrows()} if table is not None else {}
        for c in X.columns:
            if c in empty_cols:
                rows.append(model_row(study, model, words[c], engine=engine, note=EMPTY_NOTE))
            elif c in infinite_cols:
                rows.append(model_row(study, model, words[c], engine=engine, note=SEPARATION_NOTE))
            elif c in by_term:
                r = by_term[c]
                rows.append(model_row(study, model, words[c], r["estimate"], r["se"], r["df"], r["p"], engine,
                                      note_of(c)))
            else:
                rows.append(model_row(study, model, words[c], engine=engine,
                                      note="not estimable apart from the separated terms"))

    # GLM across observers (or the one observer's).
    formula = _formula_text(response, formula_rhs)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        table, zero_se = None, {}
        try:
            if not estimable:
                pass
            elif n_groups >= 2:
                table, zero_se = without_zero_se(cluster_robust(yr, Xr, gr), words)
            else:
                res = sm.GLM(yr, Xr, family=sm.families.Binomial()).fit()
                z = np.asarray(res.params) / np.asarray(res.bse)
                table = pd.DataFrame({"term": list(Xr.columns), "estimate": res.params.to_numpy(),
                                      "se": res.bse.to_numpy(), "df": math.nan, "p": 2 * sps.norm.sf(np.abs(z))})
        except Exception as e:  # a singular design: say so instead of a traceback
            notes.append(f"logistic GLM not fitted: {type(e).__name__}: {str(e).splitlines()[0] if str(e) else ''}")
        if n_groups >= 2:
            add_fit(f"glm({formula}), cluster-robust", f"statsmodels {sm_version} GLM cluster-robust CR1, t(G-1)",
                    table, lambda c: zero_se.get(c, ""))
        else:
            notes.append("one participant: no model across observers; plain logistic GLM instead")
            add_fit(f"glm({formula})", f"statsmodels {sm_version} GLM (one observer), Wald z", table,
                    lambda c: "one observer: answers treated as independent")

    if n_groups >= 3:
        slopes = mixed.slope_columns(Xr[fit_cols], gr) if estimable else []
        try:
            if not estimable:
                raise mixed.Unavailable("no term left to fit after the separated ones")
            levels = {}  # a factor's level columns among the slopes: reduced as one effect (mixed.fit)
            for c in slopes:
                if re.search(r"\[.*\]$", c):
                    levels.setdefault(sources[c], []).append(c)
            f = mixed.fit("glmm", yr, Xr, gr, slopes, levels)
        except mixed.Unavailable as e:
            notes.append(f"GLMM not fitted: {e}")
            f = None
        if f is not None:
            random = f.random_text(lambda c: sources[c], group)
            model = f"glmer({_formula_text(response, formula_rhs, random)})"
            status = f.structure + ("; singular fit (the participants' spread estimated at 0)" if f.singular
                                    else "")
            for c in sorted(words, key=len, reverse=True):  # the terms by their words, not patsy's names
                status = status.replace(c, words[c])
            if f.failed:
                # A fit that failed, or that the optimizers do not agree on (models.R: fit_one), is not an
                # estimate: said in words, no number printed (a flat likelihood's numbers are the optimizer's).
                failed = f.failed
                for c in sorted(words, key=len, reverse=True):  # the terms by their words, not patsy's names
                    failed = failed.replace(c, words[c])
                why = glmm_not_determined(failed)
                notes.append(f"GLMM: {why}")
                add_fit(model, f.engine, None, lambda c: "")
                for r in rows:
                    if r["model"] == model and r["note"] not in (SEPARATION_NOTE, EMPTY_NOTE):
                        r["note"] = why
            else:
                fixed = without_unheld_tests(f, slopes, sources, cell_means="Intercept" not in X.columns)
                add_fit(model, f.engine, fixed, lambda c: status + fixed.set_index("term")["why"].get(c, ""))
                rows += variance_rows(study, model, f, words, "log-odds")
    table = model_table(rows)
    if not table.empty:
        notes += disagreements(table)
    return table, notes


# Measured (analysis/tests/measure_glmm_type1.R, 300 simulated null data sets each: 4 or 8 participants, 66 answers
# each, a true slope 0 whose SD between participants is 0.3 log-odds per edge): the maximal glmer's Wald t(G-1)
# rejected at 0.05 in 3.8 % (4 participants) and 5.6 % (8) of the data sets where it was kept; the intercept-only
# fallback's in 33 % (it assumes one slope for everyone); CR1 with t(G-1) 4.3 % and 5.0 %. So a GLMM term without the
# random slope it was offered gets no SE and no p.
UNHELD_LOST_SLOPE = ("; no SE or p: this term's random slope could not be fitted, and without it the model assumes "
                     "every participant has the same effect, which makes its p far too small (the GLMM's, in "
                     "simulation with 4 participants, rejected a true null 33 % of the time) - use the "
                     "cluster-robust test")
UNHELD_NO_INTERCEPT = ("; no SE or p: the participants' spread in it was estimated at 0 and left out of the random "
                       "part, so its SE counts one participant's answers as independent - use the cluster-robust "
                       "test")
UNHELD_SINGULAR = ("; no SE or p: a singular fit counts one participant's answers as independent - use the "
                   "cluster-robust test")


def glmm_not_determined(failed):
    """The words for a GLMM that models.R did not keep (failed, did not converge - its optimizers disagree or lme4's
    checks failed - or a participants' SD beyond its bound): no estimate, no SE, no p."""
    return (f"not determined: the GLMM {failed}; no estimate, SE or p is printed (where the likelihood gives no "
            f"single answer a fit's numbers are its optimizer's, not estimates) - use the cluster-robust GLM")


def without_unheld_tests(f, offered, sources=None, cell_means=False):
    """A mixed.Fit's fixed effects with se, df and p blanked (and a 'why' column) where the test does not hold: the
    fit is singular, or the term was offered a random slope that the fitted model does not have. cell_means: the
    design has no intercept (0 + C(f): one log-odds per cell), so one cell of each factor gets no slope of its own
    (the random intercept spans it) - which cell is a matter of column order, so when any cell of a factor lost its
    slope every cell of that factor (sources: column -> factor) loses its test, whichever came first."""
    fixed = f.fixed.copy()
    fixed["why"] = ""
    lost = set(offered) - set(f.slopes)
    if cell_means and sources and lost:
        factors = {sources.get(c) for c in lost}
        lost |= {c for c in fixed["term"] if sources.get(c) in factors}
    for i, term in fixed["term"].items():
        why = UNHELD_SINGULAR if f.singular else (UNHELD_LOST_SLOPE if term in lost else "")
        if term == "Intercept" and not f.intercept and not f.singular:
            why = UNHELD_NO_INTERCEPT
        if why:
            fixed.loc[i, ["se", "df", "p"]] = math.nan
            fixed.loc[i, "why"] = why
    return fixed


def variance_rows(study, model, f, words, unit):
    """The rows of a mixed.Fit's SDs and correlations of the participants' effects: one estimated at its bound (a
    singular fit) in words, never as a number."""
    rows = []

    def name(t):
        if t.startswith("level:"):
            return f"each {t[6:]} level (participant x {t[6:]})"
        if t == "Intercept":
            return "baseline (intercept)" if "Intercept" in words else "intercept"
        return words.get(t, t)
    for term, value, singular in f.sds:
        if term == "Residual":
            rows.append(model_row(study, model, "residual SD", value, engine=f.engine, note=f"SD within a "
                                  f"participant ({unit})"))
            continue
        rows.append(model_row(study, model, f"observer SD: {name(term)}", math.nan if singular else value,
                              engine=f.engine, note="singular: estimated at 0, on its bound - no spread between "
                              "participants detectable" if singular else f"SD of the participants' effects ({unit})"))
    for (a, b), value, singular in f.corrs:
        rows.append(model_row(study, model, f"observer correlation: {name(a)} with {name(b)}",
                              math.nan if singular else value, engine=f.engine,
                              note="singular: at +-1" if singular else ""))
    return rows


def disagreements(table):
    """Where the cluster-robust GLM and the lme4 GLMM both give a p for a term and fall on opposite sides of 0.05, a
    note saying what that means. Both tests held their level in simulation with 4 participants (the GLMM with its
    random slope 3.8 %, CR1 with t(G-1) 4.3 %), and the GLMM gives no p where its test does not hold (a lost random
    slope, a singular fit: its note says to use the cluster-robust test), so neither overrules the other: a split is
    borderline evidence."""
    out = []
    glm = table[table["engine"].astype(str).str.contains("cluster-robust")]
    glmm = table[table["engine"].astype(str).str.startswith("lme4")]
    for term in [t for t in glm["term"] if t in set(glmm["term"]) and not str(t).startswith("observer ")]:
        a, b = glm[glm["term"] == term].iloc[0], glmm[glmm["term"] == term].iloc[0]
        pa, pb = a["p"], b["p"]
        if pd.isna(pa) or pd.isna(pb) or (pa < 0.05) == (pb < 0.05):
            continue
        text = lambda p: "p < 0.001" if p < 0.001 else f"p = {p:.3f}"
        out.append(f"{term}: the cluster-robust GLM says {text(pa)}, the GLMM {text(pb)} - borderline: both tests "
                   f"hold their level with few participants, so neither overrules the other; the GLMM's estimate is "
                   f"a typical participant's effect, the GLM's the population average (smaller in log-odds)")
    return out
