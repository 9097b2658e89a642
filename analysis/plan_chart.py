#!/usr/bin/python3
"""Power against participants, from the plan.csv `blurcue plan` writes.

  /usr/bin/python3 analysis/plan_chart.py --plan DIR/plan.csv --out DIR [--title STUDY] [--target 0.8]

Writes DIR/power.png and DIR/power.svg: one line per condition's exact test (thin), the t-tests across
participants (the GLMM stand-in, per group where the protocol has groups, thick), the comparisons between groups
(Welch) and between procedure cells (paired t on per-participant thresholds: the model's own difference solid, a
declared one dashed), the target power as a dashed line, and each test's smallest N reaching it marked. A plan with
procedure cells gets a second panel: the width of the 95 % interval of the mean threshold against N, per cell, with
its truth and bias in the legend - or, where the true threshold is not determined, that said in words. Exit 3 when
plan.csv is missing or not a plan.
"""
import argparse
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.ticker import MaxNLocator  # noqa: E402
import pandas as pd  # noqa: E402

import common  # noqa: E402

COLUMNS = ["test", "condition", "measure", "participants", "power"]
# Columns a plan with procedure cells adds (older plans lack them: no threshold panel then).
THRESHOLD_COLUMNS = ["true_threshold", "mean_estimate", "bias", "sd_estimate", "interval_width"]
COMPARISONS = {"paired_t": "paired t", "second_cell_t": "paired t, a second cell", "groups_t": "Welch t"}


def smallest_n(g, target):
    """The first N whose power reaches the target (None when none does)."""
    reached = g[g["power"] >= target]
    return int(reached["participants"].iloc[0]) if len(reached) else None


def _numeric(frame, columns):
    for c in columns:
        if c in frame.columns:
            frame[c] = pd.to_numeric(frame[c], errors="coerce")
    return frame


def power_panel(ax, plan, target):
    tested = _numeric(plan[plan["test"] != "none"].copy(), ["power", "participants"])
    tested = tested[tested["power"].notna()]
    exact = tested[tested["test"] == "exact"]
    conditions = list(dict.fromkeys(exact["condition"]))
    cmap = plt.get_cmap("viridis")
    for i, condition in enumerate(conditions):
        g = exact[exact["condition"] == condition].sort_values("participants")
        n = smallest_n(g, target)
        ax.plot(g["participants"], g["power"], lw=1, color=cmap(i / max(1, len(conditions) - 1)),
                label=f"exact, {condition}" + (f" (N = {n})" if n else ""))
    for (condition, measure), g in tested[tested["test"] == "participants_t"].groupby(["condition", "measure"],
                                                                                      sort=False):
        g = g.sort_values("participants")
        n = smallest_n(g, target)
        who = "" if condition == "all" else f"{condition}, "
        ax.plot(g["participants"], g["power"], lw=2.6, color="#D55E00", ls="-" if condition == "all" else ":",
                label=f"t-test across participants ({who}{measure}; GLMM stand-in)" + (f" (N = {n})" if n else ""))
        if n:
            ax.plot([n], [g[g["participants"] == n]["power"].iloc[0]], "o", color="#D55E00", ms=6)
    for condition, g in tested[tested["test"] == "slope_t"].groupby("condition", sort=False):
        g = g.sort_values("participants")
        n = smallest_n(g, target)
        ax.plot(g["participants"], g["power"], lw=2.6, color="#0072B2",
                label=f"slope t-test, {condition} (depth matching)" + (f" (N = {n})" if n else ""))
    colors = ["#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#0072B2"]
    compared = tested[tested["test"].isin(list(COMPARISONS))]
    for i, ((test, condition), g) in enumerate(compared.groupby(["test", "condition"], sort=False)):
        g = g.sort_values("participants")
        n = smallest_n(g, target)
        ax.plot(g["participants"], g["power"], lw=2.2, color=colors[i % len(colors)],
                ls="--" if "declared" in condition or test == "second_cell_t" else "-",
                label=f"{COMPARISONS[test]}: {condition}" + (f" (N = {n})" if n else ""))
        if n:
            ax.plot([n], [g[g["participants"] == n]["power"].iloc[0]], "o", color=colors[i % len(colors)], ms=5)
    ax.axhline(target, color="#555555", ls="--", lw=1)
    ax.set_xlabel("participants (N)")
    ax.xaxis.set_major_locator(MaxNLocator(integer=True))
    ax.set_ylabel("power\n(share of simulated studies with p < alpha)")
    ax.set_ylim(-0.02, 1.02)
    if ax.get_legend_handles_labels()[0]:
        ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=7.5, handlelength=1.5)
    else:
        ax.text(0.5, 0.5, "no test to plan here\n(for a procedure: give --difference;\nthe plan's notes say why one is not planned)", ha="center", va="center",
                transform=ax.transAxes, fontsize=9, color="#555555")


def threshold_label(g):
    """A cell's legend: its truth, mean estimate and bias - or, with no true threshold, that said in words."""
    first = g.iloc[0]
    cell = first["condition"]
    if pd.isna(first["true_threshold"]):
        return f"{cell}: mean estimate {first['mean_estimate']:.3g}, sd {first['sd_estimate']:.3g}; " \
               "true threshold not determined (see the plan's summary)"
    return f"{cell}: truth {first['true_threshold']:.3g}, mean {first['mean_estimate']:.3g} " \
           f"(bias {first['bias']:+.3g}), sd {first['sd_estimate']:.3g}"


def threshold_panel(ax, cells):
    cells = _numeric(cells.copy(), ["participants"] + THRESHOLD_COLUMNS)
    for condition, g in cells.groupby("condition", sort=False):
        g = g.sort_values("participants")
        ax.plot(g["participants"], g["interval_width"], lw=2, label=threshold_label(g))
    ax.set_xlabel("participants (N)")
    ax.xaxis.set_major_locator(MaxNLocator(integer=True))
    ax.set_ylabel("95 % interval width of the mean threshold\n(the procedure's units)")
    ax.set_ylim(bottom=0)
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=7.5, handlelength=1.5)


def chart(plan, out_dir, title, target):
    cells = plan[plan["test"] == "threshold"] if all(c in plan.columns for c in THRESHOLD_COLUMNS) else plan.iloc[0:0]
    if len(cells):
        fig, (ax, ax2) = plt.subplots(2, 1, figsize=(7.5, 7.6))
        threshold_panel(ax2, cells)
    else:
        fig, ax = plt.subplots(figsize=(7.5, 4.2))
    power_panel(ax, plan, target)
    ax.set_title(f"{title}: power against participants (dashed: {target:.0%})", loc="left")
    return common.save(fig, out_dir, "power")


def main(argv=None):
    parser = argparse.ArgumentParser(description="power.png and power.svg from blurcue plan's plan.csv")
    parser.add_argument("--plan", required=True)
    parser.add_argument("--out", required=True)
    parser.add_argument("--title", default="plan")
    parser.add_argument("--target", type=float, default=0.8)
    args = parser.parse_args(argv)
    try:
        plan = common.read_text_csv(args.plan)
    except ValueError as e:
        print(f"plan_chart: {args.plan}: {e}", file=sys.stderr)
        return 3
    missing = [c for c in COLUMNS if c not in plan.columns]
    if missing:
        print(f"plan_chart: {args.plan}: not a blurcue plan (missing {', '.join(missing)})", file=sys.stderr)
        return 3
    common.setup_style()
    try:
        png, _ = chart(plan, args.out, args.title, args.target)
    except OSError as e:  # a full disk, a read-only or vanished folder: one line naming the file, exit 3
        print(f"plan_chart: {e.filename or args.out}: cannot write the chart ({e.strerror or e})", file=sys.stderr)
        return 3
    print(f"plan_chart: drew {os.path.basename(png)} and power.svg", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
