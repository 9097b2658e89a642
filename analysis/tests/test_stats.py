"""Statistics against hand-computed answers, a psychometric fit recovering known parameters, and the side-bias and
display-timing sections against hand-computed cases (in process, fast)."""
import math
import os
import shutil
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))  # analysis/
sys.path.insert(0, HERE)  # synthetic.py

import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

import common  # noqa: E402
import forced_choice  # noqa: E402
import frame_timing  # noqa: E402
import across_observers  # noqa: E402
import stats  # noqa: E402
import study_tests  # noqa: E402
import synthetic  # noqa: E402


def binom_two_sided_half(k, n):
    """Independent closed form for p = 0.5 (the distribution is symmetric, so 'as or less likely' = 'as or more
    extreme'): P = 2 * sum_{i >= max(k, n-k)} C(n, i) / 2^n, capped at 1."""
    m = max(k, n - k)
    return min(1.0, 2 * sum(math.comb(n, i) for i in range(m, n + 1)) / 2 ** n)


def sign_flip_by_hand(shares, chance=0.5):
    """The sign-flip p by listing all 2^G sign patterns (independent of study_tests' distribution by convolution)."""
    import itertools
    d = [x - chance for x in shares]
    observed = abs(sum(d))
    hits = sum(abs(sum(s * abs(x) for s, x in zip(signs, d))) >= observed - 1e-9
               for signs in itertools.product((1, -1), repeat=len(d)))
    return hits / 2 ** len(d)


class WilsonTest(unittest.TestCase):
    # Hand computation, z = 1.959963985 (z^2 = 3.841458821), p = k/n, d = 1 + z^2/n,
    # centre = (p + z^2/(2n)) / d, half = (z/d) * sqrt(p(1-p)/n + z^2/(4n^2)):
    #  7/10:  d = 1.384145882; centre = (0.7 + 0.192072941)/d = 0.644493048;
    #         half = 1.416011 * sqrt(0.021 + 0.009603647) = 1.416011 * 0.174939 = 0.247715
    #         -> [0.396778, 0.892209]
    #  0/10:  centre = 0.192072941/d = 0.138766; half = 1.416011 * sqrt(0.009603647) = 0.138766 -> [0, 0.277533]
    #  10/10: mirror image of 0/10 -> [0.722467, 1]
    #  15/20: d = 1.192072941; centre = (0.75 + 0.096036470)/d = 0.709719;
    #         half = 1.644162 * sqrt(0.009375 + 0.002400912) = 1.644162 * 0.108517 = 0.178420 -> [0.531299, 0.888138]
    KNOWN = [((7, 10), (0.7, 0.396778, 0.892209)),
             ((0, 10), (0.0, 0.0, 0.277533)),
             ((10, 10), (1.0, 0.722467, 1.0)),
             ((15, 20), (0.75, 0.531299, 0.888138))]

    def test_known_intervals(self):
        for (k, n), expected in self.KNOWN:
            got = stats.wilson(k, n)
            for g, e in zip(got, expected):
                self.assertAlmostEqual(g, e, places=5, msg=f"Wilson {k}/{n}")

    def test_bounds_exact_at_extremes(self):
        self.assertEqual(stats.wilson(0, 10)[1], 0.0)
        self.assertEqual(stats.wilson(10, 10)[2], 1.0)

    def test_no_trials(self):
        self.assertTrue(all(math.isnan(v) for v in stats.wilson(0, 0)))


class BinomialTest(unittest.TestCase):
    # Two-sided exact p against 0.5, by hand (2^10 = 1024):
    #  9/10: P(X >= 9) = (C(10,9) + C(10,10))/1024 = 11/1024; two-sided 22/1024 = 0.021484375
    #  7/10: (C(10,7)+C(10,8)+C(10,9)+C(10,10)) = 120+45+10+1 = 176; 2*176/1024 = 0.34375
    #  0/10: 2 * 1/1024 = 0.001953125;  5/10: 1
    #  15/20: C(20,15..20) = 15504+4845+1140+190+20+1 = 21700; 2*21700/2^20 = 0.04138946533203125
    # Against p = 0.2 ('minlike': sum of every outcome no more likely than the observed one), 0 of 5:
    #  P(0) = 0.8^5 = 0.32768, P(1) = 0.4096, P(2) = 0.2048, P(3) = 0.0512, P(4) = 0.0064, P(5) = 0.00032
    #  outcomes with P <= 0.32768: 0, 2, 3, 4, 5 -> 0.32768 + 0.2048 + 0.0512 + 0.0064 + 0.00032 = 0.5904
    KNOWN = [(9, 10, 0.5, 0.021484375), (7, 10, 0.5, 0.34375), (0, 10, 0.5, 0.001953125), (5, 10, 0.5, 1.0),
             (15, 20, 0.5, 0.04138946533203125), (0, 5, 0.2, 0.5904)]

    def test_known_p_values(self):
        for k, n, p, expected in self.KNOWN:
            self.assertAlmostEqual(stats.binom_p(k, n, p), expected, places=9, msg=f"{k}/{n} vs {p}")

    def test_closed_form_agrees(self):
        for n in (1, 6, 11, 20):
            for k in range(n + 1):
                self.assertAlmostEqual(stats.binom_p(k, n), binom_two_sided_half(k, n), places=12)

    def test_no_trials(self):
        self.assertTrue(math.isnan(stats.binom_p(0, 0)))

    def test_holm(self):
        # sorted 0.01, 0.03, 0.04 -> 3*0.01 = 0.03, 2*0.03 = 0.06, max(0.06, 1*0.04) = 0.06; NaN passes through
        np.testing.assert_allclose(stats.holm([0.01, 0.04, math.nan, 0.03]), [0.03, 0.06, math.nan, 0.06])


class PsychometricTest(unittest.TestCase):
    def simulate(self, kind, alpha, beta, gamma, lam, levels, per_level, seed):
        rng = np.random.default_rng(seed)
        x = np.repeat(levels, per_level).astype(float)
        y = rng.binomial(1, stats.psi(kind, x, alpha, beta, gamma, lam)).astype(float)
        return x, y

    def test_weibull_recovers_parameters(self):
        x, y = self.simulate("weibull", 3.0, 2.5, 0.5, 0.02, [0.5, 1, 1.5, 2, 2.5, 3, 4, 5, 6], 150, seed=11)
        f = stats.fit_psychometric(x, y, kind="weibull", gamma=0.5, lam=(0, 0.1))
        self.assertTrue(f.converged)
        self.assertAlmostEqual(f.alpha, 3.0, delta=0.3)
        self.assertAlmostEqual(f.beta, 2.5, delta=0.8)
        self.assertLess(f.lam, 0.06)
        self.assertEqual(f.gamma, 0.5)

    def test_logistic_with_free_guess_rate(self):
        # A yes/no task: guess (false-alarm) rate 0.05, lapse 0.03, threshold 0, spread 1.
        x, y = self.simulate("logistic", 0.0, 1.0, 0.05, 0.03, np.linspace(-4, 4, 9), 150, seed=5)
        f = stats.fit_psychometric(x, y, kind="logistic", gamma=None, lam=(0, 0.1))
        self.assertAlmostEqual(f.alpha, 0.0, delta=0.25)
        self.assertAlmostEqual(f.beta, 1.0, delta=0.3)
        self.assertAlmostEqual(f.gamma, 0.05, delta=0.05)
        self.assertEqual(f.n_params, 4)

    def test_clustered_levels_do_not_collapse_into_a_step(self):
        # Four levels in two clusters with a gap across the transition of a smooth curve (spread 0.12). Unbounded,
        # this seed's ML logistic fit is a step in the gap (beta ~ 6e-7); bounded, beta stays >= span / 50, the fit
        # says when it sits on that bound, and the bootstrap refits keep to the same bound.
        x, y = self.simulate("logistic", 0.6, 0.12, 0.5, 0.02, [0.2, 0.3, 0.9, 1.0], 80, seed=6)
        f = stats.fit_psychometric(x, y, kind="logistic", gamma=0.5, lam=(0, 0.1))
        b_lo, _ = f.options["beta_bounds"]
        self.assertAlmostEqual(b_lo, 0.8 / 50)
        self.assertGreater(f.beta, 0.01, "spread collapsed into a step")
        self.assertGreaterEqual(f.beta, b_lo)
        self.assertEqual("beta" in f.on_bound, f.beta < b_lo * 1.001)
        self.assertTrue(0.3 < f.alpha < 0.9, "the transition belongs in the gap")
        stats.bootstrap(x, y, np.ones_like(y), f, n_boot=30, seed=2)
        self.assertGreaterEqual(f.ci["beta"][0], b_lo)
        # The Weibull's shape is bounded too (<= 10).
        w = stats.fit_psychometric(x, y, kind="weibull", gamma=0.5, lam=(0, 0.1))
        self.assertLessEqual(w.beta, stats.WEIBULL_MAX_SHAPE)

    def test_wrong_model_fits_worse(self):
        # Data from a steep Weibull: the logistic should not win by AIC by a wide margin (sanity of the likelihood).
        x, y = self.simulate("weibull", 2.0, 4.0, 0.5, 0.0, [0.5, 1, 1.5, 2, 2.5, 3, 4], 200, seed=3)
        w = stats.fit_psychometric(x, y, kind="weibull")
        lg = stats.fit_psychometric(x, y, kind="logistic")
        self.assertLess(w.aic, lg.aic + 2)

    def test_bootstrap_covers_truth_and_is_seeded(self):
        x, y = self.simulate("weibull", 3.0, 2.5, 0.5, 0.02, [0.5, 1, 1.5, 2, 2.5, 3, 4, 5, 6], 80, seed=21)
        ones = np.ones_like(y)
        for method in ("parametric", "nonparametric"):
            f1 = stats.fit_psychometric(x, y, kind="weibull")
            grid, lo, hi = stats.bootstrap(x, y, ones, f1, method=method, n_boot=60, seed=4)
            f2 = stats.fit_psychometric(x, y, kind="weibull")
            stats.bootstrap(x, y, ones, f2, method=method, n_boot=60, seed=4)
            self.assertEqual(f1.ci, f2.ci, "same seed, same intervals")
            a_lo, a_hi = f1.ci["alpha"]
            self.assertLess(a_lo, 3.0)
            self.assertGreater(a_hi, 3.0)
            self.assertLess(a_hi - a_lo, 1.5, "interval should be informative")
            self.assertTrue(np.all(lo <= hi))
            inside = (lo <= f1(grid) + 1e-9) & (f1(grid) <= hi + 1e-9)
            self.assertGreater(inside.mean(), 0.9, "the band should hold the fitted curve")

    def test_threshold_inverts_psi(self):
        f = stats.PsychometricFit("weibull", 3.0, 2.0, 0.5, 0.02, 0, 2, 100, True)
        t = stats.threshold(f, 0.75)
        self.assertAlmostEqual(float(f(t)), 0.75, places=9)
        g = stats.PsychometricFit("logistic", 1.0, 0.5, 0.5, 0.0, 0, 2, 100, True)
        self.assertAlmostEqual(stats.threshold(g, 0.75), 1.0, places=9)  # logistic midpoint of [0.5, 1]
        self.assertTrue(math.isnan(stats.threshold(f, 0.4)))


class ObserverModelTest(unittest.TestCase):
    def frame(self, participants, per, seed=2):
        rng = np.random.default_rng(seed)
        d = pd.DataFrame({"participant": np.repeat(participants, per), "edge": np.tile(np.arange(1, 12), len(
            participants) * per // 11 + 1)[:len(participants) * per]})
        d["y"] = rng.binomial(1, 1 / (1 + np.exp(-(d["edge"] - 6) * 0.5))).astype(float)
        return d

    def test_several_observers(self):
        table, notes = across_observers.observer_models(self.frame(list("ABCDEF"), 44), "y", "edge")
        self.assertEqual(list(table.columns), across_observers.MODEL_COLUMNS)
        glm = table[table["engine"].str.contains("cluster-robust")]
        self.assertEqual(set(glm["df"]), {5.0})  # t with G - 1 = 5 df
        slope = glm[glm["term"] == "edge"].iloc[0]
        self.assertAlmostEqual(slope["estimate"], 0.5, delta=0.2)

    def test_one_observer_falls_back_with_a_note(self):
        table, notes = across_observers.observer_models(self.frame(["A"], 66), "y", "edge")
        self.assertEqual(set(table["model"]), {"glm(y ~ edge)"})
        self.assertTrue(table["note"].str.contains("one observer").all())
        self.assertTrue(any("one participant" in n for n in notes))

    def test_too_few_answers(self):
        table, notes = across_observers.observer_models(self.frame(list("AB"), 3), "y", "edge")
        self.assertTrue(table.empty)
        self.assertTrue(any("no model across observers" in n for n in notes))

    @staticmethod
    def same_at_both_edges():
        """Three participants whose answers at edge 6 are those at edge 3, answer for answer, in each blur cell: the
        response is constant across the two edges, so the edge term is 0 by construction. P3 answers at exactly the
        pooled rates (5/8 sharp, 2/8 blurred), so its scores are 0 and P1's and P2's cancel: the baseline's
        cluster-robust SE is 0 (two participants get no model across them at all)."""
        rows = []
        for p, (sharp, blurred) in {"P1": ([1, 1, 1, 0], [0, 0, 1, 0]), "P2": ([1, 1, 0, 0], [0, 1, 0, 0]),
                                    "P3": ([1, 1, 1, 1, 1, 0, 0, 0], [1, 1, 0, 0, 0, 0, 0, 0])}.items():
            for edge in (3, 6):
                rows += [{"participant": p, "edge": edge, "blur": "sharp", "y": float(v)} for v in sharp]
                rows += [{"participant": p, "edge": edge, "blur": "blurred", "y": float(v)} for v in blurred]
        return pd.DataFrame(rows)

    def test_term_zero_by_construction_is_said_in_words_not_as_rounding_noise(self):
        table, _ = across_observers.observer_models(self.same_at_both_edges(), "y", "C(blur) + C(edge)")
        edge = table[table["term"] == "edge 6 (against edge 3)"].iloc[0]
        # The fit gives some 1e-16 with an SE of the same size, and a p from their ratio: none of them is printed.
        for column in ("estimate", "se", "p"):
            self.assertTrue(math.isnan(edge[column]), f"{column} = {edge[column]!r}")
        self.assertIn("not determined", edge["note"])
        self.assertIn("the answers at edge 6 come out as those at edge 3", edge["note"])
        blur = table[table["term"] == "blur sharp (against blur blurred)"].iloc[0]  # a real effect keeps its numbers
        self.assertAlmostEqual(blur["estimate"], math.log(5 / 3) - math.log(1 / 3), places=6)  # 5/8 vs 2/8 yes
        self.assertGreater(blur["se"], 0.1)
        self.assertEqual(blur["note"], "")

    def test_se_of_zero_is_said_in_words_and_the_estimate_kept(self):
        table, _ = across_observers.observer_models(self.same_at_both_edges(), "y", "C(blur) + C(edge)")
        # Every participant said yes to a quarter of their blurred balls: the baseline is log(2/6) in each, no spread.
        base = table[table["term"] == "baseline (intercept)"].iloc[0]
        self.assertAlmostEqual(base["estimate"], math.log(2 / 6), places=6)
        self.assertTrue(math.isnan(base["se"]) and math.isnan(base["p"]))
        self.assertIn("SE not determined", base["note"])

    def test_depth_matching_zero_se_is_said_in_words(self):
        # Three participants who set exactly the same blur at every distance: the cluster-robust SE is 0 to rounding
        # (no participant's settings pull the fit), so the slope gets no SE and no p, in words - and the pooled line
        # used by the charts keeps its estimates. (Two participants get no model across them at all:
        # test_depth_matching.TwoParticipants.)
        import depth_matching
        real = [0.5, 1.0, 2.0, 3.0, 4.0]
        rows = [{"participant": p, "real_arcmin": r, "set_arcmin": 1.0 + 0.5 * r + e}
                for p in ("P1", "P2", "P3") for r, e in zip(real, [0.1, -0.2, 0.15, -0.05, 0.0])]
        out, pooled = depth_matching._across(pd.DataFrame(rows), "real_arcmin", "set_arcmin", "set on real",
                                             depth_matching.WORDS_MATCH, [], "s")
        table = across_observers.model_table(out)
        slope = table[(table["term"] == depth_matching.WORDS_MATCH["real_arcmin"]) &
                      table["engine"].str.contains("cluster-robust")].iloc[0]
        self.assertTrue(math.isnan(slope["se"]) and math.isnan(slope["p"]), slope.to_dict())
        self.assertIn("SE not determined", slope["note"])
        self.assertAlmostEqual(slope["estimate"], pooled[1], places=9)
        self.assertGreater(pooled[1], 0.3)

    def test_disagreeing_models_are_called_borderline(self):
        glm = "statsmodels 0.13.5 GLM cluster-robust CR1, t(G-1)"
        lme4 = "lme4 1.1-31 glmer (Laplace), Wald t(G-1)"
        table = across_observers.model_table([
            across_observers.model_row("s", "glm", "per edge", p=0.01, engine=glm),
            across_observers.model_row("s", "glmer", "per edge", p=0.2, engine=lme4),
            across_observers.model_row("s", "glm", "pattern_id 3", p=0.01, engine=glm),
            across_observers.model_row("s", "glmer", "pattern_id 3", engine=lme4, note=across_observers.UNHELD_LOST_SLOPE),
            across_observers.model_row("s", "glm", "pattern_id 4", p=0.2, engine=glm),
            across_observers.model_row("s", "glmer", "pattern_id 4", p=0.3, engine=lme4)])
        notes = across_observers.disagreements(table)
        self.assertEqual(len(notes), 1, notes)
        self.assertIn("per edge: the cluster-robust GLM says p = 0.010, the GLMM p = 0.200 - borderline", notes[0])

    def test_terms_in_words(self):
        d = pd.DataFrame({"edge": [3, 6, 9]})
        self.assertEqual(across_observers.term_in_words("C(pattern_id)[1]", d), "pattern_id 1")
        self.assertEqual(across_observers.term_in_words("C(edge)[T.6]", d), "edge 6 (against edge 3)")
        self.assertEqual(across_observers.term_in_words("C(edge, levels=['9', '3'])[T.3]", d), "edge 3 (against edge 9)")
        # A baseline level holding a comma and quotes is named whole (it was cut at the comma: 'against c naïve').
        self.assertEqual(across_observers.term_in_words("C(c, levels=['naïve, µ \\'a\\'', 'Ω,<b>'])[T.Ω,<b>]", d),
                         "c Ω,<b> (against c naïve, µ 'a')")
        self.assertEqual(across_observers.term_in_words("Intercept", d), "baseline (intercept)")
        self.assertEqual(across_observers.term_in_words("edge_c", d), "per edge (edge centred at 6)")


class AgainstChanceIsExactTest(unittest.TestCase):
    """study_tests.against_chance, the test behind every per-condition p, Holm and star: its false-positive rate at
    3-12 participants with 1-20 answers each is at most 5 % (exactly where the outcomes can be listed, else by a
    seeded simulation whose seed and rates are printed), and a unanimous cell is never less significant than any other
    cell of the same participants and answers. The one-sample t it replaced fails both: 12.5 % at 7 participants of
    one answer each, and no t at all where every participant chose the same side."""
    SEED = 38
    ALPHA = 0.05

    def p(self, ks, ns, chance=0.5):
        """against_chance's p from per-participant counts (against_chance counts a frame's and calls this)."""
        return study_tests.against_chance_counts(ks, ns, chance)["p"]

    def test_frame_and_counts_give_one_p(self):
        ks, ns = [3, 0, 5, 2], [4, 2, 5, 6]
        frame = pd.DataFrame({"participant": np.repeat([f"P{i}" for i in range(len(ns))], ns),
                              "y": np.concatenate([[1.0] * k + [0.0] * (n - k) for k, n in zip(ks, ns)])})
        self.assertEqual(study_tests.against_chance(frame, 0.5), study_tests.against_chance_counts(ks, ns, 0.5))
        self.assertAlmostEqual(self.p(ks, ns), sign_flip_by_hand([k / n for k, n in zip(ks, ns)]), places=12)

    def exact_rate(self, people, answers, chance=0.5):
        """The false-positive rate with `people` participants of `answers` answers each, all answering at chance:
        every multiset of their counts, weighted by its multinomial probability (the p depends on the multiset)."""
        import itertools
        pmf = [math.comb(answers, k) * chance ** k * (1 - chance) ** (answers - k) for k in range(answers + 1)]
        rate = 0.0
        for ks in itertools.combinations_with_replacement(range(answers + 1), people):
            counts = np.bincount(ks, minlength=answers + 1)
            weight = math.factorial(people) / math.prod(math.factorial(c) for c in counts)
            if self.p(list(ks), [answers] * people, chance) <= self.ALPHA:
                rate += weight * math.prod(pmf[k] for k in ks)
        return rate

    def test_false_positive_rate_listed_exactly(self):
        rates = {}
        for people, answers in ((3, 12), (4, 6), (5, 4), (6, 3), (7, 1), (7, 2), (9, 1), (12, 1), (10, 2)):
            rates[(people, answers)] = rate = self.exact_rate(people, answers)
            self.assertLessEqual(rate, self.ALPHA + 1e-12, (people, answers))
        print(f"\nexact false-positive rates at 0.5 (participants, answers each): "
              + ", ".join(f"{k}: {v:.4f}" for k, v in rates.items()), file=sys.stderr)
        # What the t across shares gave at 7 x 1 (6 of 7 one way: t p = 0.047): 2 x (7 + 1) / 128 = 0.125.
        from scipy import stats as sps
        # (k = 1, 6 by the t; k = 0, 7, where t is undefined, by the sign test it fell back on, 2 / 128 each).
        t_rate = sum(math.comb(7, k) for k in range(8) if np.std([1] * k + [0] * (7 - k)) == 0 or
                     sps.ttest_1samp([1] * k + [0] * (7 - k), 0.5).pvalue <= 0.05) / 128
        self.assertAlmostEqual(t_rate, 0.125)
        self.assertAlmostEqual(self.p([1] * 6 + [0], [1] * 7), 0.125, places=12)

    def test_false_positive_rate_by_simulation(self):
        # 3-12 participants with 1-20 answers each drawn per participant; at 0.5 half the studies have every
        # participant answering at 0.5, half have participants' own rates spread symmetrically about it (Beta(2, 2):
        # preferences that cancel out, the null the sign flip holds under too); at 1/3 every participant guesses.
        rng = np.random.default_rng(self.SEED)
        rates = {}
        for chance, kind, studies in ((0.5, "at chance", 1000), (0.5, "spread about it", 1000),
                                      (1 / 3, "at chance", 500)):
            rejected = 0
            for _ in range(studies):
                people = int(rng.integers(3, 13))
                ns = rng.integers(1, 21, people)
                rate = rng.beta(2, 2, people) if kind != "at chance" else np.full(people, chance)
                rejected += self.p(rng.binomial(ns, rate), ns, chance) <= self.ALPHA
            rate = rejected / studies
            mc = math.sqrt(self.ALPHA * (1 - self.ALPHA) / studies)
            rates[(round(chance, 3), kind)] = rate
            self.assertLessEqual(rate, self.ALPHA + 2.5 * mc, (chance, kind, rate))
        print(f"\nsimulated false-positive rates (seed {self.SEED}): "
              + ", ".join(f"chance {c} {k}: {v:.4f}" for (c, k), v in rates.items()), file=sys.stderr)

    def test_unanimous_cell_never_less_significant(self):
        import itertools
        rng = np.random.default_rng(self.SEED)
        for people in range(3, 13):
            ns = [5] * people if people in (3, 5, 7) else list(rng.integers(1, 21, people))
            unanimous = self.p(ns, ns)
            self.assertAlmostEqual(unanimous, 2 / 2 ** people, places=12)
            self.assertAlmostEqual(self.p([0] * people, ns), unanimous, places=12)  # the other side alike
            if people <= 3:
                others = itertools.product(*[range(n + 1) for n in ns])
            else:
                others = (rng.binomial(ns, rng.uniform(0.3, 1.0)) for _ in range(150))
            for ks in others:
                self.assertLessEqual(unanimous, self.p(list(ks), ns) + 1e-12, (ns, ks))
        # Chance 1/3: every answer correct is the least likely outcome under guessing.
        ns = [4, 6, 5]
        best = self.p(ns, ns, 1 / 3)
        self.assertAlmostEqual(best, (1 / 3) ** 15, places=15)
        for ks in itertools.product(*[range(n + 1) for n in ns]):
            self.assertLessEqual(best, self.p(list(ks), ns, 1 / 3) + 1e-15, ks)

    def test_answer_counts_whose_common_unit_passes_64_bits(self):
        # Ten participants with 53-97 answers (primes): the deviations' common unit lcm(2 n) is ~1e19, beyond int64,
        # so the sign patterns are listed in floats - the same p as listing them by hand, 2 / 2^10 when unanimous.
        ns = [53, 59, 61, 67, 71, 73, 79, 83, 89, 97]
        ks = [40, 45, 44, 50, 52, 55, 60, 61, 70, 20]
        self.assertAlmostEqual(self.p(ks, ns), sign_flip_by_hand([k / n for k, n in zip(ks, ns)]), places=12)
        self.assertAlmostEqual(self.p(ns, ns), 2 / 2 ** 10, places=15)

    def test_unanimous_cell_gets_its_star_and_holm_adjusts_the_printed_p(self):
        # The statistician's case: 7 participants, 35 of 35 answers for the first source in one cell (the t was
        # undefined, the sign test and Holm gave no star) and 67 % in another (which got one).
        rows = []
        for i in range(7):
            rows += PerPatternUnitTest.rows(f"P{i}", 5, 0, pattern=1)
            rows += PerPatternUnitTest.rows(f"P{i}", *((4, 2) if i < 5 else (2, 4)), pattern=2)
        with tempfile.TemporaryDirectory() as tmp:
            common.setup_style()
            t = forced_choice.per_pattern(pd.DataFrame(rows), tmp, "test2-moving-balls")[0].table
        t = t.set_index("pattern_id")
        self.assertAlmostEqual(t.loc[1, "p"], 2 / 128, places=12)
        self.assertLessEqual(t.loc[1, "p"], t.loc[2, "p"])
        np.testing.assert_allclose(t["p_holm"], stats.holm(t["p"]))
        self.assertGreaterEqual(len(common.stars(t.loc[1, "p_holm"])), len(common.stars(t.loc[2, "p_holm"])))
        self.assertEqual(common.stars(t.loc[1, "p_holm"]), "*")  # 2 x 2/128 = 0.031
        self.assertFalse([c for c in t.columns if c.startswith("p_") and c != "p_holm"], list(t.columns))


class LoadTrialsTest(unittest.TestCase):
    def write(self, text):
        f = tempfile.NamedTemporaryFile("w", suffix=".csv", delete=False, newline="")
        f.write(text)
        f.close()
        self.addCleanup(os.unlink, f.name)
        return f.name

    HEADER = "study,participant,observer,session_id,trial_index,block_name,task,practice,swapped,edge,left_source," \
             "left_fixed,right_source,right_fixed,status,chosen_side,chosen_interval,yes_no,rating,adjusted_level," \
             "rt_ms\r\n"

    def test_flags_and_answers_of_the_tidy_table(self):
        path = self.write(self.HEADER +
                          "test1-static-grids,P1,person,1,0,b,forced_choice,1,0,3,measured,,estimated,,answered,left,,,,,"
                          "812\r\n"
                          "test1-static-grids,P1,person,1,1,b,forced_choice,0,1,4,fixed_arcmin,2.5,measured,,"
                          "unanswered,,,,,,\r\n"
                          "test1-static-grids,P1,person,1,2,b,forced_choice,0,0,5,measured,,none,,timed_out,,,,,,\r\n")
        d = common.load_trials(path)
        self.assertEqual(list(d["practice"]), [1, 0, 0])
        self.assertEqual(list(d["swapped"]), [0, 1, 0])
        self.assertEqual(list(d["answered"]), [True, False, True])
        self.assertEqual(list(d["choice"]), ["left", "", "none"])
        self.assertEqual(d["left"].iloc[1], "fixed 2.5 arcmin")
        fc = common.forced_choice(d)
        self.assertEqual(fc["chosen_source"].iloc[0], "measured")

    def test_pattern_by_its_id(self):
        path = self.write(self.HEADER.replace(",edge,", ",pattern,speed_cm_s,") +
                          "test2-moving-balls,P1,person,1,0,b,forced_choice,0,0,3,3,none,,estimated,,answered,right,,,,,"
                          "900\r\n")
        d = common.load_trials(path)
        self.assertEqual(d["pattern_id"].iloc[0], 3)
        self.assertEqual(d["speed_cm_s"].iloc[0], 3)

    def test_missing_and_garbled(self):
        with self.assertRaisesRegex(common.TrialsError, "nowhere.csv: no such file"):
            common.load_trials("/nonexistent/nowhere.csv")
        path = self.write("a,b\r\n1,2\r\n")
        with self.assertRaisesRegex(common.TrialsError, "missing columns"):
            common.load_trials(path)
        path = self.write("")
        with self.assertRaisesRegex(common.TrialsError, "not a readable CSV"):
            common.load_trials(path)


# --------------------------------------------------------------------------------------------------------------------
# The side-bias (forced_choice.side_bias) and display-timing (frame_timing) sections


def wilson_closed_form(k, n, z=1.959963984540054):
    """Wilson score interval written out again, independently of stats.wilson."""
    p = k / n
    centre = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z / (1 + z * z / n) * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n))
    return centre - half, centre + half


class TempDirCase(unittest.TestCase):
    def setUp(self):
        common.setup_style()
        self.tmp = tempfile.mkdtemp(prefix="blurcue-sections-")
        self.addCleanup(shutil.rmtree, self.tmp, True)


def fc_rows(study, participant, choices, practice=0, swapped=0):
    """Minimal forced-choice rows (the columns forced_choice.side_bias reads)."""
    rows = []
    for i, choice in enumerate(choices):
        sw = swapped if swapped in (0, 1) else i % 2
        left, right = ("estimated", "measured") if sw else ("measured", "estimated")
        rows.append({"study": study, "participant": participant, "practice": practice, "swapped": sw,
                     "left": left, "right": right, "choice": choice, "answered": choice != ""})
    return rows


class SideBiasTest(TempDirCase):
    # Test 1: 20 decisive answers, 14 of them "left"; plus 3 can't tell, 2 unanswered and 4 practice "left" answers,
    # which must not count. By hand (z^2 = 3.841458821, d = 1 + z^2/20 = 1.192072941):
    #   centre = (0.7 + 0.096036470) / d = 0.667775; half = (z/d) sqrt(0.0105 + 0.002400912) = 1.644162 x 0.113582
    #   = 0.186748  ->  [0.481027, 0.854523]
    #   binomial: C(20, 14..20) = 38760 + 15504 + 4845 + 1140 + 190 + 20 + 1 = 60460; p = 2 x 60460 / 2^20 = 0.115318
    # Test 2: 10 decisive, 5 left -> share 0.5, p = 1. Pooled: 19 of 30.
    def frame(self):
        t1 = fc_rows("test1-static-grids", "P1", ["left"] * 8 + ["right"] * 2 + ["cant_tell"] * 3 + [""] * 2,
                     swapped=0)
        t1 += fc_rows("test1-static-grids", "P2", ["left"] * 6 + ["right"] * 4, swapped=1)
        t1 += fc_rows("test1-static-grids", "P1", ["left"] * 4, practice=1)
        t2 = fc_rows("test2-moving-balls", "P1", ["left", "right"] * 5, swapped="alternate")
        for r in t2:
            r["pattern_left"], r["pattern_right"] = "measured", "estimated"
        return pd.DataFrame(t1 + t2)

    def test_hand_computed_case(self):
        charts = forced_choice.side_bias(self.frame(), self.tmp)
        self.assertEqual([c.name for c in charts], ["side-bias", "side-bias-per-participant"])
        self.assertTrue(os.path.isfile(os.path.join(self.tmp, "side-bias.png")))
        self.assertTrue(os.path.isfile(os.path.join(self.tmp, "side-bias.svg")))
        t = charts[0].table.set_index("study")
        self.assertEqual(list(t.index), ["test1-static-grids", "test2-moving-balls", "pooled"])

        t1 = t.loc["test1-static-grids"]
        self.assertEqual((t1["decisive"], t1["n_left"], t1["n_right"]), (20, 14, 6))
        self.assertAlmostEqual(t1["share_left"], 0.7)
        self.assertAlmostEqual(t1["share_left_low"], 0.481027, places=5)
        self.assertAlmostEqual(t1["share_left_high"], 0.854523, places=5)
        low, high = wilson_closed_form(14, 20)
        self.assertAlmostEqual(t1["share_left_low"], low, places=10)
        self.assertAlmostEqual(t1["share_left_high"], high, places=10)
        # Two participants: too few for a test across participants, said so, no p (their 20 answers pooled gave
        # the binomial p 0.115 as if independent).
        self.assertTrue(t1["test"].startswith("none: 2 participants"), t1["test"])
        self.assertTrue(math.isnan(t1["p"]))
        self.assertNotIn("p_binom", t.columns)
        # P1 (swapped = 0) had measured on the left for 10 answers, P2 (swapped = 1) for none of 10.
        self.assertAlmostEqual(t1["first_on_left"], 0.5)

        t2 = t.loc["test2-moving-balls"]  # one participant: the exact binomial test of that participant's answers
        self.assertEqual((t2["decisive"], t2["n_left"]), (10, 5))
        self.assertAlmostEqual(t2["p"], 1.0)
        pooled = t.loc["pooled"]
        self.assertEqual((pooled["decisive"], pooled["n_left"]), (30, 19))
        self.assertTrue(math.isnan(pooled["p"]))  # P1 and P2 across the studies: two participants

        per_p = charts[1].table
        p1 = per_p[(per_p["study"] == "test1-static-grids") & (per_p["participant"] == "P1")].iloc[0]
        self.assertEqual((p1["decisive"], p1["n_left"]), (10, 8))
        self.assertAlmostEqual(p1["p_binom"], binom_two_sided_half(8, 10), places=12)
        self.assertEqual(set(per_p["study"]), {"test1-static-grids", "test2-moving-balls", "pooled"})
        # Test 1 is counterbalanced by participant: each one saw measured on one side only, and a note says so.
        self.assertTrue(any("always on the same side" in n for n in charts[1].notes), charts[1].notes)

    def test_a_studys_side_bias_is_tested_with_participants_as_the_unit(self):
        # Four participants choosing left in 8, 7, 9 and 6 of 10 decisive answers: shares 0.8, 0.7, 0.9, 0.6, mean
        # 0.75, deviations +-0.05, +-0.15: sd = sqrt(0.05 / 3) = 0.1290994; t = 0.25 / (0.1290994 / 2) = 3.872983 on
        # 3 df. The answers pooled (30 of 40) would give the binomial p 0.0022 as if 40 answers were independent.
        rows = []
        for i, left in enumerate([8, 7, 9, 6]):
            rows += fc_rows("test1-static-grids", f"P{i}", ["left"] * left + ["right"] * (10 - left), swapped=i % 2)
        t = forced_choice.side_bias(pd.DataFrame(rows), self.tmp)[0].table.set_index("study")
        t1 = t.loc["test1-static-grids"]
        self.assertEqual((t1["decisive"], t1["n_left"]), (40, 30))
        self.assertAlmostEqual(t1["participant_mean"], 0.75, places=12)
        # All four above 0.5 by different amounts: of the 2^4 sign patterns only all + and all - reach |sum| 1.0.
        self.assertAlmostEqual(t1["p"], sign_flip_by_hand([0.8, 0.7, 0.9, 0.6]), places=12)
        self.assertAlmostEqual(t1["p"], 2 / 16, places=12)
        self.assertNotIn("p_sign", t.columns)  # one test behind p, p_holm and the chart
        self.assertTrue(t1["test"].startswith("exact sign-flip permutation test of 4 participants"), t1["test"])

    def test_no_forced_choice_answers_is_a_skip(self):
        df = pd.DataFrame(fc_rows("test1-static-grids", "P1", ["cant_tell", ""]))
        with self.assertRaises(common.Skip) as e:
            forced_choice.side_bias(df, self.tmp)
        self.assertIn("no decisive", str(e.exception))
        df = pd.DataFrame([{"study": "pre-research-depth-matching", "participant": "P1", "practice": 0}])
        with self.assertRaises(common.Skip) as e:
            forced_choice.side_bias(df, self.tmp)
        self.assertIn("no forced-choice trials", str(e.exception))


class PerPatternUnitTest(TempDirCase):
    """Tests 2 and 3 per pattern and per section test participants, not pooled answers (issue 23): each
    participant's share of the first source among decisive answers, t across them against 0.5 with a sign test beside
    it; scipy's ttest_1samp and binomtest on shares counted by hand are the truth."""

    @staticmethod
    def rows(participant, n_first, n_second, pattern=2, section=None, cant=0):
        out = fc_rows("test2-moving-balls", participant, ["left"] * n_first + ["right"] * n_second
                      + ["cant_tell"] * cant, swapped=0)
        for r in out:
            r.update(pattern_left="measured", pattern_right="estimated", pattern_id=pattern, speed_cm_s=3.0,
                     section=section if section is not None else math.nan)
        return out

    def test_per_pattern_exact_sign_flip_across_participants(self):
        counts = {"P1": (8, 2), "P2": (6, 4), "P3": (9, 1), "P4": (3, 7)}
        df = pd.DataFrame(sum((self.rows(p, *c, cant=2) for p, c in counts.items()), []))
        t = forced_choice.per_pattern(df, self.tmp, "test2-moving-balls")[0].table.iloc[0]
        # Deviations +0.3, +0.1, +0.4, -0.2, sum 0.6. Signs on (0.3, 0.1, 0.4, 0.2) whose sum reaches |0.6|: ++++
        # (1.0), +++- (0.6), +-++ (0.8) and their three mirror images; every other pattern sums to 0.4 or less
        # (-+++ 0.4, +-+- 0.4, ++-+ 0.2, ...): 6 of 16.
        self.assertAlmostEqual(float(t["p"]), sign_flip_by_hand([0.8, 0.6, 0.9, 0.3]), places=12)
        self.assertAlmostEqual(float(t["p"]), 6 / 16, places=12)
        self.assertAlmostEqual(float(t["participant_mean"]), 0.65, places=12)
        self.assertEqual((int(t["participants_above"]), int(t["participants_below"])), (3, 1))
        self.assertIn("sign-flip", t["test"])
        for gone in ("p_binom", "p_sign", "t"):
            self.assertNotIn(gone, t.index)
        # Pooled answers (26 of 40) would say p = 0.08; the participants' test says 0.375.
        self.assertAlmostEqual(float(t["p_holm"]), float(t["p"]))

    def test_per_section_with_one_participant_is_the_exact_binomial_said_so(self):
        from scipy import stats as sps
        df = pd.DataFrame(self.rows("P1", 9, 1, pattern=2, section=1) + self.rows("P1", 4, 6, pattern=2, section=2))
        t = forced_choice.per_section(df, self.tmp, "test2-moving-balls")[0].table.set_index("section")
        self.assertAlmostEqual(float(t.loc[1, "p"]), sps.binomtest(9, 10, 0.5).pvalue, places=12)
        self.assertAlmostEqual(float(t.loc[2, "p"]), sps.binomtest(4, 10, 0.5).pvalue, places=12)
        self.assertIn("one participant", t.loc[1, "test"])

    def test_one_decisive_answer_of_one_participant_is_no_test_said_in_words(self):
        # A cell of one decisive answer: the exact binomial of 1 of 1 at 0.5 is p = 1 whichever side it is (scipy:
        # binomtest(1, 1) = binomtest(0, 1) = 1), a statistic that means nothing; the report printed "exact
        # binomial, p = 1". Section 1 here has one measured answer (and a can't tell), section 2 ten answers.
        df = pd.DataFrame(self.rows("P1", 1, 0, pattern=2, section=1, cant=1)
                          + self.rows("P1", 9, 1, pattern=2, section=2))
        t = forced_choice.per_section(df, self.tmp, "test2-moving-balls")[0].table.set_index("section")
        self.assertEqual(int(t.loc[1, "decisive"]), 1)
        self.assertTrue(math.isnan(float(t.loc[1, "p"])), t.loc[1, "p"])
        self.assertTrue(math.isnan(float(t.loc[1, "p_holm"])))
        self.assertEqual(t.loc[1, "test"], "none: one answer cannot test anything (one way or the other, guessing "
                                           "gives either often)")
        # The other cell keeps its test, and Holm adjusts over the one p there is.
        from scipy import stats as sps
        self.assertAlmostEqual(float(t.loc[2, "p"]), sps.binomtest(9, 10, 0.5).pvalue, places=12)
        self.assertAlmostEqual(float(t.loc[2, "p_holm"]), float(t.loc[2, "p"]), places=12)
        # At another chance level too (odd one out of 3: a correct answer's p would be 1/3).
        r = study_tests.against_chance_counts([1], [1], 1 / 3)
        self.assertTrue(math.isnan(r["p"]) and r["test"].startswith("none: one answer"), r)
        # The summary's line for one participant's single answer says it in words, with no p.
        one = pd.DataFrame({"participant": ["P1"], "y": [1.0]})
        words = study_tests.summary_words(one, 0.5, "share correct")
        self.assertIn("one answer cannot test anything", words)
        self.assertNotIn("p =", words)

    def test_one_participants_few_answers_say_how_low_p_can_go(self):
        # 3 answers at 0.5: the smallest two-sided p is 2 / 2^3 = 0.25 (all three one way), so no p can reach 0.05;
        # 6 answers: 2 / 64 = 0.03125 can.
        r = study_tests.against_chance_counts([3], [3], 0.5)
        self.assertAlmostEqual(r["p"], 0.25, places=12)
        self.assertEqual(r["test"], "exact binomial, one participant's answers (with 3 answers no p can be below 0.25)")
        r = study_tests.against_chance_counts([6], [6], 0.5)
        self.assertAlmostEqual(r["p"], 2 / 64, places=12)
        self.assertEqual(r["test"], "exact binomial, one participant's answers")

    def test_one_participant_of_several_in_a_cell_is_said_in_the_singular(self):
        # Three in the analysis, one with answers in this cell: "1 participant is too few", not "1 participants are".
        r = study_tests.against_chance_counts([4], [5], 0.5, people=3)
        self.assertTrue(math.isnan(r["p"]))
        self.assertTrue(r["test"].startswith("none: 1 participant is too few for a test across participants"), r)
        r = study_tests.against_chance_counts([4, 1], [5, 5], 0.5, people=3)
        self.assertTrue(r["test"].startswith("none: 2 participants are too few"), r)

    def test_a_participants_single_decisive_answer_has_no_side_bias_p(self):
        rows = fc_rows("test1-static-grids", "P1", ["left"] * 8 + ["right"] * 2) + \
            fc_rows("test1-static-grids", "P2", ["left", "cant_tell"], swapped=1)
        per_p = forced_choice.side_bias(pd.DataFrame(rows), self.tmp)[1].table
        p2 = per_p[(per_p["study"] == "test1-static-grids") & (per_p["participant"] == "P2")].iloc[0]
        self.assertEqual(int(p2["decisive"]), 1)
        self.assertTrue(math.isnan(p2["p_binom"]) and math.isnan(p2["p_holm"]), p2)
        p1 = per_p[(per_p["study"] == "test1-static-grids") & (per_p["participant"] == "P1")].iloc[0]
        self.assertAlmostEqual(p1["p_binom"], binom_two_sided_half(8, 10), places=12)
        self.assertAlmostEqual(p1["p_holm"], p1["p_binom"], places=12)  # the one p of its study

class FrameTimingTest(TempDirCase):
    # Window session 7: two trials of 30 intervals each, 29 x 16.7 ms and one 50 ms in each -> 62 flips, 60
    # intervals (the step from trial 0's last flip to trial 1's first is not one). Sorted: 58 x 16.7, 2 x 50.
    #   median: 16.7; p95 at rank 0.95 x 59 = 56.05 -> between two 16.7s = 16.7;
    #   p99 at rank 0.99 x 59 = 58.41 -> between ranks 58 and 59, both 50 -> 50; max 50;
    #   dropped (> 25 ms): 2, share 2/60. The headless session 8 (250 ms flips) is left out.
    # Window session 9: one trial, 99 x 16.7 ms and one 50 ms -> p99 at rank 0.99 x 99 = 98.01:
    #   16.7 + 0.01 x (50 - 16.7) = 17.033 (linear interpolation between ranks).
    def frames(self):
        rows = synthetic.frames_rows("test1-static-grids", "W1", 7, True,
                                     [[16.7] * 29 + [50.0], [16.7] * 10 + [50.0] + [16.7] * 19])
        rows += synthetic.frames_rows("test1-static-grids", "P1", 8, False, [[250.0] * 20] * 3)
        rows += synthetic.frames_rows("test2-moving-balls", "W2", 9, True, [[16.7] * 50 + [50.0] + [16.7] * 49])
        return synthetic.write_frames_csv(os.path.join(self.tmp, "run", "frames.csv"), rows)

    def test_summary_against_known_intervals(self):
        frames = frame_timing.load_frames(self.frames())
        t = frame_timing.summary(frames[frames["window"] == 1]).set_index("session")
        s7 = t.loc[7]
        self.assertEqual((s7["trials"], s7["frames"], s7["intervals"], s7["dropped"]), (2, 62, 60, 2))
        self.assertAlmostEqual(s7["median_ms"], 16.7, places=6)
        self.assertAlmostEqual(s7["p95_ms"], 16.7, places=6)
        self.assertAlmostEqual(s7["p99_ms"], 50.0, places=6)
        self.assertAlmostEqual(s7["max_ms"], 50.0, places=6)
        self.assertAlmostEqual(s7["dropped_share"], 2 / 60)
        self.assertEqual(s7["long_vs_median"], 2)
        s9 = t.loc[9]
        self.assertEqual((s9["intervals"], s9["dropped"]), (100, 1))
        self.assertAlmostEqual(s9["p99_ms"], 16.7 + 0.01 * (50 - 16.7), places=6)
        self.assertNotIn(8, t.index)

    def test_chart_and_headless_left_out(self):
        charts = frame_timing.charts(self.frames(), self.tmp)
        self.assertEqual([c.name for c in charts], ["frame-intervals"])
        self.assertTrue(os.path.isfile(os.path.join(self.tmp, "frame-intervals.png")))
        self.assertTrue(os.path.isfile(os.path.join(self.tmp, "frame-intervals.svg")))
        self.assertEqual(list(charts[0].table["session"]), [7, 9])
        self.assertTrue(any("1 headless session left out" in n for n in charts[0].notes), charts[0].notes)

    def test_gap_in_frame_index_is_not_an_interval(self):
        rows = synthetic.frames_rows("test1-static-grids", "W1", 1, True, [[16.7] * 5])
        del rows[3]  # frame 3: intervals 1-2 and 4-5 stay, 2-3 and 3-4 go
        iv = frame_timing.intervals(pd.DataFrame(rows).rename(columns={"session_id": "session"}))
        self.assertEqual(list(iv["frame_index"]), [1, 2, 5])

    def test_headless_only_is_a_skip(self):
        rows = synthetic.frames_rows("test1-static-grids", "P1", 8, False, [[250.0] * 20] * 3)
        path = synthetic.write_frames_csv(os.path.join(self.tmp, "frames.csv"), rows)
        with self.assertRaises(common.Skip) as e:
            frame_timing.charts(path, self.tmp)
        self.assertIn("no window sessions", str(e.exception))
        self.assertIn("simulated clock", str(e.exception))

    def test_missing_or_old_file_is_a_skip(self):
        missing = os.path.join(self.tmp, "nope", "frames.csv")
        with self.assertRaises(common.Skip) as e:
            frame_timing.charts(missing, self.tmp)
        self.assertIn(missing + ": no such file", str(e.exception))
        old = os.path.join(self.tmp, "frames.csv")
        with open(old, "w") as f:  # an export from before the window column
            f.write("study,participant,session,trial_index,frame_index,flip_time_s,dropped\r\n"
                    "test1-static-grids,P1,1,0,0,0,0\r\n")
        with self.assertRaises(common.Skip) as e:
            frame_timing.charts(old, self.tmp)
        self.assertIn("no window column", str(e.exception))
        self.assertFalse(os.path.isfile(os.path.join(self.tmp, "frame-intervals.png")))


if __name__ == "__main__":
    unittest.main()
