"""The models across observers (across_observers.observer_models, mixed.py + models.R) and the depth-matching LMM against truth
they do not compute the same way: a direct glmer call written here in R, simulated observers with known parameters,
hand-worked cells, a cluster-robust sandwich computed here with numpy, scipy's t distribution."""
import math
import os
import subprocess
import sys
import tempfile
import unittest

import numpy as np
import pandas as pd
from scipy import stats as sps

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))
sys.path.insert(0, HERE)

import depth_matching  # noqa: E402
import mixed  # noqa: E402
import across_observers  # noqa: E402
import synthetic  # noqa: E402

RSCRIPT = mixed.rscript()
HAVE_LME4 = RSCRIPT is not None and subprocess.run(
    [RSCRIPT, "-e", "quit(status = !requireNamespace('lme4', quietly = TRUE))"], capture_output=True).returncode == 0


def direct_glmer(d, formula):
    """glmer on d, written here (not models.R): fixed effects (estimate, se), SDs by term, isSingular."""
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "d.csv")
        d.to_csv(path, index=False)
        code = f"""
suppressPackageStartupMessages(library(lme4))
d <- read.csv("{path}")
m <- suppressMessages(suppressWarnings(glmer({formula}, data = d, family = binomial)))
co <- coef(summary(m))
for (i in seq_len(nrow(co))) cat("fixed", rownames(co)[i], co[i, 1], co[i, 2], "\\n")
vc <- as.data.frame(VarCorr(m))
for (i in seq_len(nrow(vc))) if (is.na(vc$var2[i])) cat("sd", vc$var1[i], vc$sdcor[i], "\\n")
cat("singular", isSingular(m), "\\n")
"""
        run = subprocess.run([RSCRIPT, "--vanilla", "-e", code], capture_output=True, text=True, timeout=300)
        assert run.returncode == 0, run.stderr
    fixed, sds, singular = {}, {}, None
    for line in run.stdout.splitlines():
        parts = line.split()
        if parts[0] == "fixed":
            fixed[parts[1]] = (float(parts[2]), float(parts[3]))
        elif parts[0] == "sd":
            sds[parts[1]] = float(parts[2])
        elif parts[0] == "singular":
            singular = parts[1] == "TRUE"
    return fixed, sds, singular


def simulated(n_participants, per, sd_intercept, sd_slope, slope=0.5, seed=5):
    """Observers answering 1 with logit p = 0.3 + u_p + (slope + v_p) x, x = edge - 6 over edges 1-11."""
    rng = np.random.default_rng(seed)
    people = [f"P{i + 1}" for i in range(n_participants)]
    u = dict(zip(people, rng.normal(0, sd_intercept, n_participants)))
    v = dict(zip(people, rng.normal(0, sd_slope, n_participants)))
    d = pd.DataFrame({"participant": np.repeat(people, per), "edge": np.tile(np.arange(1, 12), per)[:per]
                      .tolist() * n_participants})
    d["edge_c"] = d["edge"] - 6.0
    eta = 0.3 + d["participant"].map(u) + (slope + d["participant"].map(v)) * d["edge_c"]
    d["y"] = rng.binomial(1, 1 / (1 + np.exp(-eta))).astype(float)
    return d


class NeedsLme4(unittest.TestCase):
    """A test of lme4's models: it fails without R and lme4, never passes as skipped (run as a script, as CTest does,
    this file then runs only the tests that need no R and exits 77, which CTest reports as skipped)."""

    def setUp(self):
        if not HAVE_LME4:
            self.fail("R with lme4 is needed for this test (and is not installed): it cannot pass without it")


def rows_of(table, engine_prefix):
    return table[table["engine"].str.startswith(engine_prefix)]


class GlmmAgainstDirectGlmer(NeedsLme4):
    def test_estimates_and_se_agree_with_glmer_written_here(self):
        d = simulated(10, 110, sd_intercept=0.8, sd_slope=0.25)
        table, notes = across_observers.observer_models(d, "y", "edge_c", study="s")
        glmm = rows_of(table, "lme4")
        model = glmm["model"].iloc[0]
        # The maximal model is what the data support here (both SDs clearly non-zero); the direct call fits the same.
        self.assertIn("(1 + edge_c | participant)", model, notes)
        fixed, sds, singular = direct_glmer(d, "y ~ edge_c + (1 + edge_c | participant)")
        self.assertFalse(singular)
        for term, words in (("(Intercept)", "baseline (intercept)"), ("edge_c", "per edge (edge centred at 6)")):
            est, se = fixed[term]
            row = glmm[glmm["term"] == words].iloc[0]
            self.assertLessEqual(abs(row["estimate"] - est), max(0.10 * abs(est), 0.25 * se), (term, row, est))
            self.assertLessEqual(abs(row["se"] - se), 0.20 * se, (term, row, se))
            # p from t(G-1) of the estimate over its SE, G = 10.
            self.assertAlmostEqual(row["p"], 2 * sps.t.sf(abs(est / se), 9), delta=0.02)
            self.assertEqual(row["df"], 9)
        sd_row = glmm[glmm["term"] == "observer SD: per edge (edge centred at 6)"].iloc[0]
        self.assertAlmostEqual(sd_row["estimate"], sds["edge_c"], delta=0.1 * sds["edge_c"])

    def test_a_term_that_lost_its_random_slope_has_no_p(self):
        # Participants differ in their baseline only (slope SD 0): the maximal model is singular here (checked with
        # the direct call), so the report fits the random intercept alone and gives the slope no SE and no p.
        d = simulated(6, 88, sd_intercept=1.2, sd_slope=0.0, seed=21)
        _, _, maximal_singular = direct_glmer(d, "y ~ edge_c + (1 + edge_c | participant)")
        self.assertTrue(maximal_singular)
        fixed, _, singular = direct_glmer(d, "y ~ edge_c + (1 | participant)")
        self.assertFalse(singular)
        table, _ = across_observers.observer_models(d, "y", "edge_c", study="s")
        glmm = rows_of(table, "lme4")
        self.assertIn("(1 | participant)", glmm["model"].iloc[0])
        slope = glmm[glmm["term"] == "per edge (edge centred at 6)"].iloc[0]
        self.assertTrue(math.isnan(slope["p"]) and math.isnan(slope["se"]), slope)
        self.assertAlmostEqual(slope["estimate"], fixed["edge_c"][0], delta=0.25 * fixed["edge_c"][1])
        self.assertIn("no SE or p", slope["note"])
        base = glmm[glmm["term"] == "baseline (intercept)"].iloc[0]  # its random intercept is there: p from t(5)
        est, se = fixed["(Intercept)"]
        self.assertAlmostEqual(base["p"], 2 * sps.t.sf(abs(est / se), 5), delta=0.02)

    def test_a_slope_spread_without_an_intercept_spread_keeps_its_slope_and_test(self):
        # Participants differ in their slope only (intercept SD 0, slope SD 0.35): the maximal model and the
        # uncorrelated one are singular here (their intercept SD at 0, checked with the direct calls), but the
        # slope's spread is real. Dropping every slope (the old fallback) took the slope's test away; the random
        # part reduced only by the component at 0 keeps it: the direct (0 + edge_c | participant) fit, written here.
        d = simulated(8, 66, sd_intercept=0.0, sd_slope=0.35, seed=3)
        _, _, maximal_singular = direct_glmer(d, "y ~ edge_c + (1 + edge_c | participant)")
        _, sds, uncorrelated_singular = direct_glmer(d, "y ~ edge_c + (1 | participant) + (0 + edge_c | participant)")
        self.assertTrue(maximal_singular and uncorrelated_singular)
        self.assertLess(sds["(Intercept)"], 1e-4)
        fixed, sds, singular = direct_glmer(d, "y ~ edge_c + (0 + edge_c | participant)")
        self.assertFalse(singular)
        table, notes = across_observers.observer_models(d, "y", "edge_c", study="s")
        glmm = rows_of(table, "lme4")
        self.assertIn("y ~ edge_c + (0 + edge_c | participant))", glmm["model"].iloc[0], notes)
        slope = glmm[glmm["term"] == "per edge (edge centred at 6)"].iloc[0]
        est, se = fixed["edge_c"]
        self.assertLessEqual(abs(slope["estimate"] - est), max(0.10 * abs(est), 0.25 * se), slope)
        self.assertLessEqual(abs(slope["se"] - se), 0.20 * se, slope)
        self.assertAlmostEqual(slope["p"], 2 * sps.t.sf(abs(est / se), 7), delta=0.02)
        self.assertIn("estimated the spread of the intercept at 0", slope["note"])
        base = glmm[glmm["term"] == "baseline (intercept)"].iloc[0]  # no random intercept left: no SE or p
        self.assertTrue(math.isnan(base["p"]) and math.isnan(base["se"]), base)
        sd = glmm[glmm["term"] == "observer SD: per edge (edge centred at 6)"].iloc[0]
        self.assertAlmostEqual(sd["estimate"], sds["edge_c"], delta=0.1 * sds["edge_c"])

    def test_identical_observers_have_sd_zero_in_words(self):
        # Every participant gives the very same answers: the between-participant SD's maximum likelihood is exactly 0
        # (at SD 0 each participant's score is 0, so the likelihood falls as the SD grows), so the fit is singular.
        one = simulated(1, 66, 0, 0, seed=11)[["edge_c", "y"]]
        d = pd.concat([one.assign(participant=f"P{i}") for i in range(6)], ignore_index=True)
        table, notes = across_observers.observer_models(d, "y", "edge_c", study="s")
        sd = rows_of(table, "lme4")
        sd = sd[sd["term"].str.startswith("observer SD")]
        self.assertGreaterEqual(len(sd), 1, table)
        for _, row in sd.iterrows():
            self.assertTrue(math.isnan(row["estimate"]) or row["estimate"] == 0, row)
            self.assertIn("singular", row["note"])
        _, _, singular = direct_glmer(d, "y ~ edge_c + (1 | participant)")
        self.assertTrue(singular)

    def test_random_identical_observers_follow_glmer_verdict(self):
        # Six simulated observers with the same parameters (truth SD 0), answers drawn at random.
        d = simulated(6, 66, 0, 0, seed=3)
        table, _ = across_observers.observer_models(d, "y", "edge_c", study="s")
        row = table[table["term"] == "observer SD: baseline (intercept)"].iloc[0]
        _, sds, singular = direct_glmer(d, "y ~ edge_c + (1 | participant)")
        if singular:
            self.assertTrue(math.isnan(row["estimate"]), row)
            self.assertIn("singular", row["note"])
        else:
            self.assertAlmostEqual(row["estimate"], sds["(Intercept)"], delta=0.05)


class RandomPartAsRWritesIt(unittest.TestCase):
    def test_a_reduced_factor_slope_is_written_as_lme4s_dummy(self):
        # One level's slope kept of a factor: (1 + blur || participant) would give R every level a slope; lme4's
        # dummy() names the one column (checked by hand in R on an experimenter's yes/no group: glmer with this
        # formula gave the report's estimates, -3.18117 (0.72481)).
        f = mixed.Fit(engine="", structure="", fixed=pd.DataFrame(), slopes=("C(blur)[T.object=measured]",),
                      intercept=True, correlated=False)
        self.assertEqual(f.random_text(lambda c: "blur"),
                         '(1 | participant) + (0 + dummy(blur, "object=measured") | participant)')
        f = mixed.Fit(engine="", structure="", fixed=pd.DataFrame(), slopes=("real_arcmin",), intercept=False,
                      correlated=False)
        self.assertEqual(f.random_text(), "(0 + real_arcmin | participant)")
        f = mixed.Fit(engine="", structure="", fixed=pd.DataFrame(), slopes=("x", "z"))
        self.assertEqual(f.random_text(), "(1 + x + z | participant)")


class SeparationTest(unittest.TestCase):
    def cells(self, a_ones, a_zeros, b_ones, b_zeros, participants=4):
        """Cells a and b with the given answer counts, spread over the participants in turn."""
        d = pd.DataFrame({"cell": ["a"] * (a_ones + a_zeros) + ["b"] * (b_ones + b_zeros),
                          "y": [1.0] * a_ones + [0.0] * a_zeros + [1.0] * b_ones + [0.0] * b_zeros})
        d["participant"] = [f"P{i % participants}" for i in range(len(d))]
        return d

    def test_separated_cell_has_no_estimate_and_no_p(self):
        d = self.cells(20, 0, 12, 8)
        table, notes = across_observers.observer_models(d, "y", "0 + C(cell)", study="s")
        a = table[table["term"] == "cell a"]
        self.assertEqual(len(a), 2 if HAVE_LME4 else 1, table)
        for _, row in a.iterrows():
            self.assertTrue(math.isnan(row["estimate"]) and math.isnan(row["p"]) and math.isnan(row["se"]), row)
            self.assertIn("separation", row["note"])
        # The other cell is the limit of the ML fit: its own log-odds, log(12 / 8).
        b = table[(table["term"] == "cell b") & table["engine"].str.contains("cluster-robust")].iloc[0]
        self.assertAlmostEqual(b["estimate"], math.log(12 / 8), places=6)
        self.assertTrue(any("separation in cell a: 20 answers that those terms predict" in n for n in notes), notes)

    def test_one_separated_answer_is_one_answer(self):
        # A cell of one answer is separated by it: the note counts it in the singular ("1 answers" it said).
        _, notes = across_observers.observer_models(self.cells(1, 0, 12, 8), "y", "0 + C(cell)", study="s")
        self.assertTrue(any("separation in cell a: 1 answer that those terms predict perfectly" in n for n in notes),
                        notes)

    def test_separated_baseline_leaves_the_other_factor_estimated(self):
        # The first cell a went all one way, so against it the intercept and every cell's contrast were infinite,
        # hiding the contrast of c with b that the answers estimate: the reference moves to b, the first cell whose
        # answers went both ways, and only a's own contrast is separation. On cells b and c the odds are 1 and 2
        # (b), 3 and 6 (c) for sides l and r, which an additive model fits exactly, so its maximum-likelihood side
        # effect is log(2), c against b log(3) and the baseline (b, l) log(1) = 0, hand-worked. (Found on a
        # one-participant yes/no session whose 6 px blur was all 'yes': every term was 'not estimable'.)
        counts = {("a", "l"): (5, 0), ("a", "r"): (5, 0), ("b", "l"): (5, 5), ("b", "r"): (8, 4),
                  ("c", "l"): (9, 3), ("c", "r"): (12, 2)}
        rows = [(cell, side, y) for (cell, side), (ones, zeros) in counts.items()
                for y in [1.0] * ones + [0.0] * zeros]
        d = pd.DataFrame(rows, columns=["cell", "side", "y"])
        d["participant"] = [f"P{i % 4}" for i in range(len(d))]
        table, notes = across_observers.observer_models(d, "y", "C(cell) + C(side)", study="s")
        glm = table[table["engine"].str.contains("cluster-robust")]
        side = glm[glm["term"] == "side r (against side l)"].iloc[0]
        self.assertAlmostEqual(side["estimate"], math.log(2), places=5)
        self.assertFalse(math.isnan(side["p"]), side)
        c = glm[glm["term"] == "cell c (against cell b)"].iloc[0]
        self.assertAlmostEqual(c["estimate"], math.log(3), places=5)
        self.assertFalse(math.isnan(c["p"]), c)
        self.assertAlmostEqual(glm[glm["term"] == "baseline (intercept)"].iloc[0]["estimate"], 0.0, places=5)
        a = glm[glm["term"] == "cell a (against cell b)"].iloc[0]
        self.assertTrue(math.isnan(a["estimate"]) and math.isnan(a["p"]), a)
        self.assertIn("separation", a["note"])
        self.assertTrue(any("reference level is b, not a" in n for n in notes), notes)
        # The same contrast whatever the level order given.
        again, _ = across_observers.observer_models(d, "y", "C(cell, levels=['c', 'a', 'b']) + C(side)", study="s")
        glm2 = again[again["engine"].str.contains("cluster-robust")]
        b = glm2[glm2["term"] == "cell b (against cell c)"].iloc[0]
        self.assertAlmostEqual(b["estimate"], -c["estimate"], places=5)
        self.assertAlmostEqual(b["p"], c["p"], places=6)
        if HAVE_LME4:
            glmm = rows_of(table, "lme4")
            side = glmm[glmm["term"] == "side r (against side l)"].iloc[0]
            self.assertAlmostEqual(side["estimate"], math.log(2), delta=0.05, msg=(side, notes))

    def test_large_finite_effect_is_not_separation(self):
        d = self.cells(49, 3, 26, 26)
        table, _ = across_observers.observer_models(d, "y", "0 + C(cell)", study="s")
        glm = table[table["engine"].str.contains("cluster-robust")]
        a = glm[glm["term"] == "cell a"].iloc[0]
        self.assertAlmostEqual(a["estimate"], math.log(49 / 3), places=6)  # cell means: the cell's own log-odds
        self.assertFalse(math.isnan(a["p"]))
        self.assertNotIn("separation", " ".join(table["note"]))

    def test_linear_program_on_hand_cases(self):
        X = np.column_stack([np.ones(6), [1.0, 2, 3, 4, 5, 6]])
        self.assertEqual(across_observers.separation(X, [0, 0, 0, 1, 1, 1])[0], [0, 1])  # complete: threshold at 3.5
        self.assertEqual(across_observers.separation(X, [0, 1, 0, 1, 0, 1])[0], [])      # overlap
        # Quasi-complete: both answers at x = 3, all 0 below and all 1 above; those two are the only rows left.
        infinite, rows = across_observers.separation(np.column_stack([np.ones(6), [1.0, 2, 3, 3, 4, 5]]), [0, 0, 0, 1, 1, 1])
        self.assertEqual(infinite, [0, 1])
        self.assertEqual(list(rows), [True, True, False, False, True, True])


class ClusterRobustTest(unittest.TestCase):
    def test_four_participants_use_t3_and_cr1(self):
        rng = np.random.default_rng(4)
        d = pd.DataFrame({"participant": np.repeat(list("ABCD"), 40), "x": np.tile(np.linspace(-2, 2, 8), 20)})
        u = d["participant"].map(dict(zip("ABCD", [-0.6, 0.1, 0.4, 0.9])))
        d["y"] = rng.binomial(1, 1 / (1 + np.exp(-(0.2 + u + 0.7 * d["x"])))).astype(float)
        with mock_env(BLURCUE_RSCRIPT="/nonexistent/Rscript"):
            table, _ = across_observers.observer_models(d, "y", "x", study="s")
        # The logistic ML fit by Newton's method, the CR1 sandwich and t(3) computed here.
        X = np.column_stack([np.ones(len(d)), d["x"]])
        y = d["y"].to_numpy()
        b = np.zeros(2)
        for _ in range(50):
            mu = 1 / (1 + np.exp(-X @ b))
            b = b + np.linalg.solve(X.T @ (X * (mu * (1 - mu))[:, None]), X.T @ (y - mu))
        mu = 1 / (1 + np.exp(-X @ b))
        bread = np.linalg.inv(X.T @ (X * (mu * (1 - mu))[:, None]))
        meat = sum(np.outer(s, s) for s in (X[g].T @ (y[g] - mu[g]) for g in
                                            [(d["participant"] == p).to_numpy() for p in "ABCD"]))
        n, k, G = len(y), 2, 4
        se = np.sqrt(np.diag(bread @ meat @ bread) * G / (G - 1) * (n - 1) / (n - k))
        row = table[table["term"] == "x"].iloc[0]
        self.assertAlmostEqual(row["estimate"], b[1], places=6)
        self.assertAlmostEqual(row["se"], se[1], places=6)
        self.assertEqual(row["df"], 3)
        self.assertAlmostEqual(row["p"], 2 * sps.t.sf(abs(b[1] / se[1]), 3), places=8)
        self.assertGreater(row["p"], 2 * sps.norm.sf(abs(b[1] / se[1])))  # a normal reference would be smaller


class mock_env:
    def __init__(self, **values):
        self.values, self.old = values, {}

    def __enter__(self):
        for k, v in self.values.items():
            self.old[k] = os.environ.get(k)
            os.environ[k] = v

    def __exit__(self, *exc):
        for k, v in self.old.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v


class WithoutRTest(unittest.TestCase):
    def test_no_r_says_so_and_gives_no_approximate_p(self):
        d = simulated(6, 44, 0.5, 0.0)
        with mock_env(BLURCUE_RSCRIPT="/nonexistent/Rscript"):
            table, notes = across_observers.observer_models(d, "y", "edge_c", study="s")
        self.assertEqual(list(table.columns), across_observers.MODEL_COLUMNS)
        self.assertTrue(table["engine"].str.contains("cluster-robust").all(), table)
        self.assertFalse(table["engine"].str.contains("lme4|Bayes|VB").any())
        self.assertTrue(any("GLMM not fitted: R is not installed" in n for n in notes), notes)

    @unittest.skipUnless(RSCRIPT, "R is not installed")
    def test_lme4_missing_is_said_in_words(self):
        # An Rscript whose library path leaves out Debian's site library, where r-cran-lme4 lives.
        tmp = tempfile.mkdtemp()
        wrapper = os.path.join(tmp, "Rscript")
        with open(wrapper, "w") as f:
            f.write(f"#!/bin/sh\nR_LIBS_SITE=/nonexistent R_LIBS_USER=/nonexistent exec {RSCRIPT} \"$@\"\n")
        os.chmod(wrapper, 0o755)
        probe = subprocess.run([wrapper, "-e", "quit(status = requireNamespace('lme4', quietly = TRUE))"])
        if probe.returncode != 0:
            self.skipTest("lme4 is installed outside the site library")
        with mock_env(BLURCUE_RSCRIPT=wrapper):
            table, notes = across_observers.observer_models(simulated(6, 44, 0.5, 0.0), "y", "edge_c", study="s")
        self.assertFalse(table["engine"].str.contains("lme4").any())
        self.assertTrue(any("GLMM not fitted: the R package lme4 is not installed" in n for n in notes), notes)

    def test_report_without_r(self):
        tmp = tempfile.mkdtemp()
        rows = synthetic.trials_rows(participants=("P1", "P2", "P3", "P4"), studies=["test1-static-grids"])
        trials = synthetic.write_trials_csv(os.path.join(tmp, "trials.csv"), rows)
        out = os.path.join(tmp, "out")
        env = dict(os.environ, BLURCUE_RSCRIPT="/nonexistent/Rscript", MPLCONFIGDIR=os.path.join(tmp, "mpl"))
        run = subprocess.run([sys.executable, os.path.join(os.path.dirname(HERE), "report.py"), "--trials", trials,
                              "--bench", os.path.join(tmp, "nobench"), "--out", out, "--boot", "20"],
                             capture_output=True, text=True, env=env, timeout=600)
        self.assertEqual(run.returncode, 0, run.stderr)
        self.assertNotIn("Traceback", run.stderr)
        model = pd.read_csv(os.path.join(out, "test1-model.csv"))
        self.assertEqual(list(model.columns), across_observers.MODEL_COLUMNS)
        self.assertFalse(model["engine"].str.contains("lme4|Bayes|VB").any())
        with open(os.path.join(out, "index.html")) as f:
            self.assertIn("R is not installed", f.read())


class DepthMatchingLmmTest(NeedsLme4):
    def test_lmm_recovers_the_slope_of_set_on_real_blur(self):
        rng = np.random.default_rng(8)
        distances = np.geomspace(0.4, 4, 27)
        real = 6.0 * np.abs(1 / distances - 1.0)  # arcmin: V-shaped around the 1 m focus
        rows = []
        for i in range(8):
            a_p, b_p = 2.0 + rng.normal(0, 0.4), 0.8 + rng.normal(0, 0.15)
            for d, r in zip(distances, real):
                rows.append({"participant": f"P{i}", "distance_m": d, "real_arcmin": r,
                             "set_arcmin": a_p + b_p * r + rng.normal(0, 0.3)})
        a = pd.DataFrame(rows)
        a["cutoff"] = 2 * depth_matching.EQUIVALENT_S * 600 / a["set_arcmin"]  # a 600 arcmin wide picture
        a["log_d"], a["log_c"] = np.log(a["distance_m"]), np.log(a["cutoff"])
        notes = []
        rows, _ = depth_matching.fits(a, notes)
        t = across_observers.model_table(rows)
        slope = t[t["model"].str.startswith("set on real: lmer(set_arcmin ~ real_arcmin + (1 + real_arcmin")
                  & (t["term"] == "per arcmin of real blur, against 1 (set as real)")]
        self.assertEqual(len(slope), 1, (t, notes))
        row = slope.iloc[0]
        self.assertLess(abs(row["estimate"] - 0.8), 3 * row["se"], row)
        self.assertLess(abs(row["estimate"] - 0.8), 0.15, row)
        # A random slope: the slope's Satterthwaite df are about the participants' (G - 1 = 7), not the answers'.
        self.assertTrue(4 < row["df"] < 12, row)
        self.assertTrue(row["engine"].startswith("lme4") and "Satterthwaite" in row["engine"])

    def test_slope_tested_against_1_as_lmertest_does(self):
        # "Set as real" is slope 1: the report's p against 1 must be lmerTest's own for the slope of (set - real) on
        # real (that model's slope is b - 1 with the same likelihood), written here in R, not through models.R; the
        # row against 0 beside it is lmerTest's summary of the model itself. Observers set 0.8 x real: far from 1.
        rng = np.random.default_rng(11)
        real = 6.0 * np.abs(1 / np.geomspace(0.4, 4, 27) - 1.0)
        rows = []
        for i in range(6):
            a_p, b_p = 2.0 + rng.normal(0, 0.4), 0.8 + rng.normal(0, 0.1)
            rows += [{"participant": f"P{i}", "real_arcmin": r, "set_arcmin": a_p + b_p * r + rng.normal(0, 0.4)}
                     for r in real]
        a = pd.DataFrame(rows)
        notes = []
        rows, _ = depth_matching._across(a, "real_arcmin", "set_arcmin", "set on real", depth_matching.WORDS_MATCH,
                                         notes, "s")
        t = across_observers.model_table(rows)
        lmer = t[t["engine"].str.startswith("lme4")]
        one = lmer[lmer["term"] == depth_matching.WORDS_MATCH["real_arcmin"]].iloc[0]
        zero = lmer[lmer["term"] == depth_matching.MATCH_SLOPE_AGAINST_0].iloc[0]
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "d.csv")
            a.to_csv(path, index=False)
            code = f"""
suppressPackageStartupMessages(library(lmerTest))
d <- read.csv("{path}")
d$diff <- d$set_arcmin - d$real_arcmin
m0 <- lmer(set_arcmin ~ real_arcmin + (1 + real_arcmin | participant), data = d)
m1 <- lmer(diff ~ real_arcmin + (1 + real_arcmin | participant), data = d)
c0 <- coef(summary(m0)); c1 <- coef(summary(m1))
cat(c0[2, 1], c0[2, 2], c0[2, 3], c0[2, 5], c1[2, 1], c1[2, 3], c1[2, 5], "\n")
"""
            run = subprocess.run([RSCRIPT, "--vanilla", "-e", code], capture_output=True, text=True, timeout=300)
        self.assertEqual(run.returncode, 0, run.stderr)
        b, se, df, p0, b1, df1, p1 = map(float, run.stdout.split())
        self.assertAlmostEqual(b1, b - 1, places=4)
        self.assertAlmostEqual(one["estimate"], b, delta=1e-4 * max(1, abs(b)))
        self.assertAlmostEqual(one["se"], se, delta=1e-3 * se)
        self.assertAlmostEqual(one["df"], df1, delta=0.02 * df1)
        self.assertLess(abs(one["p"] - p1), 0.02 * p1 + 1e-12, (one["p"], p1))
        self.assertLess(abs(zero["p"] - p0), 0.02 * p0 + 1e-12, (zero["p"], p0))
        self.assertLess(one["p"], 0.05)  # 0.8 is not "set as real"
        self.assertEqual(zero["estimate"], one["estimate"])
        # The SD of the participants' slopes is named without a test's words.
        self.assertTrue(any(str(r).startswith("observer SD: per arcmin of real blur") and "against" not in str(r)
                            for r in lmer["term"]), list(lmer["term"]))


if __name__ == "__main__":
    if not HAVE_LME4:  # the tests that need no lme4, then CTest's skip code: the rest could not run
        print("SKIP: R with lme4 is not installed: only the tests that need no lme4 were run", file=sys.stderr)
        suite = unittest.TestSuite(unittest.defaultTestLoader.loadTestsFromTestCase(c) for c in (
            RandomPartAsRWritesIt, SeparationTest, ClusterRobustTest, WithoutRTest))
        sys.exit(77 if unittest.TextTestRunner().run(suite).wasSuccessful() else 1)
    unittest.main()
