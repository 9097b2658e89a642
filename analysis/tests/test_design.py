"""The design read from the record (design.py), sessions kept apart (common.study_parts, session_numbers), and the
tests with participants as the unit (study_tests.py) - against hand-worked values and R's own t.test, wilcox.test,
oneway.test and kruskal.test (Rscript from Debian's r-base-core, which scripts/setup.sh installs: without it those
tests fail, never pass)."""
import math
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

import pandas as pd

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
import common  # noqa: E402
import design  # noqa: E402
import any_study  # noqa: E402
import study_tests  # noqa: E402

RSCRIPT = shutil.which("Rscript") or ("/usr/bin/Rscript" if os.path.exists("/usr/bin/Rscript") else None)


def r_value(expression):
    """A number R computes (cat of expression)."""
    out = subprocess.run([RSCRIPT, "-e", f"cat(sprintf('%.15g', {expression}))"], capture_output=True, text=True,
                         timeout=60, check=True)
    return float(out.stdout.strip())


def codebook_csv(folder, rows, with_role=True):
    header = "table,column,type,unit,allowed,meaning" + (",role" if with_role else "")
    lines = [header] + [",".join(["trials.csv", c, "string", "", "", f'"{m}"'] + ([role] if with_role else []))
                        for c, m, role in rows]
    with open(os.path.join(folder, "codebook.csv"), "w") as f:
        f.write("\n".join(lines) + "\n")
    return os.path.join(folder, "trials.csv")


LEVEL = "a level of the protocol's design: factor edge"


class DesignFromTheRecord(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.mkdtemp()

    def tearDown(self):
        shutil.rmtree(self.tmp)

    def book(self, with_role=True):
        return design.load_codebook(codebook_csv(self.tmp, [
            ("edge", LEVEL, "procedure_cell|within"), ("speed_cm_s", LEVEL, "within"), ("id", LEVEL, "label"),
            ("group", "the between-subject group the session ran", "group"), ("info_age", "participant information",
                                                                              "label"),
            ("level", "a procedure trial: the level shown", "within"), ("factor_block", LEVEL, "procedure_cell"),
            ("practice", "1: a practice trial", "practice"), ("participant", "the participant's id", "")],
            with_role))

    def test_levels_named_na_nan_none_are_levels_not_missing(self):
        # Issue 23: a level "NA", "nan" or "None" read back as missing. Read through the CSV helper, a group of "NA"
        # and "None" and a within factor of "nan" and "x" are two levels each; only an empty cell is missing.
        path = os.path.join(self.tmp, "t.csv")
        with open(path, "w") as f:
            f.write("participant,group,speed_cm_s,edge\nNA,NA,nan,\nNA,NA,x,\nP2,None,nan,\nP2,None,x,\n")
        d = common.read_text_csv(path)
        self.assertEqual(list(d["participant"]), ["NA", "NA", "P2", "P2"])
        got = design.design_of(d, self.book())
        self.assertEqual(got.group, "group")
        self.assertEqual(got.within, ("speed_cm_s",))  # edge is empty in every row: not applicable, not a factor
        self.assertEqual(list(common.text(pd.Series(["nan", float("nan"), None, " NA "]))), ["nan", "", "", "NA"])

    def test_a_participant_named_na_is_fitted_by_lme4(self):
        # R's read.csv takes "NA" for missing: the participant's answers were dropped from every mixed model. The
        # fit with that participant named "NA" must be the fit with them named "Pna" (renaming changes nothing).
        import mixed
        import numpy as np
        rng = np.random.default_rng(3)
        people = np.repeat(["NA", "P2", "P3", "P4"], 30)
        offset = {"NA": 5.0, "P2": 0.0, "P3": 0.5, "P4": -0.5}
        x = np.tile(np.linspace(-1, 1, 30), 4)
        y = np.array([offset[p] for p in people]) + 0.8 * x + rng.normal(0, 0.3, x.size)
        X = pd.DataFrame({"Intercept": 1.0, "x": x})
        with_na = mixed.fit("lmm", y, X, people)
        renamed = mixed.fit("lmm", y, X, np.where(people == "NA", "Pna", people))
        a, b = with_na.fixed.set_index("term"), renamed.fixed.set_index("term")
        self.assertAlmostEqual(a.loc["Intercept", "estimate"], b.loc["Intercept", "estimate"], places=6)
        # NA's offset of 5 lifts the mean of the 4 participants' intercepts to about 1.25 (3 of them: about 0).
        self.assertGreater(a.loc["Intercept", "estimate"], 0.8)

    def test_a_procedure_study_has_cells_from_its_rows_not_within_factors(self):
        # edge is a procedure cell in this study (the codebook's union says procedure_cell|within, the rows' cell text
        # decides); the procedure's level is its variable, not a factor; participant information is a label.
        d = pd.DataFrame({"edge": [3, 3, 9, 9], "speed_cm_s": [1.8, 3, 1.8, 3], "level": [0.5, 1, 0.7, 2],
                          "info_age": [20, 30, 20, 30], "practice": [0] * 4,
                          "cell": ["edge=3;speed_cm_s=1.8", "edge=3;speed_cm_s=3", "edge=9;speed_cm_s=1.8",
                                   "edge=9;speed_cm_s=3"]})
        got = design.design_of(d, self.book())
        self.assertEqual(got.cells, ("edge", "speed_cm_s"))
        self.assertEqual(got.within, ())
        self.assertEqual(got.factors, ("edge", "speed_cm_s"))
        self.assertEqual(got.group, "")
        self.assertIn("info_age", got.labels)
        self.assertEqual(list(got.cell_of(d)), list(d["cell"]))

    def test_a_study_without_procedure_varies_the_same_column_within(self):
        d = pd.DataFrame({"edge": [3, 9, 3, 9], "speed_cm_s": [3] * 4, "id": ["a", "b", "a", "b"],
                          "group": ["x", "x", "y", "y"], "cell": [""] * 4})
        got = design.design_of(d, self.book())
        self.assertEqual(got.within, ("edge",))  # speed_cm_s constant here; id a label
        self.assertEqual(got.cells, ())
        self.assertEqual(got.group, "group")
        self.assertNotIn("group", got.factors)

    def test_one_group_is_no_group_factor(self):
        d = pd.DataFrame({"edge": [3, 9], "group": ["x", "x"], "cell": ["", ""]})
        self.assertEqual(design.design_of(d, self.book()).group, "")

    def test_a_level_named_like_a_recorded_column_is_found_under_factor_(self):
        d = pd.DataFrame({"factor_block": [1, 2], "cell": ["block=1", "block=2"]})
        self.assertEqual(design.design_of(d, self.book()).cells, ("factor_block",))

    def test_an_export_from_before_roles_takes_its_levels_as_within(self):
        book = self.book(with_role=False)
        self.assertEqual(book["edge"].roles, frozenset({"within"}))
        self.assertEqual(book["group"].roles, frozenset({"group"}))
        d = pd.DataFrame({"edge": [3, 9], "group": ["x", "y"]})
        got = design.design_of(d, book)
        self.assertEqual((got.within, got.group), (("edge",), "group"))


def rows_of(sessions):
    """trials rows, two per session: (participant, session_id, session_number, status, version)."""
    out = []
    for participant, sid, number, status, version in sessions:
        for i in range(2):
            out.append({"study": "s", "participant": participant, "session_id": sid, "session_number": number,
                        "session_status": status, "protocol_version": version, "trial_index": i})
    return pd.DataFrame(out)


class SessionsKeptApart(unittest.TestCase):
    def test_again_after_a_completed_session_is_a_second_session(self):
        d = rows_of([("P1", 1, 1, "completed", 1), ("P1", 2, 2, "completed", 1),
                     ("P2", 3, 1, "aborted", 1), ("P2", 4, 2, "completed", 1), ("P3", 5, 1, "running", 1)])
        got = dict(zip(d["session_id"], common.session_numbers(d)))
        # P2's session after an aborted one is still P2's first; P1's --again is a second.
        self.assertEqual(got, {1: 1, 2: 2, 3: 1, 4: 1, 5: 1})
        parts = common.study_parts(d)
        self.assertEqual([label for label, _ in parts], ["", "session 2"])
        self.assertEqual(sorted(set(parts[1][1]["session_id"])), [2])

    def test_protocol_versions_are_parts_of_their_own(self):
        d = rows_of([("P1", 1, 1, "completed", 1), ("P2", 2, 1, "completed", 2), ("P3", 3, 1, "completed", 10),
                     ("P1", 4, 2, "completed", 1)])
        labels = [label for label, _ in common.study_parts(d)]
        self.assertEqual(labels, ["version 1", "version 1, session 2", "version 2", "version 10"])
        # The thesis's views read the latest version's first sessions: version 10 (numerically, not as text).
        self.assertEqual(sorted(set(common.main_rows(d)["session_id"])), [3])

    def test_one_version_with_two_texts_after_a_merge_is_two_parts(self):
        # Two stations ran version 1 with different protocols (merge warns, run refuses it in one record): the
        # report keeps them apart by their texts' hashes instead of pooling them as one version.
        d = rows_of([("P1", 1, 1, "completed", 1), ("P2", 2, 1, "completed", 1), ("P3", 3, 1, "completed", 1)])
        d["protocol_hash"] = d["session_id"].map({1: "aaaaaaaa11111111", 2: "aaaaaaaa11111111", 3: "bbbbbbbb22222222"})
        parts = common.study_parts(d)
        self.assertEqual([label for label, _ in parts], ["version 1 (text aaaaaaaa)", "version 1 (text bbbbbbbb)"])
        self.assertEqual([sorted(set(p["session_id"])) for _, p in parts], [[1, 2], [3]])
        d["protocol_hash"] = "aaaaaaaa11111111"  # one text: one version, as before
        self.assertEqual([label for label, _ in common.study_parts(d)], [""])

    def test_unfinished_sessions_are_the_running_ones(self):
        d = rows_of([("P1", 1, 1, "completed", 1), ("P3", 5, 1, "running", 1)])
        self.assertEqual(set(common.unfinished_rows(d)["session_id"]), {5})
        self.assertEqual(set(common.without_unfinished(d)["session_id"]), {1})


def answers(shares_of):
    """0/1 answers per participant: {participant: (k, n)} -> rows with y, participant."""
    out = []
    for p, (k, n) in shares_of.items():
        out += [{"participant": p, "y": 1.0 if i < k else 0.0} for i in range(n)]
    return pd.DataFrame(out)


class ParticipantsAsTheUnit(unittest.TestCase):
    def test_one_participant_gets_the_exact_binomial_of_its_answers(self):
        # 7 of 10 against 0.5: 2 (C(10,7) + C(10,8) + C(10,9) + C(10,10)) / 2^10 = 2 (120 + 45 + 10 + 1) / 1024.
        r = study_tests.against_chance(answers({"P1": (7, 10)}), 0.5)
        self.assertAlmostEqual(r["p"], 352 / 1024, places=12)
        self.assertIn("one participant", r["test"])

    def test_two_participants_get_no_test_in_words(self):
        r = study_tests.against_chance(answers({"P1": (9, 10), "P2": (10, 10)}), 0.5)
        self.assertTrue(math.isnan(r["p"]))
        self.assertTrue(r["test"].startswith("none: 2 participants"))

    def test_four_participants_an_exact_sign_flip_of_their_shares(self):
        # Shares 0.6, 0.7, 0.8, 0.5 (each of 10 answers; 40 answers pooled would be 26 of 40 - not the unit): mean
        # 0.65. Deviations 0.1, 0.2, 0.3, 0 (P4 at chance adds 0 either way), sum 0.6 = the largest |sum| any sign
        # pattern of them gives: ++++ and its mirror image, each with P4's two signs: 4 of 16 -> p = 0.25.
        m = answers({"P1": (6, 10), "P2": (7, 10), "P3": (8, 10), "P4": (5, 10)})
        r = study_tests.against_chance(m, 0.5)
        self.assertAlmostEqual(r["participant_mean"], 0.65, places=12)
        self.assertAlmostEqual(r["p"], 0.25, places=12)
        self.assertIn("sign-flip", r["test"])
        self.assertEqual((r["participants_above"], r["participants_below"]), (3, 0))

    def group_data(self, groups):
        rows = []
        for g, shares in groups.items():
            for i, share in enumerate(shares):
                k = round(share * 20)
                rows += [{"participant": f"{g}{i}", "group": g, "y": 1.0 if j < k else 0.0} for j in range(20)]
        return pd.DataFrame(rows)

    def test_two_groups_welch_and_mann_whitney_as_r_computes_them(self):
        a, b = [0.25, 0.3, 0.45, 0.2], [0.6, 0.7, 0.55, 0.85, 0.65]
        table, _, words = study_tests.group_effect(self.group_data({"a": a, "b": b}), "group")
        ra, rb = "c(" + ",".join(map(str, a)) + ")", "c(" + ",".join(map(str, b)) + ")"
        self.assertAlmostEqual(table["p_welch"][0], r_value(f"t.test({ra}, {rb})$p.value"), places=9)
        self.assertAlmostEqual(table["p_mann_whitney"][0], r_value(f"wilcox.test({ra}, {rb})$p.value"), places=9)
        self.assertEqual(list(table["participants"]), [4, 5])
        self.assertIn("group b higher than group a", words)

    def test_three_groups_welch_anova_and_kruskal_wallis_as_r_computes_them(self):
        groups = {"a": [0.25, 0.3, 0.45, 0.2], "b": [0.6, 0.7, 0.55, 0.85], "c": [0.4, 0.5, 0.35, 0.6, 0.45]}
        table, _, words = study_tests.group_effect(self.group_data(groups), "group")
        y = "c(" + ",".join(str(v) for g in groups.values() for v in g) + ")"
        g = "factor(c(" + ",".join(f"'{k}'" for k, v in groups.items() for _ in v) + "))"
        self.assertAlmostEqual(table["p_welch"][0], r_value(f"oneway.test({y} ~ {g})$p.value"), places=9)
        self.assertAlmostEqual(table["p_kruskal"][0], r_value(f"kruskal.test({y}, {g})$p.value"), places=9)
        self.assertIn("highest group b, lowest a", words)

    def test_a_direction_no_test_finds_is_said_as_the_samples_not_as_a_finding(self):
        # Overlapping groups (R: Welch p = 0.30, Wilcoxon p = 0.41): the means differ, no test finds it. The summary
        # said 'group b higher than group a' at p = 0.08 in an experimenter's yes/no study.
        a, b = [0.3, 0.5, 0.45, 0.6], [0.5, 0.65, 0.4, 0.7]
        table, _, words = study_tests.group_effect(self.group_data({"a": a, "b": b}), "group")
        ra, rb = "c(" + ",".join(map(str, a)) + ")", "c(" + ",".join(map(str, b)) + ")"
        self.assertGreater(r_value(f"t.test({ra}, {rb})$p.value"), 0.05)
        self.assertGreater(r_value(f"wilcox.test({ra}, {rb}, exact = FALSE)$p.value"), 0.05)
        self.assertIn("group b higher than group a in this sample, not significant at 0.05 by either test", words)

    def test_cells_in_the_order_of_their_numbers(self):
        # A QUEST+ per depth's psychometric cells came as edge 10, 2, 6 (text order).
        self.assertEqual(any_study._sorted_levels(["edge=10", "edge=2", "edge=6"]), ["edge=2", "edge=6", "edge=10"])
        self.assertEqual(any_study._sorted_levels(["edge=9;speed_cm_s=3", "edge=9;speed_cm_s=1.8", "edge=10;speed_cm_s=1"]),
                         ["edge=9;speed_cm_s=1.8", "edge=9;speed_cm_s=3", "edge=10;speed_cm_s=1"])

    def test_a_yes_no_table_is_not_said_to_be_an_adaptive_procedures(self):
        self.assertNotIn("adaptive", any_study.NO_CHANCE_WHY["yes_no"])
        self.assertIn("adaptive procedure", any_study.NO_CHANCE_WHY["procedure"])

    def test_a_group_of_one_participant_gets_no_test_in_words(self):
        _, _, words = study_tests.group_effect(self.group_data({"a": [0.2], "b": [0.6, 0.7]}), "group")
        self.assertIn("no test of the group effect: group a has 1 participant", words)


class VersionsInTheReport(unittest.TestCase):
    """report.py on a study run under two protocol versions: a section per version, each with its own answers."""

    def test_each_version_has_its_own_section(self):
        sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
        import synthetic
        tmp = tempfile.mkdtemp(prefix="blurcue-design-")
        self.addCleanup(shutil.rmtree, tmp, True)
        rows = synthetic.trials_rows(studies=["test1-static-grids"], unanswered=0)
        for r in rows:
            r["study"] = "my-grids"
            r["protocol_version"] = 1 if r["participant"] in ("P1", "P2", "P3") else 2
        trials = synthetic.write_trials_csv(os.path.join(tmp, "trials.csv"), rows)
        out = os.path.join(tmp, "out")
        report = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "report.py")
        proc = subprocess.run([sys.executable, report, "--trials", trials, "--bench", os.path.join(tmp, "none"),
                               "--out", out, "--boot", "20"], capture_output=True, text=True, timeout=170)
        self.assertEqual(proc.returncode, 0, proc.stderr)
        self.assertIn("report: protocol versions 1, 2 analysed apart", proc.stderr)
        with open(os.path.join(out, "index.html"), encoding="utf-8") as f:
            index = f.read()
        for version, people in ((1, {"P1", "P2", "P3"}), (2, {"P4", "P5", "P6"})):
            self.assertIn(f"study my-grids (version {version}, simulated observers)", index)
            table = pd.read_csv(os.path.join(out, f"my-grids-version{version}-simulated-conditions.csv"))
            decisive = sum(1 for r in rows if r["participant"] in people and not r.get("practice")
                           and r.get("choice") in ("left", "right") and r["r_left_px"] != r["r_right_px"])
            self.assertEqual(int(table["n"].sum()), decisive)
            self.assertEqual(int(table["participants"].max()), 3)
        self.assertFalse(os.path.exists(os.path.join(out, "my-grids-simulated-conditions.csv")), "versions pooled")


if __name__ == "__main__":
    unittest.main()
