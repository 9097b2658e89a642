"""Two within factors crossed (crossed.py): the model with their interaction against a direct glmer call written here
(the same formula as the report fitted, on the same data), a planted interaction found with the sign it was planted
with, the additive model saying it has no interaction term, and the shares drawn by both factors. Needs R with lme4:
fails without it, never passes as skipped."""
import os
import re
import sys
import tempfile
import unittest

import numpy as np
import pandas as pd

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))
sys.path.insert(0, HERE)
os.environ.setdefault("MPLCONFIGDIR", tempfile.mkdtemp(prefix="mpl-"))

import any_study  # noqa: E402
import crossed  # noqa: E402
from test_mixed import HAVE_LME4, direct_glmer  # noqa: E402

EDGES = ["e3", "e6", "e9"]
COMPARISONS = ["a-none", "b-estimated"]  # level names whose alphabetical order (R's) is the report's order


def planted(people=8, per_cell=16, seed=3):
    """logit p = 0.2 + u_p + 0.8 x step at comparison a-none (step 0, 1, 2 over the edges), flat at b-estimated:
    the interaction terms are -0.8 (edge e6) and -1.6 (edge e9); u_p ~ N(0, 0.4)."""
    rng = np.random.default_rng(seed)
    rows = []
    for i in range(people):
        u = rng.normal(0, 0.4)
        for c, comparison in enumerate(COMPARISONS):
            for step, edge in enumerate(EDGES):
                eta = 0.2 + u + (0.8 * step if c == 0 else 0.0)
                for y in rng.binomial(1, 1 / (1 + np.exp(-eta)), per_cell):
                    rows.append({"participant": f"P{i + 1}", "comparison": comparison, "edge": edge, "y": float(y)})
    return pd.DataFrame(rows)


class InteractionModel(unittest.TestCase):
    def setUp(self):
        if not HAVE_LME4:
            self.fail("R with lme4 is needed for this test (and is not installed): it cannot pass without it")

    def test_the_glmm_with_the_interaction_is_lme4s_own(self):
        d = planted()
        chart = crossed.interaction_models(d, ["comparison", "edge"], "s", "8 participants", "y",
                                           {"comparison": COMPARISONS, "edge": EDGES})
        t = chart.table
        glmm = t[t["engine"].str.startswith("lme4")]
        self.assertFalse(glmm.empty, chart.notes)
        formula = re.fullmatch(r"glmer\((.*)\)", glmm["model"].iloc[0]).group(1)
        self.assertTrue(formula.startswith("y ~ comparison * edge"), formula)
        fixed, _, _ = direct_glmer(d, formula)
        names = {"comparisonb-estimated:edgee6": "comparison b-estimated x edge e6 (interaction: beyond the effects "
                                                 "added)",
                 "comparisonb-estimated:edgee9": "comparison b-estimated x edge e9 (interaction: beyond the effects "
                                                 "added)",
                 "edgee9": "edge e9 (against edge e3)", "comparisonb-estimated": "comparison b-estimated (against "
                                                                                   "comparison a-none)"}
        for r_name, words in names.items():
            row = glmm[glmm["term"] == words]
            self.assertEqual(len(row), 1, (words, list(glmm["term"])))
            est, se = fixed[r_name]
            self.assertLess(abs(row["estimate"].iloc[0] - est), max(0.1 * abs(est), 0.25 * se), (words, est))
            if not np.isnan(row["se"].iloc[0]):
                self.assertLess(abs(row["se"].iloc[0] / se - 1), 0.2, (words, se))
        # The planted interaction at edge e9 (-1.6) found with its sign, and within 3 SE of it.
        est, se = fixed["comparisonb-estimated:edgee9"]
        self.assertLess(est, 0)
        self.assertLess(abs(est + 1.6), 3 * se)

    def test_the_additive_model_says_it_has_no_interaction_and_the_shares_are_drawn_by_both(self):
        d = planted(people=4, per_cell=8)
        table = any_study.condition_table(d, ["comparison", "edge"], 0.5)
        with tempfile.TemporaryDirectory() as out:
            charts = any_study.within_models(d, table, ["comparison", "edge"], 0.5, "y", "s", out, "s",
                                             "4 participants")
            names = [c.name for c in charts]
            self.assertEqual(names, ["s-models", "s-per-edge-by-comparison", "s-models-interaction"])
            self.assertTrue(os.path.isfile(charts[1].svg))
        self.assertIn("no interaction term: this model assumes each factor's effect (in log-odds) is the same at "
                      "every level of the other", charts[0].notes[0])
        self.assertIn("s-models-interaction", charts[0].notes[0])


if __name__ == "__main__":
    unittest.main()
