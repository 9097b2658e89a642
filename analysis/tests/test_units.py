"""A report a reviewer can check (issue 38, item 5): every level with its unit (common.level_unit, axis_label,
factor_label), levels at the precision the protocol gave them (common.level_text), and a threshold's criterion as the
fitted function gives it (criteria.Criterion.label)."""
import json
import math
import os
import tempfile
import unittest

import numpy as np
import pandas as pd

import common
import criteria

RELATIVE = {"procedure": "staircase", "variable": "relative_difference", "start": 0.5, "min": 0.0, "max": 1.0,
            "up": 1, "down": 2, "steps": [0.1]}
ARCMIN = {"procedure": "quest_plus", "variable": "difference_arcmin", "stimuli": [0.5, 1, 2], "thresholds": [1],
          "slopes": [3], "lapses": [0], "guess": 0.5}


class LevelUnit(unittest.TestCase):
    def test_from_a_procedures_parameters(self):
        self.assertEqual(common.level_unit(RELATIVE), "ratio - 1")
        self.assertEqual(common.level_unit(ARCMIN), "arcmin")
        self.assertEqual(common.level_unit(json.dumps(ARCMIN)), "arcmin")  # procedures.csv's JSON text

    def test_from_rows_of_trials_with_their_procedure_parameters(self):
        rows = pd.DataFrame({"procedure_parameters": [json.dumps(RELATIVE), "", json.dumps(RELATIVE)]})
        self.assertEqual(common.level_unit(rows), "ratio - 1")
        both = pd.DataFrame({"procedure_parameters": [json.dumps(RELATIVE), json.dumps(ARCMIN)]})
        self.assertEqual(common.level_unit(both), "ratio - 1 or arcmin")  # never one unit for two variables

    def test_from_the_codebook_the_export_writes(self):
        book = pd.DataFrame({"table": ["trials.csv", "trials.csv", "trials.csv"],
                             "column": ["level", "speed_cm_s", "edge"],
                             "unit": ["ratio - 1 (relative_difference: the test side's radius / the reference's - 1)",
                                      "cm/s", ""]})
        self.assertEqual(common.level_unit(book), "ratio - 1")
        self.assertEqual(common.level_unit(book, "speed_cm_s"), "cm/s")
        self.assertEqual(common.level_unit(book, "edge"), "")
        with tempfile.TemporaryDirectory() as d:
            book.to_csv(os.path.join(d, "codebook.csv"), index=False)
            open(os.path.join(d, "trials.csv"), "w").close()
            self.assertEqual(common.level_unit(os.path.join(d, "trials.csv")), "ratio - 1")
        # The table's generic words (a record without a design) are no unit.
        generic = pd.DataFrame({"table": ["trials.csv"], "column": ["level"], "unit": ["the procedure's variable"]})
        self.assertEqual(common.level_unit(generic), "")

    def test_unknown_is_said_and_a_factors_name_gives_its_unit(self):
        self.assertEqual(common.level_unit(None), "")
        self.assertEqual(common.axis_label("level shown", ""), "level shown (unit not recorded)")
        self.assertEqual(common.axis_label("level shown", common.level_unit(RELATIVE)), "level shown (ratio - 1)")
        self.assertEqual(common.factor_label("speed_cm_s"), "speed_cm_s (cm/s)")
        self.assertEqual(common.factor_label("distance_m"), "distance_m (m)")
        self.assertEqual(common.factor_label("edge"), "edge")


class LevelText(unittest.TestCase):
    def test_a_level_as_the_protocol_gave_it(self):
        binary = 0.5 - 0.1 - 0.1 - 0.1
        self.assertNotEqual(binary, 0.2)
        self.assertEqual(common.level_text(binary), "0.2")
        self.assertEqual(common.level_text("0.19999999999999996"), "0.2")
        self.assertEqual(common.level_text("3.0"), "3")
        self.assertEqual(common.level_text(1.8), "1.8")
        self.assertEqual(common.level_text("12345678901234567"), "12345678901234567")  # digits of an id kept
        self.assertEqual(common.level_text(float("nan")), "")
        self.assertEqual(common.level_text("NA"), "NA")

    def test_a_sides_radius_says_its_unit(self):
        # protocols/yes-no-ball.json's {"object": 4}: a number is a radius in photo px.
        self.assertEqual(common.level_text("object=4"), "object=4 photo px")
        self.assertEqual(common.level_text("object=measured"), "object=measured")
        self.assertEqual(common.level_text("left=2.50;right=measured"), "left=2.5 photo px;right=measured")

    def test_the_tables_write_levels_so(self):
        import any_study
        m = pd.DataFrame({"level": [0.5 - 0.1 - 0.1 - 0.1] * 4 + [0.5] * 4, "y": [1, 0] * 4,
                          "participant": ["P1"] * 8})
        t = any_study.condition_table(m, ["level"], None)
        self.assertEqual(sorted(t["level"]), ["0.2", "0.5"])


class DepthOnTheEdgeAxis(unittest.TestCase):
    def test_test1s_edges_carry_the_grids_depth_from_trials_csv(self):
        # trials.csv's u_left_mm (the calibration's geometry) beside each edge number: 341.5 + 19.7 (edge - 1) mm here,
        # so edge 1 reads 342 mm (rounded) and edge 11 538 mm.
        import sys
        sys.path.insert(0, os.path.dirname(__file__))
        import forced_choice
        import synthetic
        with tempfile.TemporaryDirectory() as d:
            df = common.load_trials(synthetic.write_trials_csv(os.path.join(d, "trials.csv"), synthetic.trials_rows()))
            df["u_left_mm"] = [f"{341.5 + (e - 1) * 19.7:.2f}" if e == e else "" for e in df["edge"]]
            chart = forced_choice.test1_per_edge(df, d)
            chart = chart[0] if isinstance(chart, list) else chart
            with open(chart.svg, encoding="utf-8") as f:
                svg = f.read()
        self.assertIn("342 mm", svg)
        self.assertIn("538 mm", svg)
        self.assertIn("the grids' depth u (mm)", svg)


class CriterionAsFitted(unittest.TestCase):
    def test_quests_criterion_with_a_lapse_says_what_the_function_gives(self):
        c = criteria.criterion("quest_plus", ARCMIN, 0.5)
        self.assertEqual(c.short(), "81.6 % correct without lapses")
        lapse = 0.0633
        there = 0.5 + (1 - 0.5 - lapse) * (1 - math.exp(-1))  # 0.776
        self.assertAlmostEqual(c.psi(0.5, lapse), there, places=12)
        self.assertEqual(c.label(0.5, lapse), "81.6 % correct without lapses; the fitted function gives 77.6 % there "
                                              "(lapse 0.063)")
        self.assertEqual(c.label(0.5, 0.0), c.short())  # no lapse: the two are one
        # A staircase's target is a share of the answers: the same whatever the lapse.
        s = criteria.criterion("staircase", RELATIVE, 0.5)
        self.assertEqual(s.label(0.5, 0.08), s.short())

    def test_a_procedure_cells_fit_is_labelled_as_fitted_with_its_unit(self):
        import any_study
        from design import Design
        # A Weibull observer with lapses 0.08 (alpha 1, beta 3, guess 0.5): the fit's lapse is near 0.08, and the
        # threshold it reads (QUEST+'s parameter) is where the function gives 0.5 + (0.5 - lapse)(1 - 1/e).
        rng = np.random.default_rng(7)
        levels = np.repeat(np.linspace(0.3, 3.0, 10), 300)
        psi = 0.5 + (0.5 - 0.08) * (1 - np.exp(-(levels / 1.0) ** 3))
        params = dict(ARCMIN, stimuli=list(np.linspace(0.2, 3.2, 16)), thresholds=list(np.linspace(0.1, 3.0, 30)),
                      slopes=[1, 3, 5], lapses=[0, 0.04, 0.08])
        m = pd.DataFrame({"level": levels, "y": (rng.random(levels.size) < psi).astype(float), "participant": "P1",
                          "cell": "edge=9", "procedure_cell": "1", "procedure_parameters": json.dumps(params)})
        with tempfile.TemporaryDirectory() as out:
            charts, words = any_study.psychometric_cells(m, "procedure", 0.5, "correct", Design(cells=("edge",)),
                                                         "s", out, "s", "1 participant", 40, 1)
            with open(charts[0].svg, encoding="utf-8") as f:
                svg = f.read()
        row = charts[0].table.iloc[0]
        lapse = float(row["lapse"])
        self.assertGreater(lapse, 0.03)
        share = 0.5 + (0.5 - lapse) * (1 - math.exp(-1))
        self.assertAlmostEqual(float(row["criterion_share_correct"]), share, places=9)
        said = f"the fitted function gives {100 * share:.1f} % there"
        self.assertIn(said, row["criterion_fitted"])
        self.assertIn(said, words)
        self.assertIn("arcmin", words)
        self.assertIn("level shown (arcmin)", svg)
        self.assertEqual(row["unit"], "arcmin")  # the threshold table says its unit


if __name__ == "__main__":
    unittest.main()
