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


def _procedure_rows(n, participant, observer, spec, correct, r_left=6.0, r_right=4.0, **more):
    return pd.DataFrame({
        "study": ["s"] * n, "participant": [participant] * n, "observer": [observer] * n,
        "observer_params": [spec] * n, "practice": [0] * n, "status": ["answered"] * n,
        "task": ["forced_choice"] * n, "chosen_side": ["left"] * n, "chosen_interval": [""] * n,
        "level": [0.5] * n, "correct": correct, "chose_more_blurred": [""] * n, "test_side": ["left"] * n,
        "r_left_arcmin": [r_left] * n, "r_right_arcmin": [r_right] * n, "r_scene_arcmin": [4.0] * n,
        "r_left_px": [r_left / 1.5] * n, "r_right_px": [r_right / 1.5] * n, "r_scene_px": [4.0 / 1.5] * n, **more})


class RecordedParameters(unittest.TestCase):
    """Each session is predicted with the observer parameters it recorded (issue 38: the report used the defaults for
    every session), a person's with the defaults; the truth is the model's formula worked by hand here."""

    def test_each_session_is_predicted_with_its_recorded_parameters(self):
        spec = "sim:model=arcmin,intrinsic=1,weber=0.8,exponent=2,side=0,blurrier=0.3,rthard=0.5,lapse=0.1,rt=900,step=350"
        d = pd.concat([_procedure_rows(10, "S1", "simulated", spec, ["1"] * 10),
                       _procedure_rows(10, "P1", "person", "", ["1"] * 10)], ignore_index=True)
        m = prediction.predicted(d)
        phi = lambda x: 0.5 * math.erfc(-x / math.sqrt(2))  # noqa: E731
        # E(s) = sqrt(s^2 + s_i^2) of s = r / 2: 3 and 2 arcmin; sd = ln(1 + weber) / z75.
        sim = 0.1 / 2 + 0.9 * phi(abs(0.5 * math.log((9 + 1) / (4 + 1))) / (math.log(1.8) / 0.6744897501960817))
        person = 0.04 / 2 + 0.96 * phi(abs(0.5 * math.log((9 + 0.36) / (4 + 0.36))) / (math.log(1.35) / 0.6744897501960817))
        got = m.groupby("participant")["predicted"].first()
        self.assertAlmostEqual(float(got["S1"]), sim, places=12)
        self.assertAlmostEqual(float(got["P1"]), person, places=12)
        self.assertIn("weber 0.8", m[m["participant"] == "S1"]["model"].iloc[0])
        self.assertIn("the defaults", m[m["participant"] == "P1"]["model"].iloc[0])

    def test_a_pixel_session_is_predicted_from_its_photo_px_radii(self):
        # The record of before model= existed: sim:jnd=...,bias=... is the pixel model, P = Phi(|r_l - r_r| / jnd).
        d = _procedure_rows(4, "S1", "simulated", "sim:jnd=0.5,bias=0.2,lapse=0,rt=900,step=350", ["1"] * 4)
        m = prediction.predicted(d)
        expect = 0.5 * math.erfc(-(abs(6.0 / 1.5 - 4.0 / 1.5) / 0.5) / math.sqrt(2))
        self.assertAlmostEqual(float(m["predicted"].iloc[0]), expect, places=12)

    def test_the_side_bias_recorded_moves_the_prediction(self):
        # Equal radii: only the side bias (in noise sds) decides; the test side on the left is chosen Phi(side).
        d = _procedure_rows(2, "S1", "simulated", "sim:model=arcmin,side=0.5,lapse=0", ["1", "1"], r_left=4.0)
        m = prediction.predicted(d)
        self.assertAlmostEqual(float(m["predicted"].iloc[0]), 0.5 * math.erfc(-0.5 / math.sqrt(2)), places=12)


class HolmOverTheConditions(unittest.TestCase):
    def test_a_condition_departs_only_after_holms_correction(self):
        # Ten conditions of 40 trials at a predicted 0.5; one has 28 of 40 (exact two-sided p = 0.0166: its Wilson
        # interval excludes 0.5, which flagged it before), the rest 20 of 40 (p = 1). Holm: 10 x 0.0166 > 0.05, so
        # nothing departs; one of 36 of 40 (p < 1e-6) departs after it too.
        from scipy.stats import binomtest
        rows = []
        for c in range(10):
            k = 28 if c == 0 else 36 if c == 1 else 20
            rows.append(pd.DataFrame({"edge": [c + 1] * 40, "y": [1] * k + [0] * (40 - k), "predicted": [0.5] * 40,
                                      "participant": ["P1"] * 40}))
        t = prediction.condition_table(pd.concat(rows, ignore_index=True), ["edge"]).set_index("edge")
        p28 = binomtest(28, 40, 0.5).pvalue
        p36 = binomtest(36, 40, 0.5).pvalue
        self.assertAlmostEqual(float(t.loc["1", "p"]), p28, places=12)
        self.assertLess(float(t.loc["1", "observed_low"]), 1)  # its interval excludes the prediction ...
        self.assertGreater(float(t.loc["1", "observed_low"]), 0.5)
        self.assertAlmostEqual(float(t.loc["1", "p_holm"]), min(1.0, 9 * p28), places=12)  # second smallest of 10
        self.assertAlmostEqual(float(t.loc["2", "p_holm"]), 10 * p36, places=12)
        self.assertFalse(bool(t.loc["1", "departs"]))  # ... but not after Holm over the ten
        self.assertTrue(bool(t.loc["2", "departs"]))
        self.assertEqual(int(t["departs"].sum()), 1)


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
