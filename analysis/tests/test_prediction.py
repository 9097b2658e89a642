"""The report's observer model (prediction.py) against the C++ closed form's shared table, and its pair choice
against the C++ observer's own rule worked by hand."""
import csv
import math
import os
import unittest

import numpy as np
import pandas as pd

import prediction

TABLE = os.path.join(os.path.dirname(__file__), "..", "..", "tests", "data", "observer-2afc.csv")


class ClosedFormTest(unittest.TestCase):
    def test_matches_the_cpp_table(self):
        with open(TABLE) as f:
            rows = list(csv.DictReader(line for line in f if not line.startswith("#")))
        self.assertGreaterEqual(len(rows), 10)
        for r in rows:
            got = float(prediction.p_correct_2afc(float(r["r_a_arcmin"]), float(r["r_b_arcmin"])))
            self.assertAlmostEqual(got, float(r["p_correct"]), places=12, msg=r)

    def test_pair_choice_without_a_difference_is_the_blurrier_bias(self):
        # Both sides as far from the scene (in ln E) and equally blurred: mu = 0, so P(left) = P(right) =
        # lapse / 3 + (1 - lapse) Phi(-1/2) with can't tell, and the three sum to 1.
        left, right, cant = prediction.pair_choice(np.array([2.0]), np.array([2.0]), np.array([2.0]))
        expect = 0.04 / 3 + 0.96 * 0.5 * math.erfc(0.5 / math.sqrt(2))
        self.assertAlmostEqual(float(left[0]), expect, places=12)
        self.assertAlmostEqual(float(right[0]), expect, places=12)
        self.assertAlmostEqual(float(left[0] + right[0] + cant[0]), 1.0, places=12)

    def test_pair_choice_prefers_the_side_nearer_the_scene(self):
        # Left at the scene's blur, right far off: left nearly always (up to the lapse's share); strict 2AFC.
        left, right, cant = prediction.pair_choice(np.array([3.0]), np.array([30.0]), np.array([3.0]), cant_tell=False)
        self.assertAlmostEqual(float(left[0]), 0.02 + 0.96, places=5)
        self.assertAlmostEqual(float(cant[0]), 0.0, places=12)

    def test_predicted_rows_and_departures(self):
        # A procedure row (correct against P2afc with lapse) and a pair row; a condition whose observed share is far
        # from the prediction departs.
        d = pd.DataFrame({
            "study": ["s"] * 40, "participant": ["P1"] * 20 + ["P2"] * 20, "observer": ["person"] * 40,
            "practice": [0] * 40, "status": ["answered"] * 40, "task": ["forced_choice"] * 40,
            "chosen_side": ["left"] * 40, "chosen_interval": [""] * 40, "level": [0.5] * 40,
            "correct": ["0"] * 40, "chose_more_blurred": [""] * 40,
            "r_left_arcmin": [6.0] * 40, "r_right_arcmin": [4.0] * 40, "r_scene_arcmin": [4.0] * 40})
        m = prediction.predicted(d)
        self.assertEqual(len(m), 40)
        p = 0.02 + 0.96 * float(prediction.p_correct_2afc(6.0, 4.0))
        self.assertAlmostEqual(float(m["predicted"].iloc[0]), p, places=12)
        t = prediction.condition_table(m, [])
        self.assertTrue(bool(t["departs"].iloc[0]))  # 0 of 40 correct against ~0.79


class LevelsInTheTable(unittest.TestCase):
    def test_a_level_a_row_does_not_have_is_blank_not_nan(self):
        # Task 1 rows of test 2 have no section: their cell is blank (not applicable), never the text "nan" that
        # report_numbers_check.py flags as a number meaning "not determined".
        m = pd.DataFrame({"section": [1.0, 1.0, np.nan], "y": [1, 0, 1], "predicted": [0.5, 0.5, 0.5],
                          "participant": ["P1"] * 3})
        t = prediction.condition_table(m, ["section"])
        self.assertEqual(sorted(t["section"]), ["", "1"])


class PerGroupTest(unittest.TestCase):
    def test_between_subject_groups_are_never_pooled(self):
        # Group a (P1, P2) always right, group b (P3, P4) always wrong, on the same trials: each group's table holds
        # its own share (hand count: 20 of 20 and 0 of 20), never the pooled 20 of 40 (issue 23: prediction.py
        # pooled between-subject groups).
        import tempfile
        from design import Column
        n = 10
        d = pd.DataFrame({
            "study": ["s"] * 4 * n, "participant": sum([[p] * n for p in ("P1", "P2", "P3", "P4")], []),
            "group": ["a"] * 2 * n + ["b"] * 2 * n, "observer": ["person"] * 4 * n,
            "practice": [0] * 4 * n, "status": ["answered"] * 4 * n, "task": ["forced_choice"] * 4 * n,
            "chosen_side": ["left"] * 4 * n, "chosen_interval": [""] * 4 * n, "level": [0.5] * 4 * n,
            "correct": ["1"] * 2 * n + ["0"] * 2 * n, "chose_more_blurred": [""] * 4 * n,
            "r_left_arcmin": [6.0] * 4 * n, "r_right_arcmin": [4.0] * 4 * n, "r_scene_arcmin": [4.0] * 4 * n})
        book = {"group": Column("the participant's between-subject group", frozenset({"group"}), "")}
        with tempfile.TemporaryDirectory() as out:
            charts = prediction.charts(d, out, book)
        by_slug = {c.name: c for c in charts}
        self.assertEqual(sorted(by_slug), ["s-predicted-procedure-people-group-a", "s-predicted-procedure-people-group-b"])
        a, b = by_slug["s-predicted-procedure-people-group-a"].table, by_slug["s-predicted-procedure-people-group-b"].table
        self.assertEqual((int(a["k"].iloc[0]), int(a["n"].iloc[0])), (20, 20))
        self.assertEqual((int(b["k"].iloc[0]), int(b["n"].iloc[0])), (0, 20))
        self.assertIn("group a", by_slug["s-predicted-procedure-people-group-a"].notes[0])


if __name__ == "__main__":
    unittest.main()
