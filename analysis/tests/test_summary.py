"""The report's summary line of a study: never a figure pooled across levels that ask different questions (a factor
that changes which sources a pair compares), checked against hand-worked shares and exact p-values."""
import os
import sys
import tempfile
import unittest

import pandas as pd

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
import any_study  # noqa: E402
import design  # noqa: E402
import across_observers  # noqa: E402
import study_tests  # noqa: E402

# twofac.json's design: edge 3, 6, 9 x comparison (measured vs none, measured vs estimated), sides swapped in half.
COMPARISONS = {"left=measured;right=none": ("measured", "none"),
               "left=measured;right=estimated": ("measured", "estimated")}
# Each of 6 participants' answers (1 = chose the more blurred side) per comparison, 8 answers each (edges pooled):
# measured vs none 6, 7, 8, 7, 8, 8 of 8; measured vs estimated 4, 3, 5, 4, 4, 5 of 8.
CHOSE = {"left=measured;right=none": [6, 7, 8, 7, 8, 8], "left=measured;right=estimated": [4, 3, 5, 4, 4, 5]}


def twofac_rows():
    rows = []
    for comparison, (first, second) in COMPARISONS.items():
        for i, k in enumerate(CHOSE[comparison]):
            for j in range(8):
                swapped = j % 2
                left, right = (second, first) if swapped else (first, second)
                rows.append({"participant": f"P{i + 1}", "comparison": comparison, "edge": str(3 + 3 * (j % 3)),
                             "swapped": str(swapped),
                             "left_source": left, "right_source": right, "y": float(j < k)})
    return pd.DataFrame(rows)


class NotPooledAcrossQuestions(unittest.TestCase):
    def test_comparison_changes_the_sources_compared_and_edge_does_not(self):
        m = twofac_rows()
        self.assertEqual(design.comparing_factors(m, ["comparison", "edge"]), ["comparison"])
        # Sides swapped are the same question: the sides' order is not a factor that changes it.
        self.assertEqual(design.comparing_factors(m, ["swapped", "edge"]), [])

    def test_the_summary_goes_per_comparison_with_holm_over_its_levels(self):
        m = twofac_rows()
        words = study_tests.summary_by_level(m, 0.5, "chose the more blurred side", ["comparison"])
        # By hand: measured vs none, shares 6/8 .. 8/8, mean 44/48 = 0.917, every participant above 0.5, so the exact
        # sign-flip test's p is 2 / 2^6 = 0.03125; measured vs estimated, mean 25/48 = 0.521, p = 1 (deviations
        # 0, -1/8, 1/8, 0, 0, 1/8: 2^6 patterns, all at least as far from 0 as 1/8). Holm over 2: 0.0625 and 1.
        self.assertIn("comparison left=measured;right=none: chose the more blurred side: mean of 6 participants' "
                      "shares 0.92", words)
        self.assertIn("p = 0.062 (Holm over 2 levels)", words)
        self.assertIn("comparison left=measured;right=estimated: chose the more blurred side: mean of 6 "
                      "participants' shares 0.52", words)
        self.assertIn("p = 1.000 (Holm over 2 levels)", words)
        self.assertIn("no pooled figure", words)
        # Neither level can reach 0.05: said once, with the smallest p attainable, 2 x 2/2^6 = 0.0625.
        self.assertEqual(words.count("none of the 2 levels can reach p < 0.05 after Holm's correction: the smallest "
                                     "p attainable is 0.0625"), 1, words)
        # The pooled mean (69/96 = 0.72) of the two questions is nowhere.
        self.assertNotIn("0.72", words)



class SmallestAttainableP(unittest.TestCase):
    """Six cells of 6 participants Holm-adjusted: the sign-flip test's least p is 2/2^6 = 1/32, and Holm's first step
    multiplies it by 6, so no cell can reach 0.05 (0.1875); with 8 participants 6 x 2/2^8 = 0.047 can."""

    def table(self, people, cells=6, answers=24):
        return pd.DataFrame({"participants": [people] * cells, "n": [answers] * cells, "p": [0.5] * cells})

    def test_six_cells_of_six_participants_cannot_reach_005(self):
        words = study_tests.holm_floor_words(self.table(6), 0.5, 6)
        self.assertIn("none of the 6 conditions can reach p < 0.05 after Holm's correction: the smallest p "
                      "attainable is 0.188 (6 tests x 0.0312", words)
        self.assertIn("0.0938", study_tests.holm_floor_words(self.table(7), 0.5, 7))  # 6 x 2/128

    def test_silent_where_a_cell_can_reach_it_or_is_alone(self):
        self.assertEqual(study_tests.holm_floor_words(self.table(8), 0.5, 8), "")      # 6 x 2/256 = 0.047
        self.assertEqual(study_tests.holm_floor_words(self.table(4, cells=1), 0.5, 4), "")  # its test says it

    def test_one_participants_binomial_floor(self):
        # One participant, 4 answers per cell, 3 cells: the exact binomial's least p is 2 x 0.5^4 = 0.125; x 3 = 0.375.
        words = study_tests.holm_floor_words(self.table(1, cells=3, answers=4), 0.5, 1)
        self.assertIn("the smallest p attainable is 0.375 (3 tests x 0.125", words)


class TwoParticipantsNoModel(unittest.TestCase):
    def test_two_participants_get_no_model_across_them_in_words(self):
        # Two participants, edges 5 and 8, 12 answers each: a cluster-robust GLM would be a sandwich of two residual
        # sums referred to t(1) (it printed "edge 5: 1.386, SE not determined"); a GLMM's spread from two likewise.
        rows = []
        for who, (at5, at8) in {"P1": (9, 12), "P2": (10, 12)}.items():
            for edge, k in (("5", at5), ("8", at8)):
                rows += [{"participant": who, "edge": edge, "y": float(j < k)} for j in range(12)]
        table, notes = across_observers.observer_models(pd.DataFrame(rows), "y", "0 + C(edge)", study="s")
        self.assertTrue(table.empty, table)
        self.assertEqual(len(notes), 1, notes)
        self.assertTrue(notes[0].startswith("two participants: too few for a model across participants"), notes)


class WhatTheMeasureMeans(unittest.TestCase):
    """A pair study's measure is "chose the more blurred side" (the thesis's views alone count the first source): the
    summary says which source that was, and where it changes between conditions."""

    def rows(self, radii):
        """One row per edge and side order: radii {edge: (r measured, r estimated)} in arcmin."""
        out = []
        for edge, (r_m, r_e) in radii.items():
            for swapped in (0, 1):
                left, right = (("estimated", r_e), ("measured", r_m)) if swapped else (("measured", r_m),
                                                                                        ("estimated", r_e))
                out.append({"edge": edge, "left_source": left[0], "right_source": right[0],
                            "r_left_arcmin": str(left[1]), "r_right_arcmin": str(right[1])})
        return pd.DataFrame(out)

    def test_the_same_source_everywhere_is_named(self):
        words = any_study.more_blurred_words(self.rows({"2": (0.48, 0.99), "5": (1.69, 2.18)}), ["edge"])
        self.assertEqual(words, "; between estimated and measured, the more blurred side showed estimated in every "
                                "condition")

    def test_a_source_that_changes_between_edges_is_said(self):
        # The lens model's estimate above the measurement at edges 3 and 6, below it at edge 9.
        words = any_study.more_blurred_words(self.rows({"3": (1.0, 1.3), "6": (2.0, 2.2), "9": (3.4, 3.1)}),
                                             ["edge"])
        self.assertIn("the more blurred side showed estimated at edge 3, edge 6; measured at edge 9: the share "
                      "means choosing a different source where that changes", words)


if __name__ == "__main__":
    unittest.main()


class FactorBarsNotTestedAcrossQuestions(unittest.TestCase):
    def test_a_factors_bars_pooling_the_comparisons_draw_no_test(self):
        # Per edge, each bar pools measured vs none with measured vs estimated (0.92 and 0.52 by hand above): a test of
        # that mean against chance (it was starred) answers no question the study asked. Per comparison, each bar is
        # one question: tested.
        m = twofac_rows()
        d = design.Design(within=("comparison", "edge"))
        with tempfile.TemporaryDirectory() as out:
            charts, _ = any_study._analyse_rows(m, "pair", 0.5, "chose the more blurred side", d, None, "twofac", out,
                                                "twofac", "6 participants", 0, 1)
        by_name = {c.name: c for c in charts}
        edge, comparison = by_name["twofac-per-edge"], by_name["twofac-per-comparison"]
        self.assertNotIn("p_holm", edge.table.columns)
        self.assertIn("no test against chance: each bar pools the levels of comparison, which compare other sources",
                      " ".join(edge.notes))
        self.assertIn("p_holm", comparison.table.columns)
        self.assertNotIn("no test against chance", " ".join(comparison.notes))

