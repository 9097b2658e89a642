"""The plan's chart says what the plan holds: each test's line and its smallest N reaching the target (worked out
here from the rows by hand), groups compared and not pooled, a procedure cell's interval width with its truth and
bias, and a truth that is not determined said in words, never as a number. Figures are caught before saving."""
import contextlib
import io
import os
import sys
import tempfile
import unittest

import pandas as pd

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))

import plan_chart  # noqa: E402


class Caught:
    """Stands in for common.save: keeps the figure open for the test instead of writing it."""

    def __init__(self):
        self.figures = {}

    def __call__(self, fig, out_dir, name):
        self.figures[name] = fig
        return os.path.join(out_dir, name + ".png"), os.path.join(out_dir, name + ".svg")


def row(test, condition, n, power="", measure="first_source", **extra):
    r = dict(test=test, condition=condition, measure=measure, participants=str(n), power=power, true_threshold="",
             mean_estimate="", bias="", sd_estimate="", interval_width="", difference="")
    r.update({k: str(v) for k, v in extra.items()})
    return r


def plan_rows():
    rows = []
    for n, p in enumerate(["0", "0.3", "0.79", "0.8", "0.95"], start=1):
        rows.append(row("participants_t", "group=a", n, p))
        rows.append(row("groups_t", "group b - a", n, ["0", "0", "0.5", "0.7", "0.85"][n - 1]))
        rows.append(row("paired_t", "e=2 - e=1 (declared +0.5 arcmin)", n, ["0", "0.1", "0.2", "0.3", "0.4"][n - 1],
                        measure="threshold"))
        rows.append(row("threshold", "e=1", n, measure="threshold", true_threshold=1.6, mean_estimate=1.9, bias=0.3,
                        sd_estimate=0.6, interval_width="" if n == 1 else 2.0 / n))
        rows.append(row("threshold", "e=2", n, measure="threshold", mean_estimate=5.9, sd_estimate=0.2,
                        interval_width="" if n == 1 else 0.5 / n))
    return pd.DataFrame(rows)


class PlanChartTest(unittest.TestCase):
    def setUp(self):
        self.caught = Caught()
        self.saved = plan_chart.common.save
        plan_chart.common.save = self.caught

    def tearDown(self):
        plan_chart.common.save = self.saved

    def draw(self, plan):
        plan_chart.chart(plan, tempfile.gettempdir(), "study", 0.8)
        return self.caught.figures["power"]

    def test_each_test_has_its_line_and_smallest_n(self):
        fig = self.draw(plan_rows())
        power, cells = fig.axes[0], fig.axes[1]
        labels = power.get_legend_handles_labels()[1]
        # By hand: group=a first reaches 0.8 at N = 4, the Welch test at N = 5, the paired test never.
        self.assertIn("t-test across participants (group=a, first_source; GLMM stand-in) (N = 4)", labels)
        self.assertIn("Welch t: group b - a (N = 5)", labels)
        self.assertIn("paired t: e=2 - e=1 (declared +0.5 arcmin)", labels)
        self.assertFalse([label for label in labels if "e=1 (declared" in label and "N =" in label], labels)
        cell_labels = cells.get_legend_handles_labels()[1]
        self.assertEqual(cell_labels[0], "e=1: truth 1.6, mean 1.9 (bias +0.3), sd 0.6")
        # No truth: said in words, with no bias or truth number.
        self.assertIn("true threshold not determined", cell_labels[1])
        self.assertNotIn("bias", cell_labels[1])
        self.assertNotIn("truth", cell_labels[1].split(";")[0])
        # The width line is the rows' own: 2 / N for e=1 from N = 2.
        x, y = cells.get_lines()[0].get_data()
        self.assertAlmostEqual(float(y[list(x).index(4)]), 0.5)

    def test_a_plan_without_procedure_cells_has_one_panel(self):
        plan = plan_rows()
        fig = self.draw(plan[plan["test"] != "threshold"])
        self.assertEqual(len(fig.axes), 1)

    def test_only_cells_with_nothing_tested_say_why_in_words(self):
        # --difference given but not planned (a truth out of range): the empty power panel points at the notes, and
        # neither panel counts participants in quarters.
        plan = plan_rows()
        fig = self.draw(plan[plan["test"] == "threshold"])
        power, cells = fig.axes[0], fig.axes[1]
        self.assertIn("the plan's notes say why", " ".join(t.get_text() for t in power.texts))
        for ax in (power, cells):
            ticks = [t for t in ax.get_xticks() if ax.get_xlim()[0] <= t <= ax.get_xlim()[1]]
            self.assertTrue(all(float(t).is_integer() for t in ticks), ticks)

    def test_not_a_plan_is_exit_3(self):
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "plan.csv")
            pd.DataFrame([{"x": 1}]).to_csv(path, index=False)
            self.assertEqual(plan_chart.main(["--plan", path, "--out", d]), 3)

    def test_a_chart_that_cannot_be_written_is_exit_3_naming_the_file(self):
        # A full disk (ENOSPC) as the save raises it: one line naming the file, exit 3, no traceback.
        def full(fig, out_dir, name):
            raise OSError(28, "No space left on device", os.path.join(out_dir, name + ".png"))
        plan_chart.common.save = full
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "plan.csv")
            plan_rows().to_csv(path, index=False)
            err = io.StringIO()
            with contextlib.redirect_stderr(err):
                self.assertEqual(plan_chart.main(["--plan", path, "--out", d]), 3)
            self.assertEqual(err.getvalue().strip(),
                             f"plan_chart: {d}/power.png: cannot write the chart (No space left on device)")

    def test_a_full_disk_is_exit_3_naming_the_file_it_could_not_write(self):
        # A real ENOSPC: power.png is a link to /dev/full, which fails every write at flush, with no file name in the
        # error (as a full 2 MiB tmpfs did: the message named only the folder). The line names power.png.
        plan_chart.common.save = self.saved  # the real save, not the test's stand-in
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "plan.csv")
            plan_rows().to_csv(path, index=False)
            os.symlink("/dev/full", os.path.join(d, "power.png"))
            err = io.StringIO()
            with contextlib.redirect_stderr(err):
                self.assertEqual(plan_chart.main(["--plan", path, "--out", d]), 3)
            self.assertEqual(err.getvalue().strip(),
                             f"plan_chart: {d}/power.png: cannot write the chart (No space left on device)")


if __name__ == "__main__":
    unittest.main()
