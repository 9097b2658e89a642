"""Benchmark charts from `blurcue bench measure` (measure.csv) and `blurcue bench render` (render.csv).

  speed vs accuracy, measurement   time per section (log) against mean |error| (log) of every measurement and
                                   estimation method on the base scene, every other condition faint behind; Pareto
                                   front = methods no other method beats on both time and error
  speed vs accuracy, rendering     time per whole-frame blur (log) against max error in 8-bit levels against the exact
                                   convolution, per frame size; Pareto front per size and radius
  two-ball frame                   region-by-region vs the thesis's whole-frame blur, median and p99 per frame
  stability                        share of sections within target, mean |error|, and share of sections flagged
                                   (not answered; phase_limited dotted) against each swept factor (noise, contrast,
                                   JPEG, flaws, blur size, tilt, vignetting, distortion, a filter on the sampled image,
                                   the edge angle, the sub-pixel phase); the target line of docs/benchmarks.md and the
                                   level where each method first fails
  error against r, per PSF         median (and p90) |error| / true r against the true r for each PSF family (disc,
                                   Gaussian, disc x floor at floor/defocus ratios, near focus with a 0.35 px floor),
                                   one panel per method; the issue's 2 % / 5 % lines and where each family breaks
Target (docs/benchmarks.md, `bench measure`): |error| <= max(0.25 px, 5 %) on >= 90 % of sections (and >= 50 %
answered).
"""
import csv
import os
import textwrap

import numpy as np
import pandas as pd
import matplotlib.pyplot as plt
from matplotlib import ticker

from common import Chart, Skip, save

MEASURE_COLUMNS = ["method", "factor", "level", "sections", "answered", "mean_abs_error_px", "median_abs_error_px",
                   "p90_abs_error_px", "max_abs_error_px", "bias_px", "within_target", "time_us_per_section",
                   "meets_target", "board_found"]
RENDER_COLUMNS = ["kind", "method", "backend", "radius_px", "width", "height", "samples", "median_ms", "p99_ms",
                  "mean_abs_error_levels", "max_abs_error_levels"]  # and objects (frame and growth rows), quick

WITHIN_TARGET = 0.9      # docs/benchmarks.md: within max(0.25 px, 5 %) on >= 90 % of sections
ERROR_FLOOR_PX = 0.25    # the target's absolute part
REFRESH_MS = 1000 / 60   # one 60 Hz refresh
REFRESH_120_MS = 1000 / 120  # one 120 Hz refresh: the frame budget of a 120 Hz display
ONE_LEVEL = 1.0          # docs/benchmarks.md: GL and CPU within 1 level of the exact convolution for r >= 4

METHOD_LABELS = {"model_fit": "model fit (r_px)", "thesis": "thesis threshold count (r_thesis_px)",
                 "eq37": "eq. 3.7 from edge 1", "fitted_model": "fitted thin-lens model"}
METHOD_COLORS = {"model_fit": "#0072B2", "thesis": "#D55E00", "eq37": "#E69F00", "fitted_model": "#009E73"}
FACTOR_LABELS = {"noise": "sensor noise std (fraction of full scale)", "contrast": "Michelson contrast",
                 "jpeg": "JPEG quality", "flaws": "printing flaws (dark spots)", "blur": "true blur radius r (px)",
                 "tilt": "camera tilt (deg)", "vignetting": "vignetting (fall-off at the corner)",
                 "distortion": "lens distortion k1 in camera.json (barrel < 0)",
                 "post_gaussian": "Gaussian on the sampled image, std (px)",
                 "post_sharpen": "unsharp mask on the sampled image (std 0.6 px), amount",
                 "edge_angle": "edges' angle to the pixel rows (deg; board turned)",
                 "phase": "edge's distance from a pixel centre (px; level board, 0.45 px filter)"}
RENDER_COLORS = {("gaussian", "gl"): "#0072B2", ("gaussian", "cpu"): "#56B4E9", ("disc", "gl"): "#D55E00",
                 ("disc", "cpu"): "#E69F00"}
RADIUS_MARKERS = {1: "o", 4: "s", 8: "^", 16: "D"}


# The bench CSVs' text columns; every other column of theirs holds numbers (empty: none).
BENCH_TEXT_COLUMNS = {"method", "factor", "kind", "backend", "procedure", "condition", "within_target", "fails"}


def _read(path, columns):
    """A bench CSV, or (None, note) when missing or not what the C++ writer produces."""
    if not os.path.isfile(path):
        return None, f"{path}: no such file"
    try:
        df = pd.read_csv(path)
    except Exception as e:  # empty or garbled file
        return None, f"{path}: not a readable CSV ({type(e).__name__})"
    missing = [c for c in columns if c not in df.columns]
    if missing:
        return None, f"{path}: missing columns {', '.join(missing)}"
    if df.empty:
        return None, f"{path}: no rows"
    # Every row whole and every number a number: a file cut inside a row read as a shorter row, and a cell "abc"
    # stopped the report (exit 10). Either is said, naming the line, and the bench charts are left out.
    with open(path, newline="", encoding="utf-8", errors="replace") as f:
        for line, row in enumerate(csv.reader(f), start=1):
            if len(row) != len(df.columns):
                return None, f"{path}: line {line} has {len(row)} fields, the header {len(df.columns)} (cut short?)"
    for c in df.columns:
        if c in BENCH_TEXT_COLUMNS:
            continue
        bad = df[c].notna() & pd.to_numeric(df[c], errors="coerce").isna()
        if bad.any():
            i = int(np.flatnonzero(bad.to_numpy())[0])
            return None, f"{path}: line {i + 2}, column {c}: not a number ({df[c].iloc[i]!r})"
        df[c] = pd.to_numeric(df[c], errors="coerce")
    return df, None


def level_text(value):
    """A swept level as the charts and tables write it: 3 significant digits, plainly (a PSF family's radius
    0.279508 as 0.28, 17.8885 as 17.9, 1000 as 1000 - not 1e+03)."""
    return f"{float(f'{value:.3g}'):g}"


def quick_note(df, sep=" - "):
    """'a --quick run ...' after `sep` when the bench CSV says its rows come from one (its quick column), else ''."""
    return sep + "a --quick run (few levels, small frames: a smoke test, not the full benchmark)" \
        if "quick" in df.columns and (df["quick"] == 1).any() else ""


def plain_log_ticks(axis):
    """Log-axis ticks as plain numbers (0.1, 1, 10, 100), not 10^-1 powers or crowded minor labels."""
    axis.set_major_locator(ticker.LogLocator(base=10, subs=(1.0, 2.0, 5.0), numticks=12))
    axis.set_major_formatter(ticker.FuncFormatter(lambda v, _: f"{v:g}"))
    axis.set_minor_formatter(ticker.NullFormatter())


def better_arrow(ax, text="better: faster and more accurate", start=(0.30, 0.30)):
    """An arrow toward the lower left (less time, less error), where a method would rather be."""
    ax.annotate(text, xy=(0.04, 0.04), xytext=start, xycoords="axes fraction", textcoords="axes fraction",
                arrowprops={"arrowstyle": "->", "color": "#444444", "lw": 1.2}, fontsize=8.5, color="#444444",
                ha="left", va="bottom")


def load_bench(folder):
    """(measure DataFrame or None, render DataFrame or None, notes naming what is missing)."""
    notes = []
    measure, note = _read(os.path.join(folder, "measure.csv"), MEASURE_COLUMNS)
    if note:
        notes.append(note)
    render, note = _read(os.path.join(folder, "render.csv"), RENDER_COLUMNS)
    if note:
        notes.append(note)
    return measure, render, notes


def pareto_front(times, errors):
    """Boolean mask of points no other point beats on both (lower time and lower error, one strictly)."""
    t = np.asarray(times, float)
    e = np.asarray(errors, float)
    keep = np.ones(len(t), bool)
    for i in range(len(t)):
        dominated = (t <= t[i]) & (e <= e[i]) & ((t < t[i]) | (e < e[i]))
        keep[i] = not dominated.any()
    return keep


def _draw_front(ax, t, e, color="#444444"):
    """Step line through the Pareto points (sorted by time), the staircase no method gets below."""
    order = np.argsort(t)
    ax.step(np.asarray(t)[order], np.asarray(e)[order], where="post", color=color, lw=1, ls="--", zorder=1)


# --------------------------------------------------------------------------------------------------------------------
# Measurement


# eq. 3.7 and the fitted model start from the model fit's measurements (src/calib/calibrate.cc), so their cost per
# section is the model fit's time plus their own (which the bench records alone: 0 for eq. 3.7, not timed).
ESTIMATORS = ("eq37", "fitted_model")


def _total_time(measure):
    """time_us_per_section, plus the model fit's time of the same condition for the estimators."""
    fit = measure[measure["method"] == "model_fit"].set_index(["factor", "level"])["time_us_per_section"]
    key = pd.MultiIndex.from_arrays([measure["factor"], measure["level"]])
    own = measure["time_us_per_section"].to_numpy()
    upstream = pd.Series(fit.reindex(key).to_numpy(), index=measure.index).fillna(0).to_numpy()
    return pd.Series(np.where(measure["method"].isin(ESTIMATORS), own + upstream, own), index=measure.index)


def measure_speed_accuracy(measure, out_dir):
    if (measure["factor"] == "base").sum() == 0:
        raise Skip("bench measure: no 'base' condition rows in measure.csv")
    measure = measure.assign(total_us=_total_time(measure))
    base = measure[measure["factor"] == "base"]
    notes = []
    timed = base["total_us"] > 0
    fig, ax = plt.subplots(figsize=(7.5, 4.8))
    # Every other condition, faint, so the spread of each method shows behind its base point.
    others = measure[(measure["factor"] != "base") & (measure["total_us"] > 0) & (measure["mean_abs_error_px"] > 0)]
    for method, g in others.groupby("method"):
        ax.scatter(g["total_us"], g["mean_abs_error_px"], s=10, alpha=0.25, color=METHOD_COLORS.get(method, "#555555"),
                   lw=0)
    b = base[timed]
    front = pareto_front(b["total_us"], b["mean_abs_error_px"])
    for (_, r), on_front in zip(b.iterrows(), front):
        color = METHOD_COLORS.get(r["method"], "#555555")
        # Measurement methods as large open rings, the estimators (whose time includes the model fit they start from)
        # as small filled diamonds on top: the fitted model can land on the model fit (0.0374 px at 406 us against
        # 0.0370 px at 391 us in a --quick run), where a filled marker of the same size hid it. Neither is moved.
        if r["method"] in ESTIMATORS:
            style = dict(s=45, marker="D", color=color, edgecolor="white", lw=0.6, zorder=5)
        else:
            style = dict(s=130, marker="o", facecolor="none", edgecolor=color, lw=2.2, zorder=4)
        ax.scatter([r["total_us"]], [max(r["mean_abs_error_px"], 1e-4)], **style,
                   label=METHOD_LABELS.get(r["method"], r["method"]) +
                   (" (+ model fit time)" if r["method"] in ESTIMATORS else ""))
        if on_front:
            ax.scatter([r["total_us"]], [r["mean_abs_error_px"]], s=300, marker="o", facecolor="none",
                       edgecolor="black", lw=0.8, zorder=3)
    if front.sum() > 1:
        _draw_front(ax, b.loc[front, "total_us"], b.loc[front, "mean_abs_error_px"])
    ax.axhline(ERROR_FLOOR_PX, color="#888888", ls=":", lw=1, label="0.25 px (the target's absolute floor)")
    ax.set_xscale("log")
    ax.set_yscale("log")
    plain_log_ticks(ax.xaxis)
    plain_log_ticks(ax.yaxis)
    better_arrow(ax)
    ax.set_xlabel("time per board-edge section (µs, log)")
    ax.set_ylabel("mean |error| against ground truth (px, log)")
    ax.set_title("Blur measurement: speed against accuracy" + quick_note(measure) +
                 "\nbase scene (large), every swept condition (faint)", loc="left")
    ax.scatter([], [], s=300, facecolor="none", edgecolor="black", lw=0.8, label="Pareto front (base scene)")
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8)
    png, svg = save(fig, out_dir, "bench-measure-speed-accuracy")
    if (~timed).any():
        notes.append(f"{', '.join(base.loc[~timed, 'method'])}: no time in measure.csv; not drawn")
    table = base[["method", "time_us_per_section", "total_us", "mean_abs_error_px", "p90_abs_error_px", "bias_px",
                  "within_target", "meets_target"]].copy()
    table = table.rename(columns={"time_us_per_section": "own_time_us", "total_us": "time_us_drawn"})
    table["pareto_front"] = False
    table.loc[b.index[front], "pareto_front"] = True
    swept = measure[measure["factor"] != "base"].groupby("method")
    table["conditions_meeting_target"] = table["method"].map(
        swept["meets_target"].apply(lambda s: f"{int(s.sum())}/{len(s)}"))
    table["median_error_over_conditions_px"] = table["method"].map(swept["mean_abs_error_px"].median())
    notes.append("error = mean |measured or estimated − true| over the scene's sections; target: within "
                 "max(0.25 px, 5 %) on >= 90 % of sections")
    notes.append("eq. 3.7 and the fitted model estimate from the model fit's measurements, so they are drawn at the "
                 "model fit's time plus their own (own_time_us; 0 = not timed by the bench)")
    return [Chart("bench-measure-speed-accuracy", png, svg, table, notes)]


def _sweeps(measure):
    """Factors in file order with their levels in sweep order (the writer sweeps from easy to hard)."""
    m = measure[measure["factor"] != "base"]
    return [(f, list(dict.fromkeys(m.loc[m["factor"] == f, "level"]))) for f in dict.fromkeys(m["factor"])]


def breakpoints(measure):
    """Per (method, factor): the levels where the method meets the target and the first where it fails."""
    rows = []
    for factor, levels in _sweeps(measure):
        for method, g in measure[measure["factor"] == factor].groupby("method", sort=False):
            g = g.set_index("level").loc[[lv for lv in levels if lv in set(g["level"])]]
            fails = g[g["meets_target"] == 0]
            broke = fails.iloc[0] if len(fails) else None
            lost = g[g["board_found"] == 0]
            rows.append({"method": method, "factor": factor,
                         "holds_at": ", ".join(level_text(lv) for lv in g.index[g["meets_target"] == 1]),
                         "breaks_at": level_text(fails.index[0]) if broke is not None else "holds everywhere",
                         "within_target_at_break": broke["within_target"] if broke is not None else np.nan,
                         "mean_error_at_break_px": broke["mean_abs_error_px"] if broke is not None else np.nan,
                         "board_not_found_from": level_text(lost.index[0]) if len(lost) else ""})
    return pd.DataFrame(rows)


PSF_FAMILY_LABELS = {"psf_disc": "disc", "psf_gaussian": "Gaussian", "psf_disc_floor_0.25": "disc x floor 0.25 R",
                     "psf_disc_floor_0.5": "disc x floor 0.5 R", "psf_disc_floor_1": "disc x floor 1 R",
                     "near_focus": "disc x floor 0.35 px (near focus)"}
PSF_FAMILY_COLORS = {"psf_disc": "#0072B2", "psf_gaussian": "#D55E00", "psf_disc_floor_0.25": "#009E73",
                     "psf_disc_floor_0.5": "#CC79A7", "psf_disc_floor_1": "#E69F00", "near_focus": "#000000"}
MEDIAN_REL, P90_REL = 0.02, 0.05  # issue 25, "Must hold"


def _is_psf_family(factor):
    return factor.startswith("psf_") or factor == "near_focus"


def error_vs_r(measure, out_dir):
    """Each method's relative error against the true r, one line per PSF family (bench measure's PSF sweeps)."""
    if "median_rel_error" not in measure.columns:
        raise Skip("bench measure: measure.csv has no median_rel_error column (written by an older blurcue)")
    fams = [f for f in dict.fromkeys(measure["factor"]) if _is_psf_family(f)]
    if not fams:
        raise Skip("bench measure: no PSF-family sweeps in measure.csv")
    methods = [m for m in ("model_fit", "thesis", "fitted_model") if m in set(measure["method"])]
    fig, axes = plt.subplots(1, len(methods), figsize=(4.6 * len(methods), 4.4), squeeze=False, sharey=True)
    rows = []
    for ax, method in zip(axes.flat, methods):
        for fam in fams:
            g = measure[(measure["factor"] == fam) & (measure["method"] == method)].sort_values("level")
            answered = g[g["answered"] > 0]
            color = PSF_FAMILY_COLORS.get(fam, "#555555")
            ax.plot(answered["level"], 100 * answered["median_rel_error"].clip(lower=5e-4), "-o", ms=3.5, lw=1.3,
                    color=color, label=PSF_FAMILY_LABELS.get(fam, fam))
            ax.plot(answered["level"], 100 * answered["p90_rel_error"].clip(lower=5e-4), ":", lw=1, color=color)
            holds = (g["answered"] * 2 >= g["sections"]) & (g["median_rel_error"] <= MEDIAN_REL) & \
                (g["p90_rel_error"] <= P90_REL)
            fails = g[~holds]
            if len(fails) and fails.iloc[0]["answered"] > 0:
                first = fails.iloc[0]
                ax.scatter([first["level"]], [100 * max(first["median_rel_error"], 5e-4)], marker="X", s=90,
                           color=color, edgecolor="black", lw=0.6, zorder=5)
            rows.append({"method": method, "psf": PSF_FAMILY_LABELS.get(fam, fam),
                         "holds_at_r_px": ", ".join(level_text(lv) for lv in g.loc[holds, "level"]),
                         "breaks_at_r_px": level_text(fails.iloc[0]["level"]) if len(fails) else "holds everywhere",
                         "median_rel_error_at_break": fails.iloc[0]["median_rel_error"] if len(fails) else np.nan,
                         "p90_rel_error_at_break": fails.iloc[0]["p90_rel_error"] if len(fails) else np.nan})
        ax.axhline(100 * MEDIAN_REL, color="black", ls="--", lw=0.9)
        ax.axhline(100 * P90_REL, color="black", ls="-.", lw=0.9)
        ax.set_xscale("log")
        ax.set_yscale("log")
        plain_log_ticks(ax.xaxis)
        plain_log_ticks(ax.yaxis)
        ax.set_xlabel("true r (px, 2 x std of the optical LSF)")
        ax.set_title(METHOD_LABELS.get(method, method), loc="left", fontsize=9)
    axes[0][0].set_ylabel("|error| / true r (%, log)\nsolid: median, dotted: p90")
    handles, labels = axes[0][0].get_legend_handles_labels()
    handles += [plt.Line2D([], [], color="black", ls="--", lw=0.9), plt.Line2D([], [], color="black", ls="-.", lw=0.9),
                plt.Line2D([], [], marker="X", ls="none", color="#777777", markeredgecolor="black", ms=9)]
    labels += ["2 % (median target)", "5 % (p90 target)", "first r where median > 2 % or p90 > 5 %"]
    fig.legend(handles, labels, loc="lower center", ncol=4, bbox_to_anchor=(0.5, -0.12), fontsize=8.5)
    fig.suptitle("Blur measurement against the true r, per PSF shape (one radius over the whole scene; noise 0.003)" +
                 quick_note(measure, "\n"), x=0.01, ha="left", fontsize=11)
    fig.tight_layout(rect=(0, 0.02, 1, 1))
    name = "bench-measure-error-vs-r"
    png, svg = save(fig, out_dir, name)
    notes = ["truth: 2 x the std of the line-spread function of the kernels the synthetic scene applied (defocus and "
             "floor, from their arrays), pixel aperture excluded",
             "floor R: a Gaussian floor of std ratio x the disc radius R; near focus: a 0.35 px floor under a disc of "
             "0 .. 1.5 px, so r starts at 0.7 px",
             "a method that answers fewer than half the sections at some r counts as broken there"]
    return [Chart(name, png, svg, pd.DataFrame(rows), notes)]


SWEEP_LABEL_CHARS = 36  # a stability panel's x label wrapped to this, so it stays under its own panel


def sweep_label(factor):
    """A stability panel's x label: the factor in words and the sweep's direction, wrapped to its panel's width (one
    line ran past the figure's edge: 'lens distortion k1 ...' at the left, '... (sweep order →' at the right)."""
    words = FACTOR_LABELS.get(factor, factor) + "  (sweep\u00a0order\u00a0→)"  # no break inside the direction
    return "\n".join(textwrap.wrap(words, SWEEP_LABEL_CHARS))


def stability(measure, out_dir):
    charts, against_r = [], []
    try:
        against_r = error_vs_r(measure, out_dir)
    except Skip:
        pass
    # The PSF families have their own chart against r (above); the panels here sweep the other factors.
    measure = measure[~measure["factor"].map(_is_psf_family)]
    sweeps = _sweeps(measure)
    if not sweeps:
        if against_r:
            return against_r
        raise Skip("bench measure: no swept factors in measure.csv (only the base scene)")
    table = breakpoints(measure)
    measure = measure.assign(flagged=1 - measure["answered"] / measure["sections"].clip(lower=1))
    for what, column, ylabel in (("within-target", "within_target", "share of sections within target"),
                                 ("error", "mean_abs_error_px", "mean |error| (px, log)"),
                                 ("flagged", "flagged", "share of sections not answered")):
        ncols = 3
        nrows = int(np.ceil(len(sweeps) / ncols))
        fig, axes = plt.subplots(nrows, ncols, figsize=(12, 3.4 * nrows), squeeze=False)
        for ax in axes.flat[len(sweeps):]:
            ax.set_visible(False)
        for ax, (factor, levels) in zip(axes.flat, sweeps):
            pos = {lv: i for i, lv in enumerate(levels)}
            for method, g in measure[measure["factor"] == factor].groupby("method", sort=False):
                g = g.assign(x=g["level"].map(pos)).sort_values("x")
                color = METHOD_COLORS.get(method, "#555555")
                y = g[column].clip(lower=1e-3) if column == "mean_abs_error_px" else g[column]
                ax.plot(g["x"], y, "-", color=color, lw=1.3, label=METHOD_LABELS.get(method, method))
                found = g["board_found"] == 1
                ax.scatter(g.loc[found, "x"], y[found], s=18, color=color, zorder=3)
                # Hollow: the board was not found, so the bench measured at the true pose.
                ax.scatter(g.loc[~found, "x"], y[~found], s=18, facecolor="white", edgecolor=color, zorder=3)
                fails = g[g["meets_target"] == 0]
                if len(fails):  # where the method first misses - its first level when it never meets the target
                    first = fails.iloc[0]
                    ax.scatter([first["x"]], [y[first.name]], marker="X", s=110, color=color, edgecolor="black",
                               lw=0.6, zorder=5)
            if column == "within_target":
                ax.axhline(WITHIN_TARGET, color="black", ls="--", lw=0.9)
                ax.set_ylim(-0.03, 1.05)
            elif column == "flagged":
                # Of them, flagged phase_limited (issue 42; older measure.csv files have no such column).
                if "phase_limited" in measure.columns:
                    g = measure[(measure["factor"] == factor) & (measure["method"] == "model_fit")]
                    g = g.assign(x=g["level"].map(pos)).sort_values("x")
                    ax.plot(g["x"], g["phase_limited"] / g["sections"].clip(lower=1), ":", color="black", lw=1.3)
                ax.set_ylim(-0.03, 1.05)
            else:
                ax.set_yscale("log")
                plain_log_ticks(ax.yaxis)
                ax.axhline(ERROR_FLOOR_PX, color="black", ls="--", lw=0.9)
            ax.set_xticks(range(len(levels)))
            ax.set_xticklabels([level_text(lv) for lv in levels])
            ax.set_xlabel(sweep_label(factor))
            ax.set_ylabel(ylabel)
        handles, labels = axes.flat[0].get_legend_handles_labels()
        handles += [plt.Line2D([], [], color="black", ls="--", lw=0.9),
                    plt.Line2D([], [], marker="X", ls="none", color="#777777", markeredgecolor="black", ms=9),
                    plt.Line2D([], [], marker="o", ls="none", markerfacecolor="white", markeredgecolor="#777777")]
        if column == "flagged":
            handles[-3] = plt.Line2D([], [], color="black", ls=":", lw=1.3)
        labels += ["target: 90 % of sections within max(0.25 px, 5 %)" if column == "within_target"
                   else "model fit: flagged phase_limited" if column == "flagged"
                   else "0.25 px (the target's absolute floor)",
                   "first level where the method misses the target", "board not found: measured at the true pose"]
        fig.legend(handles, labels, loc="lower center", ncol=3, bbox_to_anchor=(0.5, -0.02 - 0.04 / nrows),
                   fontsize=9)
        title = {"within-target": "Where each measurement method breaks: share of sections within target",
                 "error": "Where each measurement method breaks: mean |error| against ground truth",
                 "flagged": "Where each method gives no value: share of sections flagged"}[what]
        fig.suptitle(title + " (one factor swept at a time from the base scene)" + quick_note(measure, "\n"),
                     x=0.01, ha="left", fontsize=12)
        fig.tight_layout(rect=(0, 0.06, 1, 1))
        name = f"bench-stability-{what}"
        png, svg = save(fig, out_dir, name)
        never = table[table["holds_at"] == ""]
        notes = ["x: the factor's levels in sweep order, from the base scene's value to the hardest"] + \
                [f"{METHOD_LABELS.get(method, method)} misses the target from the first level of "
                 f"{', '.join(g['factor'])} (marked there)" for method, g in never.groupby("method", sort=False)] + [
                 "table: levels where each method meets docs/benchmarks.md's target and the first where it does not "
                 "(answered >= 50 % of sections and >= 90 % of them within max(0.25 px, 5 %))"]
        charts.append(Chart(name, png, svg, table if what == "within-target" else pd.DataFrame(), notes))
    return charts + against_r


# --------------------------------------------------------------------------------------------------------------------
# Rendering


def render_speed_accuracy(render, out_dir):
    blur = render[render["kind"] == "blur"]
    measured = blur[blur["method"].isin(["gaussian", "disc"])]
    if measured.empty:
        raise Skip("bench render: no gaussian / disc blur rows in render.csv")
    sizes = sorted({(int(w), int(h)) for w, h in zip(measured["width"], measured["height"])}, key=lambda s: s[0] * s[1])
    fig, axes = plt.subplots(1, len(sizes), figsize=(4.2 * len(sizes) + 1.5, 4.2), squeeze=False, sharey=True)
    top = max(3.5, float(measured["max_abs_error_levels"].max()) * 1.15)
    table_rows = []
    for ax, (w, h) in zip(axes.flat, sizes):
        g = measured[(measured["width"] == w) & (measured["height"] == h)]
        # A radius is a task, not a setting to trade: the front is over (method, backend) at each radius.
        front = pd.Series(False, index=g.index)
        for _, gr in g.groupby("radius_px"):
            front[gr.index] = pareto_front(gr["median_ms"], gr["max_abs_error_levels"])
            on = gr[front[gr.index].to_numpy()]
            if len(on) > 1:
                _draw_front(ax, on["median_ms"], on["max_abs_error_levels"], color="#999999")
        for (method, backend), gg in g.groupby(["method", "backend"]):
            for _, r in gg.iterrows():
                ax.scatter(r["median_ms"], r["max_abs_error_levels"], s=45,
                           marker=RADIUS_MARKERS.get(int(r["radius_px"]), "o"),
                           color=RENDER_COLORS.get((method, backend), "#555555"), zorder=3, edgecolor="white", lw=0.5)
        ax.scatter(g.loc[front, "median_ms"], g.loc[front, "max_abs_error_levels"], s=160, facecolor="none",
                   edgecolor="black", lw=0.8, zorder=2)
        ax.axhline(ONE_LEVEL, color="#888888", ls=":", lw=1)
        ax.set_xscale("log")
        plain_log_ticks(ax.xaxis)
        better_arrow(ax, "better", start=(0.45, 0.12))
        ax.set_title(f"{w} x {h}", fontsize=10.5)
        ax.set_xlabel("time per whole-frame blur (ms, log)")
        for (_, r), on_front in zip(g.iterrows(), front.to_numpy()):
            table_rows.append({"size": f"{w}x{h}", "method": r["method"], "backend": r["backend"],
                               "radius_px": r["radius_px"], "median_ms": r["median_ms"], "p99_ms": r["p99_ms"],
                               "mean_abs_error_levels": r["mean_abs_error_levels"],
                               "max_abs_error_levels": r["max_abs_error_levels"], "pareto_front": bool(on_front)})
        ax.set_ylim(-0.2, top)
    axes.flat[0].set_ylabel("max |error| vs exact convolution\n(8-bit levels)")
    # A legend entry only for what the chart draws.
    drawn = set(zip(measured["method"], measured["backend"]))
    radii = {int(r) for r in measured["radius_px"]}
    handles = [plt.Line2D([], [], marker="s", ls="none", color=c, ms=8, label=f"{m} ({b.upper()})")
               for (m, b), c in RENDER_COLORS.items() if (m, b) in drawn]
    handles += [plt.Line2D([], [], marker=mk, ls="none", color="#555555", ms=7, label=f"r = {r} px")
                for r, mk in RADIUS_MARKERS.items() if r in radii]
    handles += [plt.Line2D([], [], marker="o", ls="--", color="black", markerfacecolor="none", ms=11, lw=0.8,
                           label="Pareto front at one radius"),
                plt.Line2D([], [], ls=":", color="#888888", label="1 level (docs/benchmarks.md: reached for r >= 4)")]
    axes.flat[-1].legend(handles=handles, loc="upper left", bbox_to_anchor=(1.02, 1.0), fontsize=8)
    where = "per frame size" if len(sizes) > 1 else f"at {sizes[0][0]} x {sizes[0][1]}"
    fig.suptitle(f"Blur rendering: speed against accuracy {where}" + quick_note(render, "\n"), x=0.01, ha="left",
                 fontsize=12)
    fig.tight_layout()
    png, svg = save(fig, out_dir, "bench-render-speed-accuracy")
    notes = ["error: 8-bit sRGB levels against the continuous PSF applied exactly in the frequency domain, on a crop",
             "Pareto front per frame size and radius: no other method/backend at that radius is both faster and more "
             "accurate (a radius is what the scene asks for, not a setting to trade)"]
    bw = blur[blur["method"] == "butterworth"]
    if len(bw):
        notes.append("butterworth (CPU, frequency domain) is timed but its error is not measured by the bench: "
                     + "; ".join(f"{int(r['width'])}x{int(r['height'])} {r['median_ms']:.0f} ms"
                                 for _, r in bw.iterrows()))
    return [Chart("bench-render-speed-accuracy", png, svg, pd.DataFrame(table_rows), notes)]


def render_frame(render, out_dir):
    frames = render[render["kind"] == "frame"]
    if frames.empty:
        raise Skip("bench render: no two-ball frame rows in render.csv")
    fig, ax = plt.subplots(figsize=(6.5, 3.6))
    labels = {"region": "each ball blurred in its own layer", "whole_frame": "whole frame blurred (thesis)"}
    y = np.arange(len(frames))
    ax.barh(y + 0.18, frames["median_ms"], 0.36, color="#0072B2", label="median")
    ax.barh(y - 0.18, frames["p99_ms"], 0.36, color="#56B4E9", label="99th percentile")
    for yi, (_, r) in zip(y, frames.iterrows()):
        ax.text(r["median_ms"] * 1.1, yi + 0.18, f"{r['median_ms']:.1f} ms", va="center", fontsize=8.5)
        ax.text(r["p99_ms"] * 1.1, yi - 0.18, f"{r['p99_ms']:.1f} ms", va="center", fontsize=8.5)
    ax.axvline(REFRESH_MS, color="#D55E00", ls="--", lw=1, label="one 60 Hz refresh (16.7 ms)")
    ax.axvline(REFRESH_120_MS, color="#CC79A7", ls=":", lw=1.2, label="one 120 Hz refresh (8.3 ms)")
    ax.set_xscale("log")
    ax.set_xlim(right=frames["p99_ms"].max() * 4)
    ax.set_yticks(y)
    ax.set_yticklabels([labels.get(m, m) for m in frames["method"]])
    ax.set_xlabel("time per frame (ms, log)")
    w, h = int(frames["width"].iloc[0]), int(frames["height"].iloc[0])
    ax.set_title(f"Two rolling balls, {w} x {h}: time per frame" + quick_note(render), loc="left")
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8)
    ax.grid(axis="y", visible=False)
    png, svg = save(fig, out_dir, "bench-frame")
    table = frames[["method", "backend", "width", "height", "samples", "median_ms", "p99_ms", "mean_abs_error_levels",
                    "max_abs_error_levels"]].copy()
    notes = []
    region = frames[frames["method"] == "region"]
    whole = frames[frames["method"] == "whole_frame"]
    if len(region):
        # The frame budget, from the numbers drawn: a frame whose p99 exceeds a refresh misses that refresh.
        p99 = float(region["p99_ms"].iloc[0])
        verdict = lambda budget: "within it" if p99 <= budget else f"NOT within it ({p99 / budget:.1f} x over)"
        notes.append(f"frame budget: the region approach's p99 is {p99:.1f} ms - one 60 Hz refresh (16.7 ms): "
                     f"{verdict(REFRESH_MS)}; one 120 Hz refresh (8.3 ms): {verdict(REFRESH_120_MS)}")
    if len(region) and len(whole):
        speedup = whole["median_ms"].iloc[0] / region["median_ms"].iloc[0]
        notes.append(f"speed-up: the region approach is {speedup:.0f} x faster than the whole-frame blur "
                     f"(docs/benchmarks.md target >= 10 x: {'met' if speedup >= 10 else 'NOT met'}); "
                     f"outputs differ by at most {whole['max_abs_error_levels'].iloc[0]:.0f} levels")
    notes.append("error columns of the whole_frame row: difference to the region approach's output, not to an exact "
                 "reference")
    return [Chart("bench-frame", png, svg, table, notes)]


def render_growth(render, out_dir):
    """How a region-by-region frame's cost grows with the balls in it, the frame's size and the blur radius (one
    swept at a time from the two-ball frame), median and p99, against one 120 Hz and one 60 Hz refresh."""
    growth = render[render["kind"] == "growth"] if "kind" in render else render.iloc[0:0]
    if growth.empty:
        raise Skip("bench render: no growth rows in render.csv (written by blurcue bench render since it sweeps "
                   "balls, frame size and radius)")
    panels = [("objects", "balls in the frame", lambda g: g["objects"]),
              ("size", "frame size (megapixels)", lambda g: g["width"] * g["height"] / 1e6),
              ("radius", "blur radius (px)", lambda g: g["radius_px"])]
    panels = [p for p in panels if (growth["method"] == p[0]).any()]
    fig, axes = plt.subplots(1, len(panels), figsize=(4.2 * len(panels) + 1.5, 3.8), sharey=True, squeeze=False)
    notes = []
    for ax, (swept, label, x_of) in zip(axes[0], panels):
        g = growth[growth["method"] == swept].copy()
        g["x"] = x_of(g)
        g = g.sort_values("x")
        ax.plot(g["x"], g["median_ms"], "o-", color="#0072B2", label="median")
        ax.plot(g["x"], g["p99_ms"], "s--", color="#56B4E9", label="99th percentile")
        for budget, name, color in ((REFRESH_120_MS, "120 Hz", "#CC79A7"), (REFRESH_MS, "60 Hz", "#D55E00")):
            ax.axhline(budget, color=color, ls=":", lw=1.1, label=f"one {name} refresh ({budget:.1f} ms)")
        if swept == "objects":
            ax.set_xscale("log", base=2)
            ax.set_xticks(list(g["x"]))
            ax.set_xticklabels([f"{int(v)}" for v in g["x"]])
            slope = np.polyfit(g["x"], g["median_ms"], 1)[0] if len(g) > 1 else float("nan")
            notes.append(f"each ball adds about {slope:.2f} ms a frame (median, a straight line through the sweep)")
            within = g[g["p99_ms"] <= REFRESH_MS]
            notes.append("p99 within one 60 Hz refresh up to " +
                         (f"{int(within['x'].max())} balls" if len(within) else "no number of balls swept"))
        elif swept == "size":
            for _, r in g.iterrows():
                ax.annotate(f"{int(r['width'])}x{int(r['height'])}", (r["x"], r["median_ms"]), fontsize=7.5,
                            textcoords="offset points", xytext=(4, -10))
        ax.set_yscale("log")
        plain_log_ticks(ax.yaxis)
        ax.set_xlabel(label)
        ax.set_title(f"{swept} swept", loc="left", fontsize=10)
    axes[0][0].set_ylabel("time per frame (ms, log)")
    axes[0][-1].legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), fontsize=8)
    base = growth.iloc[0]
    fig.suptitle("How a frame's cost grows, region by region (one thing swept at a time from two balls at "
                 f"{int(base['width'])}x{int(base['height'])})" + quick_note(render, "\n"), x=0.01, ha="left",
                 fontsize=11)
    fig.tight_layout()
    png, svg = save(fig, out_dir, "bench-frame-growth")
    table = growth[["method", "objects", "width", "height", "radius_px", "samples", "median_ms", "p99_ms"]].rename(
        columns={"method": "swept"})
    return [Chart("bench-frame-growth", png, svg, table, notes)]


# --------------------------------------------------------------------------------------------------------------------
# Procedures (`blurcue bench procedures`): which one to choose

PROCEDURE_COLUMNS = ["procedure", "condition", "trials", "runs", "failed", "truth", "bias", "bias_se", "sd", "rmse",
                     "rmse_se", "within_target", "fails", "us_per_trial"]
PROCEDURE_LABELS = {"constant_stimuli": "constant stimuli (8 levels, ML fit)", "staircase_1u2d": "1-up/2-down",
                    "staircase_1u3d": "1-up/3-down", "quest_plus": "QUEST+"}
PROCEDURE_COLORS = {"constant_stimuli": "#999999", "staircase_1u2d": "#E69F00", "staircase_1u3d": "#D55E00",
                    "quest_plus": "#0072B2"}
CONDITION_LABELS = {"nominal": "nominal observer", "lapses": "5 % lapses", "side_bias": "25 % side bias",
                    "steep_slope": "slope 8 (outside QUEST+'s prior)", "beyond_range": "threshold beyond the range"}
PRECISION = 0.10  # the stated precision: RMSE within 10 % of the target


def load_procedures(folder):
    """(procedures DataFrame or None, note)."""
    return _read(os.path.join(folder, "procedures.csv"), PROCEDURE_COLUMNS)


def _pct(value, truth):
    return f"{100 * value / truth:+.1f} %"


def procedure_claims(part, condition_label):
    """The sentences the chart's notes make for one condition, read from the CSV's own verdicts (`within_target`,
    `fails`: yes / no / undecided, decided in src/bench/procedure_bench.cc with the rows' Monte Carlo errors): who is
    first clearly within the stated precision - several at the same trial count are a tie, said as such - and who
    fails at the most trials. Rows a verdict leaves undecided are named as undecided at this number of runs."""
    notes = []
    runs = int(part["runs"].iloc[0]) if len(part) else 0
    first = {}
    for name, label in PROCEDURE_LABELS.items():
        rows = part[part["procedure"] == name].sort_values("trials")
        ok = rows[rows["within_target"] == "yes"]
        if len(ok):
            first[label] = ok.iloc[0]
    if first:
        best = min(int(r["trials"]) for r in first.values())
        winners = [label for label, r in first.items() if int(r["trials"]) == best]
        rmse = ", ".join(f"{label} {100 * first[label]['rmse'] / first[label]['truth']:.1f} ± "
                         f"{100 * first[label]['rmse_se'] / first[label]['truth']:.1f} %" for label in winners)
        if len(winners) == 1:
            notes.append(f"{condition_label}: RMSE clearly within {100 * PRECISION:.0f} % first by {winners[0]} "
                         f"({best} trials; RMSE {rmse}, ± its Monte Carlo standard error over {runs} runs)")
        else:
            notes.append(f"{condition_label}: a tie - {' and '.join(winners)} are all first clearly within "
                         f"{100 * PRECISION:.0f} % RMSE, at {best} trials (RMSE {rmse}, {runs} runs)")
        early = part[(part["within_target"] == "undecided") & (part["trials"] < best)]
        for _, r in early.iterrows():
            notes.append(f"{condition_label}: {PROCEDURE_LABELS.get(r['procedure'], r['procedure'])} at "
                         f"{int(r['trials'])} trials is within its Monte Carlo error of the {100 * PRECISION:.0f} % "
                         f"line (RMSE {100 * r['rmse'] / r['truth']:.1f} ± {100 * r['rmse_se'] / r['truth']:.1f} %): "
                         f"undecided with {runs} runs")
    else:
        notes.append(f"{condition_label}: no procedure is clearly within {100 * PRECISION:.0f} % RMSE within "
                     f"{int(part['trials'].max())} trials ({runs} runs)")
    for name, label in PROCEDURE_LABELS.items():
        rows = part[part["procedure"] == name].sort_values("trials")
        if rows.empty:
            continue
        last = rows.iloc[-1]
        se = 100 * last["bias_se"] / last["truth"]
        bias = f"bias {_pct(last['bias'], last['truth'])} (Monte Carlo se {se:.1f} %)"
        if last["fails"] == "yes":
            notes.append(f"{condition_label}: {label} fails - {bias} after {int(last['trials'])} trials")
        elif last["fails"] == "undecided":
            notes.append(f"{condition_label}: {label} - {bias} after {int(last['trials'])} trials, within its Monte "
                         f"Carlo error of the 15 % failure line: undecided with {runs} runs")
    return notes


def procedures(df, out_dir):
    conditions = [c for c in CONDITION_LABELS if c in set(df["condition"])]
    if not conditions:
        raise Skip("bench procedures: no known conditions in procedures.csv")
    fig, axes = plt.subplots(1, len(conditions), figsize=(3.0 * len(conditions), 3.4), sharey=True, squeeze=False)
    notes = []
    for ax, condition in zip(axes[0], conditions):
        part = df[df["condition"] == condition]
        for name, label in PROCEDURE_LABELS.items():
            rows = part[part["procedure"] == name].sort_values("trials")
            if rows.empty:
                continue
            rel = 100 * rows["rmse"] / rows["truth"]
            ax.plot(rows["trials"], rel, marker="o", ms=3.5, color=PROCEDURE_COLORS[name], label=label)
            bias = 100 * rows["bias"] / rows["truth"]
            ax.plot(rows["trials"], bias.abs().clip(lower=0.5), ls=":", lw=1, color=PROCEDURE_COLORS[name])
        ax.axhline(100 * PRECISION, color="#444444", ls="--", lw=0.8)
        ax.set_xscale("log", base=2)
        ax.set_yscale("log")
        ax.set_ylim(0.5, 300)  # a |bias| below half a percent is drawn at the floor
        ax.set_xticks(sorted(part["trials"].unique()))
        ax.set_xticklabels([str(t) for t in sorted(part["trials"].unique())])
        ax.set_title(CONDITION_LABELS[condition], loc="left", fontsize=9)
        ax.set_xlabel("trials (the participant's time)")
        notes += procedure_claims(part, CONDITION_LABELS[condition])
    axes[0][0].set_ylabel("threshold error (% of target)\nsolid: RMSE, dotted: |bias|")
    axes[0][-1].legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8)
    runs = int(df["runs"].iloc[0])
    fig.suptitle(f"Which procedure: speed (trials) against accuracy, {runs} simulated 2AFC runs each" +
                 quick_note(df), x=0.01, y=1.02, ha="left", fontsize=10)
    png, svg = save(fig, out_dir, "bench-procedures")
    table = df[PROCEDURE_COLUMNS].copy()
    notes.append("target: the Weibull threshold for QUEST+ and constant stimuli, the 70.7 % / 79.4 % point of the "
                 "observer's sensory function for the staircases; dashed line: the stated precision. 'Clearly within': "
                 "RMSE + 1.96 Monte Carlo standard errors <= 10 % of the target; 'fails': |bias| - 1.96 standard "
                 "errors > 15 %; between the two a claim is undecided at this number of runs")
    return [Chart("bench-procedures", png, svg, table, notes)]
