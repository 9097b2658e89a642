"""The report's summary line of a study: never a figure pooled across levels that ask different questions (a factor
that changes which sources a pair compares), checked against hand-worked shares and exact p-values."""
import os
import sys
import unittest

import pandas as pd

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
import any_study  # noqa: E402
import design  # noqa: E402
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
        # The pooled mean (69/96 = 0.72) of the two questions is nowhere.
        self.assertNotIn("0.72", words)



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
