"""The benchmark charts say what they draw: titles and legends match the data, every method gets a mark where it
fails (also from the first level), the frame budget verdict follows the numbers drawn, and a --quick run says so.
The figures are caught before they are saved, so their titles and legends can be read."""
import os
import sys
import tempfile
import unittest

import numpy as np
import pandas as pd

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))

import bench_charts  # noqa: E402
import common  # noqa: E402


class Caught:
    """Stands in for bench_charts.save: keeps each figure open for the test instead of writing it."""

    def __init__(self):
        self.figures = {}

    def __call__(self, fig, out_dir, name):
        self.figures[name] = fig
        return os.path.join(out_dir, name + ".png"), os.path.join(out_dir, name + ".svg")


def render_rows(sizes=((640, 360),), quick=1, p99=19.6):
    rows = []
    for w, h in sizes:
        for method, backend, r, ms, err in (("gaussian", "gl", 1, 11.5, 2.0), ("disc", "cpu", 8, 15.0, 1.0)):
            rows.append(dict(kind="blur", method=method, backend=backend, radius_px=r, width=w, height=h, samples=3,
                             median_ms=ms, p99_ms=ms, mean_abs_error_levels=0.1, max_abs_error_levels=err,
                             quick=quick))
    rows.append(dict(kind="frame", method="region", backend="gl", radius_px=0, width=640, height=360, samples=30,
                     median_ms=p99 / 2, p99_ms=p99, mean_abs_error_levels=None, max_abs_error_levels=None, quick=quick))
    rows.append(dict(kind="frame", method="whole_frame", backend="gl", radius_px=0, width=640, height=360, samples=30,
                     median_ms=20 * p99, p99_ms=25 * p99, mean_abs_error_levels=0.5, max_abs_error_levels=6,
                     quick=quick))
    return pd.DataFrame(rows)


def measure_rows(quick=0):
    rows = []
    for method, ok in (("model_fit", [1, 1, 0]), ("thesis", [0, 0, 0])):
        rows.append(dict(method=method, factor="base", level=0, sections=10, answered=10, mean_abs_error_px=0.05,
                         median_abs_error_px=0.05, p90_abs_error_px=0.1, max_abs_error_px=0.2, bias_px=0,
                         within_target=1.0, time_us_per_section=100 if method == "model_fit" else 1, meets_target=1,
                         board_found=1, quick=quick))
        for level, meets in zip((0.0, 0.02, 0.04), ok):
            rows.append(dict(method=method, factor="noise", level=level, sections=10, answered=10,
                             mean_abs_error_px=0.1 if meets else 2, median_abs_error_px=0.1, p90_abs_error_px=0.2,
                             max_abs_error_px=0.3, bias_px=0, within_target=0.95 if meets else 0.2,
                             time_us_per_section=100, meets_target=meets, board_found=1, quick=quick))
    return pd.DataFrame(rows)


class BenchChartsTest(unittest.TestCase):
    def setUp(self):
        common.setup_style()
        self.caught = Caught()
        self.saved = bench_charts.save
        bench_charts.save = self.caught
        self.out = tempfile.mkdtemp()

    def tearDown(self):
        bench_charts.save = self.saved

    def test_one_frame_size_is_named_and_the_legend_lists_only_what_is_drawn(self):
        bench_charts.render_speed_accuracy(render_rows(), self.out)
        fig = self.caught.figures["bench-render-speed-accuracy"]
        self.assertEqual(len(fig.axes), 1)
        title = fig._suptitle.get_text()
        self.assertIn("at 640 x 360", title)
        self.assertNotIn("per frame size", title)
        labels = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
        self.assertIn("gaussian (GL)", labels)
        self.assertIn("disc (CPU)", labels)
        self.assertNotIn("gaussian (CPU)", labels)  # not in the data: not in the legend
        self.assertNotIn("r = 4 px", labels)
        self.assertIn("--quick", title)

    def test_a_damaged_bench_file_is_named_by_line_and_left_out(self):
        # A cell "abc" stopped the report (exit 10); a file cut inside a row was read as a shorter row.
        header = ",".join(bench_charts.RENDER_COLUMNS)
        row = "blur,gaussian,gl,1,640,360,1,8.2,8.2,0.01,2.0"
        folder = tempfile.mkdtemp()
        with open(os.path.join(folder, "render.csv"), "w") as f:
            f.write(f"{header}\n{row}\n{row.replace(',640,', ',abc,')}\n")
        _, render, notes = bench_charts.load_bench(folder)
        self.assertIsNone(render)
        self.assertIn("render.csv: line 3, column width: not a number ('abc')", " ".join(notes))
        with open(os.path.join(folder, "render.csv"), "w") as f:
            f.write(f"{header}\n{row}\n{row[:20]}")
        _, render, notes = bench_charts.load_bench(folder)
        self.assertIsNone(render)
        self.assertIn("render.csv: line 3 has 5 fields, the header 11 (cut short?)", " ".join(notes))
        with open(os.path.join(folder, "render.csv"), "w") as f:
            f.write(f"{header}\n{row}\n")
        self.assertIsNotNone(bench_charts.load_bench(folder)[1])

    def test_two_sizes_get_two_panels(self):
        bench_charts.render_speed_accuracy(render_rows(((640, 360), (1920, 1080)), quick=0), self.out)
        fig = self.caught.figures["bench-render-speed-accuracy"]
        self.assertEqual(len([a for a in fig.axes if a.get_visible()]), 2)
        self.assertIn("per frame size", fig._suptitle.get_text())
        self.assertNotIn("--quick", fig._suptitle.get_text())

    def test_frame_budget_verdict_follows_the_numbers(self):
        over = bench_charts.render_frame(render_rows(p99=56.9), self.out)[0]
        self.assertTrue(any("p99 is 56.9 ms" in n and "NOT within it" in n for n in over.notes), over.notes)
        self.assertFalse(any("target met" in n for n in over.notes))
        under = bench_charts.render_frame(render_rows(p99=6.0), self.out)[0]
        self.assertTrue(any("120 Hz refresh (8.3 ms): within it" in n for n in under.notes), under.notes)

    def test_a_method_that_fails_from_the_first_level_gets_a_mark(self):
        charts = bench_charts.stability(measure_rows(), self.out)
        notes = charts[0].notes
        self.assertTrue(any("thesis threshold count" in n and "from the first level of noise" in n for n in notes),
                        notes)
        fig = self.caught.figures["bench-stability-within-target"]
        ax = fig.axes[0]
        # The X marks: one per failing method - the thesis count's at the first level (x = 0), the model fit's at
        # the third (x = 2).
        marks = [c.get_offsets().tolist() for c in ax.collections if c.get_sizes().size and c.get_sizes()[0] == 110]
        xs = sorted(p[0][0] for p in marks)
        self.assertEqual(xs, [0.0, 2.0])

    def test_error_against_r_per_psf_says_where_each_family_breaks(self):
        rows = []
        for fam, rel in (("psf_disc", (0.01, 0.01, 0.01)), ("near_focus", (0.30, 0.015, 0.01))):
            for level, e in zip((0.7, 1.0, 1.5), rel):
                for method in ("model_fit", "thesis"):
                    err = e if method == "model_fit" else 2.0
                    rows.append(dict(method=method, factor=fam, level=level, sections=77, answered=77,
                                     mean_abs_error_px=err * level, median_abs_error_px=err * level,
                                     p90_abs_error_px=2 * err * level, max_abs_error_px=3 * err * level, bias_px=0,
                                     within_target=1.0, time_us_per_section=100, meets_target=1, board_found=1,
                                     median_rel_error=err, p90_rel_error=2 * err, quick=0))
        charts = bench_charts.stability(pd.DataFrame(rows), self.out)
        self.assertEqual([c.name for c in charts], ["bench-measure-error-vs-r"])
        t = charts[0].table.set_index(["method", "psf"])
        self.assertEqual(t.loc[("model_fit", "disc"), "breaks_at_r_px"], "holds everywhere")
        # near focus: median 30 % at r = 0.7 breaks there; 1.5 % median with a 3 % p90 holds
        self.assertEqual(t.loc[("model_fit", "disc x floor 0.35 px (near focus)"), "breaks_at_r_px"], "0.7")
        self.assertEqual(t.loc[("model_fit", "disc x floor 0.35 px (near focus)"), "holds_at_r_px"], "1, 1.5")
        self.assertEqual(t.loc[("thesis", "disc"), "breaks_at_r_px"], "0.7")
        self.assertIn("bench-measure-error-vs-r", self.caught.figures)

    def test_frame_growth_charts_each_sweep_and_says_what_fits_a_refresh(self):
        rows = [dict(kind="growth", method="objects", backend="gl", radius_px=3, width=1920, height=1080, samples=40,
                     median_ms=1 + 2 * n, p99_ms=1.5 + 2 * n, objects=n, quick=0) for n in (1, 2, 8, 32)]
        rows += [dict(kind="growth", method="radius", backend="gl", radius_px=r, width=1920, height=1080, samples=40,
                      median_ms=5, p99_ms=6, objects=2, quick=0) for r in (1, 4, 8, 16)]
        chart = bench_charts.render_growth(pd.DataFrame(rows), self.out)[0]
        self.assertTrue(any("each ball adds about 2.00 ms" in n for n in chart.notes), chart.notes)
        self.assertTrue(any("up to 2 balls" in n for n in chart.notes), chart.notes)  # p99 of 8 balls: 17.5 ms
        fig = self.caught.figures["bench-frame-growth"]
        self.assertEqual(len(fig.axes), 2)  # no size rows: no size panel
        with self.assertRaises(common.Skip):
            bench_charts.render_growth(render_rows(), self.out)

    def test_speed_accuracy_has_a_better_direction_and_plain_ticks(self):
        bench_charts.measure_speed_accuracy(measure_rows(quick=1), self.out)
        fig = self.caught.figures["bench-measure-speed-accuracy"]
        ax = fig.axes[0]
        self.assertTrue(any("better" in t.get_text() for t in ax.texts))
        fig.canvas.draw()
        ticks = [t.get_text() for t in ax.get_xticklabels() if t.get_text()]
        self.assertTrue(ticks and all("^" not in t and "$" not in t for t in ticks), ticks)
        self.assertIn("--quick", ax.get_title(loc="left"))

    def test_fitted_model_on_the_model_fit_leaves_both_visible(self):
        rows = measure_rows()
        fit = rows[(rows["method"] == "model_fit") & (rows["factor"] == "base")].assign(method="fitted_model",
                                                                                        time_us_per_section=4)
        bench_charts.measure_speed_accuracy(pd.concat([rows, fit], ignore_index=True), self.out)
        ax = self.caught.figures["bench-measure-speed-accuracy"].axes[0]
        marks = {c.get_label(): c for c in ax.collections if not c.get_label().startswith("_")}
        ring = marks["model fit (r_px)"]
        diamond = marks["fitted thin-lens model (+ model fit time)"]
        # Where the numbers put them (104 us: the model fit's 100 plus its own 4; 0.05 px both), not moved apart...
        self.assertEqual(ring.get_offsets().tolist(), [[100.0, 0.05]])
        self.assertEqual(diamond.get_offsets().tolist(), [[104.0, 0.05]])
        # ...so the model fit is an open ring wider than the filled diamond drawn over it.
        self.assertEqual(ring.get_facecolors().size, 0, "the model fit's ring is open")
        self.assertGreater(ring.get_sizes()[0], 2 * diamond.get_sizes()[0])
        self.assertGreater(diamond.get_zorder(), ring.get_zorder())

    def test_stability_labels_stay_in_their_panels_and_levels_have_three_digits(self):
        rows = measure_rows()
        rows = pd.concat([rows] + [rows[rows["factor"] == "noise"].assign(factor=f, level=rows["level"] * k + 0.279508)
                                   for f, k in (("vignetting", 10), ("distortion", -5), ("tilt", 1))],
                         ignore_index=True)
        charts = bench_charts.stability(rows, self.out)
        for name in ("bench-stability-within-target", "bench-stability-error"):
            fig = self.caught.figures[name]
            fig.canvas.draw()
            width = fig.bbox.width
            for i, ax in enumerate(a for a in fig.axes if a.get_visible()):
                column = i % 3
                box = ax.xaxis.label.get_window_extent()
                # Within its third of the figure: not past the figure's edge, not under the next panel's label.
                self.assertGreaterEqual(box.x0, column * width / 3 - 1, (name, ax.get_xlabel()))
                self.assertLessEqual(box.x1, (column + 1) * width / 3 + 1, (name, ax.get_xlabel()))
                self.assertIn("sweep", ax.get_xlabel())
        ticks = [t.get_text() for t in self.caught.figures["bench-stability-within-target"].axes[1].get_xticklabels()]
        self.assertEqual(ticks, ["0.28", "0.48", "0.68"])  # vignetting: 0.279508, 0.479508, 0.679508
        t = charts[0].table.set_index(["method", "factor"])
        self.assertEqual(t.loc[("model_fit", "vignetting"), "holds_at"], "0.28, 0.48")
        self.assertEqual(t.loc[("model_fit", "vignetting"), "breaks_at"], "0.68")

    def test_flagged_share_per_level_with_the_phase_limited_line(self):
        rows = measure_rows()
        phase = rows[rows["factor"] == "noise"].assign(factor="phase", level=rows["level"] * 10 + 0.05)
        phase = phase.assign(answered=[10, 7, 4] * 2, phase_limited=[0, 3, 6] * 2)
        rows = pd.concat([rows.assign(phase_limited=0), phase], ignore_index=True)
        bench_charts.stability(rows, self.out)
        fig = self.caught.figures["bench-stability-flagged"]
        ax = next(a for a in fig.axes if a.get_visible() and "pixel" in a.get_xlabel())
        model = [ln for ln in ax.get_lines() if ln.get_label() == bench_charts.METHOD_LABELS["model_fit"]][0]
        self.assertEqual(list(np.round(model.get_ydata(), 3)), [0.0, 0.3, 0.6])  # 1 - answered / sections
        dotted = [ln for ln in ax.get_lines() if ln.get_linestyle() == ":"][0]
        self.assertEqual(list(np.round(dotted.get_ydata(), 3)), [0.0, 0.3, 0.6])  # phase_limited / sections

    def test_levels_are_written_with_three_significant_digits(self):
        self.assertEqual([bench_charts.level_text(v) for v in (0.279508, 17.8885, 1000, 95, 0.04, -0.3, 0)],
                         ["0.28", "17.9", "1000", "95", "0.04", "-0.3", "0"])



def procedure_rows(rows):
    """procedures.csv rows from (procedure, trials, rmse, rmse_se, within, bias, bias_se, fails), truth 1, 200 runs."""
    return pd.DataFrame([{"procedure": p, "condition": "nominal", "trials": n, "runs": 200, "failed": 0, "truth": 1.0,
                          "bias": b, "bias_se": bse, "sd": 0.05, "rmse": r, "rmse_se": rse, "within_target": w,
                          "fails": f, "us_per_trial": 1.0} for p, n, r, rse, w, b, bse, f in rows])


class ProcedureClaimsTest(unittest.TestCase):
    """The bench page's sentences about procedures follow the CSV's verdicts: ties are ties, undecided is said."""

    def test_two_procedures_first_at_the_same_trials_are_a_tie_not_an_alphabetical_winner(self):
        d = procedure_rows([("quest_plus", 40, 0.084, 0.006, "yes", 0.0, 0.005, "no"),
                            ("staircase_1u3d", 40, 0.080, 0.007, "yes", 0.0, 0.005, "no"),
                            ("constant_stimuli", 40, 0.2, 0.01, "no", 0.0, 0.005, "no")])
        notes = bench_charts.procedure_claims(d, "5 % lapses")
        self.assertIn("a tie", notes[0])
        self.assertIn("1-up/3-down", notes[0])
        self.assertIn("QUEST+", notes[0])
        self.assertNotIn("first by", notes[0])

    def test_one_first_names_it_with_its_monte_carlo_error_and_an_earlier_undecided_row(self):
        d = procedure_rows([("quest_plus", 20, 0.105, 0.01, "undecided", 0.0, 0.005, "no"),
                            ("quest_plus", 40, 0.06, 0.004, "yes", 0.0, 0.005, "no"),
                            ("staircase_1u2d", 80, 0.07, 0.004, "yes", 0.0, 0.005, "no")])
        notes = bench_charts.procedure_claims(d, "nominal observer")
        self.assertIn("first by QUEST+ (40 trials; RMSE QUEST+ 6.0 ± 0.4 %", notes[0])
        self.assertTrue(any("at 20 trials" in n and "undecided with 200 runs" in n for n in notes), notes)

    def test_failure_only_where_the_verdict_says_so(self):
        d = procedure_rows([("quest_plus", 160, 0.3, 0.01, "no", -0.26, 0.001, "yes"),
                            ("staircase_1u2d", 160, 0.16, 0.01, "no", 0.148, 0.01, "undecided"),
                            ("staircase_1u3d", 160, 0.05, 0.01, "yes", 0.01, 0.01, "no")])
        notes = bench_charts.procedure_claims(d, "beyond")
        self.assertTrue(any("QUEST+ fails - bias -26.0 %" in n for n in notes), notes)
        self.assertTrue(any("1-up/2-down" in n and "undecided" in n and "fails" not in n for n in notes), notes)
        self.assertFalse(any("1-up/3-down fails" in n for n in notes), notes)


if __name__ == "__main__":
    unittest.main()
