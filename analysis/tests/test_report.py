"""report.py end to end on synthetic inputs, and its edge cases (run as a separate process: exit codes, stderr)."""
import html
import os
import re
import shutil
import subprocess
import sys
import tempfile
import unittest
import xml.etree.ElementTree as ET

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
REPORT = os.path.join(os.path.dirname(HERE), "report.py")

import synthetic  # noqa: E402

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def read(*parts):
    with open(os.path.join(*parts), encoding="utf-8") as f:
        return f.read()


def run_report(trials, bench, out, *extra):
    proc = subprocess.run([sys.executable, REPORT, "--trials", trials, "--bench", bench, "--out", out, "--boot", "30",
                           *extra], capture_output=True, text=True, timeout=120)
    return proc.returncode, proc.stdout, proc.stderr


class ReportTestCase(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix="blurcue-report-")
        self.addCleanup(shutil.rmtree, self.tmp, True)

    def assertCleanStderr(self, stderr):
        self.assertNotIn("Traceback", stderr)
        for line in stderr.splitlines():
            self.assertTrue(line.startswith("report: "), f"stderr line without the prefix: {line!r}")


class EndToEndTest(ReportTestCase):
    """All four studies, six participants, bench fixtures: every chart is written, linked and readable."""

    def test_full_report(self):
        trials = synthetic.write_trials_csv(os.path.join(self.tmp, "run", "trials.csv"), synthetic.trials_rows())
        synthetic.write_frames_csv(os.path.join(self.tmp, "run", "frames.csv"), synthetic.report_frames())
        bench = synthetic.write_bench_fixtures(os.path.join(self.tmp, "bench"))
        out = os.path.join(self.tmp, "report")
        code, _, err = run_report(trials, bench, out)
        self.assertEqual(code, 0, err)
        self.assertCleanStderr(err)
        self.assertRegex(err, r"report: \[3/\d+\] test 1 per edge")
        self.assertNotIn("skipped", err)

        index = read(out, "index.html")
        # The summary says what each thesis study found.
        self.assertIn("measured chosen over estimated", index)
        self.assertRegex(index, r"c ~ d\^b with b = -?[0-9.]+ \[")
        pngs = sorted(f for f in os.listdir(out) if f.endswith(".png"))
        expected = {"depth-matching", "depth-matching-arcmin", "test1-per-edge", "test2-per-pattern", "test3-per-pattern",
                    "test2-pattern2-per-section", "test2-pattern4-per-section", "test2-pattern6-per-section",
                    "test3-pattern2-per-section", "test3-pattern4-per-section", "test3-pattern6-per-section",
                    "psychometric", "side-bias", "frame-intervals", "bench-measure-speed-accuracy", "bench-stability-within-target",
                    "bench-stability-error", "bench-stability-flagged", "bench-render-speed-accuracy", "bench-frame", "bench-frame-growth",
                    "bench-procedures", "test1-static-grids-predicted-pair-simulated",
                    "test2-moving-balls-predicted-pair-simulated", "test3-no-board-predicted-pair-simulated"}
        self.assertEqual({p[:-4] for p in pngs}, expected)
        # Observed beside the observer model's prediction, per condition, with the departures counted.
        self.assertIn("conditions depart from the model", index)
        bench_page = read(out, "bench.html")
        linked = set(re.findall(r"<img src='([^']+)'", index))
        bench_linked = set(re.findall(r"<img src='([^']+)'", bench_page))
        self.assertEqual(linked | bench_linked, set(pngs), "the pages show every PNG, and only existing ones")
        self.assertEqual(bench_linked, {p for p in pngs if p.startswith("bench-")}, "benchmarks on their own page")
        for page in (index, bench_page):
            for href in re.findall(r"href='([^'#]+)'", page):
                self.assertFalse(os.path.isabs(href), href)
                self.assertTrue(os.path.isfile(os.path.join(out, href)), f"a page links a missing file {href}")

        for png in pngs:
            with open(os.path.join(out, png), "rb") as f:
                data = f.read()
            self.assertTrue(data.startswith(PNG_SIGNATURE), png)
            self.assertGreater(len(data), 10000, png)
            # IHDR: width and height of a readable chart
            width, height = int.from_bytes(data[16:20], "big"), int.from_bytes(data[20:24], "big")
            self.assertGreater(width, 400, png)
            self.assertGreater(height, 250, png)
            svg = os.path.join(out, png[:-4] + ".svg")
            root = ET.parse(svg).getroot()
            self.assertTrue(root.tag.endswith("svg"), svg)

        # Tables: one CSV per chart with a table; the numbers are there.
        t1 = read(out, "test1-per-edge.csv").splitlines()
        self.assertEqual(len(t1), 12)  # header + 11 edges
        self.assertIn(",p,", t1[0])  # the test across participants (study_tests), not pooled answers
        model = read(out, "test1-model.csv")
        self.assertTrue(model.startswith("study,model,term,estimate,se,df,p,engine,note\n"), model[:80])
        self.assertIn("glmer(chose_first ~ edge_c", model)
        self.assertIn("lme4 ", model)
        depth = read(out, "depth-matching.csv")  # the match in arcmin by lmer, beside the power law
        self.assertIn("set on real: lmer(set_arcmin ~ real_arcmin", depth)
        self.assertIn("power law: lm(log_c ~ log_d), cluster-robust", depth)
        for name in os.listdir(out):  # every model table has the same columns
            if name.endswith("model.csv") or name.endswith("models.csv") or name == "depth-matching.csv":
                self.assertTrue(read(out, name).startswith("study,model,term,estimate,se,df,p,engine,note"), name)

        # The two checks: side bias per study and pooled (+ per participant), display timing per window session.
        self.assertRegex(err, r"report: \[\d+/\d+\] side bias \(counterbalancing check\) \.\.\.")
        self.assertRegex(err, r"report: \[\d+/\d+\] display timing \.\.\.")
        side = read(out, "side-bias.csv").splitlines()
        self.assertIn("share_left_low", side[0])
        self.assertEqual([line.split(",")[0] for line in side[1:]],
                         ["test1-static-grids", "test2-moving-balls", "test3-no-board", "pooled"])
        self.assertTrue(os.path.isfile(os.path.join(out, "side-bias-per-participant.csv")))
        timing = read(out, "frame-intervals.csv").splitlines()
        self.assertEqual(len(timing), 3, "two window sessions; the headless one is left out")
        self.assertTrue(all(line.split(",")[1] in ("W1", "W2") for line in timing[1:]))
        self.assertIn("side bias (counterbalancing check)", index)
        self.assertIn("display timing", index)
        self.assertIn("1 headless session left out", index)


class EdgeCaseTest(ReportTestCase):
    def test_missing_trials_exits_3_with_one_line(self):
        missing = os.path.join(self.tmp, "nope", "trials.csv")
        code, _, err = run_report(missing, os.path.join(self.tmp, "bench"), os.path.join(self.tmp, "out"))
        self.assertEqual(code, 3)
        self.assertEqual(len(err.strip().splitlines()), 1, err)
        self.assertRegex(err, r"^report: .*nope/trials\.csv: no such file")

    def test_garbled_trials_exits_3(self):
        path = os.path.join(self.tmp, "trials.csv")
        with open(path, "wb") as f:
            f.write(b"\x00\xff\xfe garbage\r\nnot,a,trials\"file\r\n")
        code, _, err = run_report(path, os.path.join(self.tmp, "bench"), os.path.join(self.tmp, "out"))
        self.assertEqual(code, 3)
        self.assertEqual(len(err.strip().splitlines()), 1, err)
        self.assertIn("trials.csv", err)
        self.assertCleanStderr(err)

    def test_a_full_disk_is_exit_3_naming_the_file_and_never_says_wrote(self):
        # The disk fills while the charts are saved: one line naming the file, exit 3 (it used to be exit 10 after
        # "wrote .../index.html").
        import contextlib
        import errno
        import io
        import report
        rows = synthetic.trials_rows(participants=("P1", "P2"), studies=["test1-static-grids"], unanswered=0)
        trials = synthetic.write_trials_csv(os.path.join(self.tmp, "trials.csv"), rows)
        out = os.path.join(self.tmp, "out")

        def full(fig, out_dir, name):
            raise OSError(errno.ENOSPC, "No space left on device", os.path.join(out_dir, name + ".png"))
        saved = report.common.save
        modules = [m for m in sys.modules.values() if getattr(m, "save", None) is saved]
        for m in modules:
            m.save = full
        try:
            err = io.StringIO()
            with contextlib.redirect_stderr(err):
                code = report.main(["--trials", trials, "--bench", os.path.join(self.tmp, "bench"), "--out", out,
                                    "--boot", "10"])
        finally:
            for m in modules:
                m.save = saved
        self.assertEqual(code, 3)
        last = err.getvalue().strip().splitlines()[-1]
        self.assertRegex(last, r"^report: .*/out/[^/]+\.png: cannot write \(No space left on device\)")
        self.assertNotIn("wrote", err.getvalue())
        self.assertNotIn("Traceback", err.getvalue())

    def test_a_page_the_disk_cannot_hold_is_named(self):
        # A real ENOSPC at the page's write: /dev/full fails it with no file name, as a full tmpfs did ("report:
        # cannot write (No space left on device)", naming nothing); the error names the page.
        import errno
        import report
        with self.assertRaises(OSError) as caught:
            report.write_index("/dev", [], ["a line"], name="full")
        self.assertEqual((caught.exception.errno, caught.exception.filename), (errno.ENOSPC, "/dev/full"))

    def test_zero_responses(self):
        rows = synthetic.trials_rows(participants=("P1", "P2", "P3"), unanswered=1.0)
        trials = synthetic.write_trials_csv(os.path.join(self.tmp, "trials.csv"), rows)
        out = os.path.join(self.tmp, "out")
        code, _, err = run_report(trials, os.path.join(self.tmp, "nobench"), out)
        self.assertEqual(code, 0, err)
        self.assertCleanStderr(err)
        self.assertIn("0 of 33 trials answered", err)  # test 1: 3 participants x 11 edges
        index = read(out, "index.html")
        self.assertIn("Skipped:", index)
        pngs = {f for f in os.listdir(out) if f.endswith(".png")}
        self.assertEqual(pngs, set())

    def test_header_only_trials(self):
        path = os.path.join(self.tmp, "trials.csv")
        with open(path, "w", newline="") as f:
            f.write(",".join(synthetic.LEADING + synthetic.TRAILING) + "\r\n")
        code, _, err = run_report(path, os.path.join(self.tmp, "nobench"), os.path.join(self.tmp, "out"))
        self.assertEqual(code, 0, err)
        self.assertCleanStderr(err)
        self.assertTrue(os.path.isfile(os.path.join(self.tmp, "out", "index.html")))

    def test_one_participant(self):
        rows = synthetic.trials_rows(participants=("P1",), seed=3, unanswered=0)
        trials = synthetic.write_trials_csv(os.path.join(self.tmp, "trials.csv"), rows)
        out = os.path.join(self.tmp, "out")
        code, _, err = run_report(trials, os.path.join(self.tmp, "nobench"), out)
        self.assertEqual(code, 0, err)
        self.assertCleanStderr(err)
        index = read(out, "index.html")
        self.assertIn("one participant", index)
        for chart in ("depth-matching", "test1-per-edge", "test2-per-pattern"):
            self.assertTrue(os.path.isfile(os.path.join(out, chart + ".png")), chart)
        model = read(out, "depth-matching.csv")
        self.assertIn("lm(log_c ~ log_d) (one observer)", model)
        self.assertNotIn("lmer(", model)

    def test_missing_bench_folder(self):
        rows = synthetic.trials_rows(participants=("P1", "P2"), studies=["pre-research-depth-matching"])
        trials = synthetic.write_trials_csv(os.path.join(self.tmp, "trials.csv"), rows)
        bench = os.path.join(self.tmp, "no-such-bench")
        out = os.path.join(self.tmp, "out")
        code, _, err = run_report(trials, bench, out)
        self.assertEqual(code, 0, err)
        self.assertCleanStderr(err)
        self.assertIn(os.path.join(bench, "measure.csv") + ": no such file", err)
        index = read(out, "index.html")
        self.assertIn("measure.csv: no such file", read(out, "bench.html"))
        self.assertNotIn("test 1 (static grids)", index)  # a study nobody ran gets no section
        # No frames.csv beside trials.csv: display timing is skipped with a note naming the file.
        frames = os.path.join(self.tmp, "frames.csv")
        self.assertIn(f"skipped: {frames}: no such file", err)
        self.assertIn(f"Skipped: {frames}: no such file", index)
        self.assertFalse(any(f.startswith("bench-") for f in os.listdir(out)))

    def test_one_bench_file_only(self):
        rows = synthetic.trials_rows(participants=("P1", "P2"), studies=["pre-research-depth-matching"])
        trials = synthetic.write_trials_csv(os.path.join(self.tmp, "trials.csv"), rows)
        bench = synthetic.write_bench_fixtures(os.path.join(self.tmp, "bench"))
        os.remove(os.path.join(bench, "measure.csv"))
        out = os.path.join(self.tmp, "out")
        code, _, err = run_report(trials, bench, out)
        self.assertEqual(code, 0, err)
        self.assertIn("measure.csv: no such file", err)
        self.assertTrue(os.path.isfile(os.path.join(out, "bench-frame.png")))
        self.assertFalse(os.path.isfile(os.path.join(out, "bench-measure-speed-accuracy.png")))


class AbortedSessionsTest(ReportTestCase):
    """An aborted session (blurcue sessions --abort) is left out by default and the summary says so; a participant
    who started again answered the same first trials, which used to be counted twice."""

    def rows(self):
        rows = synthetic.trials_rows(participants=("P1", "P2", "P3"), studies=["test1-static-grids"], unanswered=0)
        # P1's first session, given up after 6 answers and aborted: the same trials as P1's complete session.
        first = [dict(r, session=99, session_status="aborted") for r in rows if r["participant"] == "P1"][:6]
        return rows, first

    @staticmethod
    def decisive(rows):
        return sum(1 for r in rows if not r.get("practice") and r["choice"] in ("left", "right"))

    def report(self, rows, *extra):
        trials = synthetic.write_trials_csv(os.path.join(self.tmp, "trials.csv"), rows)
        out = os.path.join(self.tmp, "out")
        shutil.rmtree(out, ignore_errors=True)
        code, _, err = run_report(trials, os.path.join(self.tmp, "nobench"), out, *extra)
        self.assertEqual(code, 0, err)
        self.assertCleanStderr(err)
        return read(out, "index.html"), err

    def test_left_out_by_default_and_said_in_the_summary(self):
        rows, first = self.rows()
        index, err = self.report(rows + first)
        answers = sum(1 for r in first if not r.get("practice"))
        said = (f"left out 1 aborted session (P1 (session id 99)) with {answers} answers: closed with blurcue sessions "
                f"--abort, they are not part of the study; blurcue report --include-aborted analyses them")
        self.assertIn(html.escape(said), index)
        self.assertIn(said, err)
        self.assertIn(f"of {self.decisive(rows)} decisive answers", index)
        self.assertNotIn(f"of {self.decisive(rows + first)} decisive answers", index)

    def test_include_aborted_counts_them_and_says_so(self):
        rows, first = self.rows()
        index, _ = self.report(rows + first, "--include-aborted")
        self.assertIn("included 1 aborted session (P1 (session id 99))", index)
        self.assertIn(f"of {self.decisive(rows + first)} decisive answers", index)

    def test_a_record_of_an_aborted_session_only_says_aborted(self):
        _, first = self.rows()
        index, _ = self.report(first)
        self.assertIn("left out 1 aborted session (P1 (session id 99))", index)
        self.assertNotIn("decisive answers", index)

    def test_a_session_aborted_after_its_practice_gives_no_share(self):
        # Aborted after one practice trial and analysed (--include-aborted): no answer to share out (the summary said
        # "can't tell nan% of all answers").
        rows = synthetic.trials_rows(participants=("P1",), studies=["test1-static-grids"], unanswered=0)
        session = [dict(r, session=99, session_status="aborted", choice=r["choice"] if r.get("practice") else None)
                   for r in rows]
        index, _ = self.report(session, "--include-aborted")
        self.assertIn("no measured-vs-estimated pairs answered; no answers", index)
        self.assertNotIn("nan%", index)


class UnansweredOnlyTest(ReportTestCase):
    """A record whose only session stopped before its first answer (blurcue report builds the report in a partial
    folder): the rows read are counted as the file holds them, one line says there is nothing to analyse, and every
    message names the user's folder, never the partial one."""

    def test_one_line_naming_the_users_paths(self):
        rows = [dict(r, session=7, session_status="running", choice=None) for r in
                synthetic.trials_rows(participants=("S9",), studies=["test1-static-grids"], unanswered=0)]
        partial, final = os.path.join(self.tmp, ".rep.partial-1"), os.path.join(self.tmp, "rep")
        os.makedirs(os.path.join(partial, "tables"))
        trials = synthetic.write_trials_csv(os.path.join(partial, "tables", "trials.csv"), rows)
        code, _, err = run_report(trials, os.path.join(self.tmp, "nobench"), partial, "--final-out", final)
        self.assertEqual(code, 0, err)  # a report was written, saying there is nothing in it (as a study unanswered)
        self.assertCleanStderr(err)
        self.assertNotIn(".rep.partial-1", err)
        shown = os.path.join(final, "tables", "trials.csv")
        self.assertIn(f"read {shown}: {len(rows)} rows (0 of them analysed)", err)  # was "0 rows"
        said = f"nothing to analyse: all {len(rows)} rows of {shown} are of sessions left out (above)"
        self.assertEqual(sum(said in line for line in err.splitlines()), 1, err)
        self.assertIn("left out 1 unfinished session (S9 (session id 7)) with 0 answers", err)
        self.assertNotIn("--include-unfinished analyses", err)  # nothing it could analyse
        self.assertIn(html.escape(said), read(partial, "index.html"))


class FileStemTest(unittest.TestCase):
    """A chart's name as a file name (issue 24: a factor named a/b made report write into a folder a/ that did not
    exist, exit 10): safe names as they are, others with '_' for each unsafe character and a hash of the name."""

    def test_names_as_file_names(self):
        sys.path.insert(0, os.path.dirname(HERE))
        from common import file_stem
        self.assertEqual(file_stem("test1-static-grids-per-edge"), "test1-static-grids-per-edge")
        slash, underscore = file_stem("s-share-per-label_a/b"), file_stem("s-share-per-label_a_b")
        self.assertTrue(slash.startswith("s-share-per-label_a_b-"), slash)
        self.assertNotEqual(slash, underscore)  # two names stay two files
        self.assertRegex(slash, r"^[A-Za-z0-9_.-]+$")
        self.assertFalse(file_stem("../x").startswith("."))
        self.assertLessEqual(len(file_stem("é" * 300)), 200)


class TableLayoutTest(unittest.TestCase):
    """index.html's tables as a reader sees them (a first-time experimenter's findings): a long text cell written once
    under its table, and a table a section already showed not shown again."""

    def test_long_cells_once_and_a_repeated_table_named(self):
        sys.path.insert(0, os.path.dirname(HERE))
        import pandas as pd
        import report
        from common import Chart
        words = "exact sign-flip permutation test of 3 participants' shares around 0.5 (all 2^3 sign patterns)"
        table = pd.DataFrame({"edge": [2, 5, 8], "test": [words, words, "none: too few"], "p": [0.5, 1.0, float("nan")]})
        out = tempfile.mkdtemp()
        try:
            charts = [Chart("my-study-conditions", None, None, table, []), Chart("my-study-per-edge", None, None, table, [])]
            page = read(report.write_index(out, [("study", charts, [])], ["header"]))
        finally:
            shutil.rmtree(out)
        self.assertEqual(page.count(html.escape(words)), 1)  # under the first table only
        self.assertEqual(len(re.findall(r"<td>\(a\)</td>", page)), 2)
        self.assertIn("<td>none: too few</td>", page)  # short cells stay in place
        self.assertEqual(page.count("<table"), 1)
        self.assertIn("its table is my-study-conditions's, above", page)
        # Headings without the part the section's charts share, the whole name (the files') beside them.
        self.assertIn("<h3>per-edge <span class='notes'>(my-study-per-edge)</span></h3>", page)


if __name__ == "__main__":
    unittest.main()
