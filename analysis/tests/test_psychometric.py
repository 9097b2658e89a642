"""A procedure cell's pooled psychometric fit says a number only where it is determined (house rule: a threshold whose
interval is not determined, a threshold beyond the tested range, a slope whose interval reaches a bound are words, in
the table, the chart and the summary alike), and its threshold interval comes from --boot samples, as many as asked.
"""
import json
import math
import os
import re
import sys
import tempfile
import unittest

import numpy as np
import pandas as pd

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
os.environ.setdefault("MPLCONFIGDIR", tempfile.mkdtemp(prefix="mpl-"))
import any_study  # noqa: E402
from design import Design  # noqa: E402

STAIRCASE = {"procedure": "staircase", "variable": "relative_difference", "start": 1.0, "min": 0.02, "max": 3.0,
             "up": 1, "down": 2, "steps": [0.4, 0.2, 0.1], "stop_reversals": 4}

# Edge 5 of the experimenter's 8-trial staircase (short.json, 4 simulated participants, the observer's threshold
# ~0.4-0.6): the levels shown and whether each answer was correct, as the record holds them.
SHORT_LEVELS = [1.0, 1.0, 0.6, 0.6, 0.2, 0.2, 0.02, 0.22, 1.0, 1.0, 0.6, 0.6, 0.2, 0.2, 0.02, 0.02, 1.0, 1.0, 0.6, 0.8,
                0.8, 0.7, 0.7, 0.8, 1.0, 1.0, 0.6, 0.6, 0.2, 0.2, 0.4, 0.4]
SHORT_CORRECT = [1, 1, 1, 1, 1, 1, 0, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 0, 1, 1, 1, 0, 1, 1, 1, 1, 1, 1, 0, 1, 1]


def cell_rows(levels, correct, params=STAIRCASE):
    return pd.DataFrame({"level": np.asarray(levels, float), "y": np.asarray(correct, float),
                         "participant": [f"P{i % 4 + 1}" for i in range(len(levels))], "cell": "edge=5",
                         "procedure_cell": "1", "procedure_parameters": json.dumps(params)})


def run_cells(m, n_boot=60):
    with tempfile.TemporaryDirectory() as out:
        charts, words = any_study.psychometric_cells(m, "procedure", 0.5, "correct", Design(cells=("edge",)),
                                                     "s", out, "s", "4 participants", n_boot, 1)
        with open(charts[0].svg, encoding="utf-8") as f:
            svg = f.read()
    return charts[0], words, svg


def weibull_answers(alpha, beta, levels, per_level, seed):
    """Answers of a Weibull observer with guess 0.5 and no lapses at each level, per_level times."""
    rng = np.random.default_rng(seed)
    x = np.repeat(np.asarray(levels, float), per_level)
    p = 0.5 + 0.5 * (1 - np.exp(-(x / alpha) ** beta))
    return x, (rng.random(x.size) < p).astype(float)


class NotDeterminedIsWords(unittest.TestCase):
    def test_a_short_staircases_threshold_is_words_in_table_chart_and_summary(self):
        chart, words, svg = run_cells(cell_rows(SHORT_LEVELS, SHORT_CORRECT))
        row = chart.table.iloc[0]
        # 28 of 32 correct, 2 of 3 correct at the lowest level: these answers cannot place a 70.7 % point; the old
        # report printed 0.0397 (an observer at ~0.5) with "its interval not determined".
        for col in ("threshold", "threshold_low", "threshold_high", "alpha"):
            self.assertTrue(math.isnan(row[col]), (col, row[col]))
        self.assertTrue(row["threshold_note"].startswith("not determined"), row["threshold_note"])
        self.assertIn("threshold at 70.7 % correct not determined", words)
        # No number beside "threshold" in the summary or the chart's legend; no vertical line drawn for it.
        self.assertIsNone(re.search(r"threshold at 70\.7 % correct [0-9]", words), words)
        self.assertIn("threshold (70.7 % correct): not determined", svg)
        self.assertIsNone(re.search(r"threshold \(70\.7 % correct\): [0-9]", svg))
        note = chart.notes[0]
        self.assertIsNone(re.search(r"Levitt 1971\): [0-9]", note), note)

    def test_a_slope_whose_interval_reaches_a_bound_is_words(self):
        # A steep Weibull observer (alpha 0.5, beta 5), 15 answers at each of 9 levels: the fit's slope (4.99) is
        # off its range's bounds (0 to 10), but its bootstrap interval runs to 10. The old table printed the 4.99.
        x, y = weibull_answers(0.5, 5.0, np.linspace(0.2, 1.0, 9), 15, seed=1)
        chart, words, _ = run_cells(cell_rows(x, y))
        self.assertNotIn("beta", chart.table.iloc[0]["on_bound"])  # the case of a slope free but not determined
        row = chart.table.iloc[0]
        self.assertTrue(math.isnan(row["beta_slope"]), row["beta_slope"])
        self.assertTrue(math.isnan(row["beta_low"]) and math.isnan(row["beta_high"]))
        self.assertTrue(row["slope_note"].startswith("not determined"), row["slope_note"])
        self.assertIn("slope not determined", chart.notes[0])
        self.assertIsNone(re.search(r"slope [0-9]", chart.notes[0]), chart.notes[0])

    def test_a_determined_threshold_and_slope_are_numbers_near_the_truth(self):
        # The positive control: a Weibull observer alpha 0.5, beta 3, 600 answers at each of 8 levels. Its 70.7 %
        # point, worked by hand: 0.5 + 0.5 (1 - exp(-(t/0.5)^3)) = 1/sqrt(2) -> t = 0.5 (-ln(2 - sqrt 2))^(1/3).
        truth = 0.5 * (-math.log(2 - math.sqrt(2))) ** (1 / 3)   # 0.4072
        x, y = weibull_answers(0.5, 3.0, np.linspace(0.15, 1.2, 8), 600, seed=11)
        chart, words, svg = run_cells(cell_rows(x, y))
        row = chart.table.iloc[0]
        self.assertLess(abs(row["threshold"] - truth), 0.03, row)
        self.assertLessEqual(row["threshold_low"], truth)
        self.assertGreaterEqual(row["threshold_high"], truth)
        self.assertEqual(row["threshold_note"], "")
        self.assertLess(row["beta_low"], 3.0)
        self.assertGreater(row["beta_high"], 3.0)
        self.assertIn(f"threshold at 70.7 % correct {row['threshold']:.3g} ratio - 1 [", words)
        self.assertIn(f"threshold (70.7 % correct): {row['threshold']:.3g}", svg)


class BootSamples(unittest.TestCase):
    def test_the_threshold_interval_uses_the_boot_samples_asked_for(self):
        # --boot 60: the band and the threshold's interval from the same 60 refits (the old code drew
        # max(50, n_boot // 2) apart: 100 refits said beside --boot 200, 50 beside --boot 60).
        x, y = weibull_answers(0.5, 3.0, np.linspace(0.15, 1.2, 8), 60, seed=5)
        for n_boot in (60, 120):
            chart, words, _ = run_cells(cell_rows(x, y), n_boot=n_boot)
            self.assertIn(f"(parametric bootstrap, {n_boot} refits)", chart.notes[0])


if __name__ == "__main__":
    unittest.main()
