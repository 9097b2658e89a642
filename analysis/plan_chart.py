#!/usr/bin/python3
"""Power against participants, from the plan.csv `blurcue plan` writes.

  /usr/bin/python3 analysis/plan_chart.py --plan DIR/plan.csv --out DIR [--title STUDY] [--target 0.8]

Writes DIR/power.png and DIR/power.svg: one line per condition's exact binomial test (thin) and the t-test across
participants (the GLMM stand-in, thick), the target power as a dashed line, and each test's smallest N reaching it
marked. Exit 3 when plan.csv is missing or not a plan.
"""
import argparse
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import matplotlib.pyplot as plt  # noqa: E402
import pandas as pd  # noqa: E402

import common  # noqa: E402

COLUMNS = ["test", "condition", "measure", "participants", "power"]


def smallest_n(g, target):
    """The first N whose power reaches the target (None when none does)."""
    reached = g[g["power"] >= target]
    return int(reached["participants"].iloc[0]) if len(reached) else None


def chart(plan, out_dir, title, target):
    tested = plan[plan["test"] != "none"].copy()
    tested["power"] = pd.to_numeric(tested["power"], errors="coerce")
    tested["participants"] = pd.to_numeric(tested["participants"], errors="coerce")
    fig, ax = plt.subplots(figsize=(7.5, 4.2))
    binomial = tested[tested["test"] == "binomial"]
    conditions = list(dict.fromkeys(binomial["condition"]))
    cmap = plt.get_cmap("viridis")
    for i, condition in enumerate(conditions):
        g = binomial[binomial["condition"] == condition].sort_values("participants")
        n = smallest_n(g, target)
        ax.plot(g["participants"], g["power"], lw=1, color=cmap(i / max(1, len(conditions) - 1)),
                label=f"binomial, {condition}" + (f" (N = {n})" if n else ""))
    for measure, g in tested[tested["test"] == "participants_t"].groupby("measure"):
        g = g.sort_values("participants")
        n = smallest_n(g, target)
        ax.plot(g["participants"], g["power"], lw=2.6, color="#D55E00",
                label=f"t-test across participants ({measure}; GLMM stand-in)" + (f" (N = {n})" if n else ""))
        if n:
            ax.plot([n], [g[g["participants"] == n]["power"].iloc[0]], "o", color="#D55E00", ms=6)
    for condition, g in tested[tested["test"] == "slope_t"].groupby("condition"):
        g = g.sort_values("participants")
        n = smallest_n(g, target)
        ax.plot(g["participants"], g["power"], lw=2.6, color="#0072B2",
                label=f"slope t-test, {condition} (depth matching)" + (f" (N = {n})" if n else ""))
    ax.axhline(target, color="#555555", ls="--", lw=1)
    ax.set_xlabel("participants (N)")
    ax.set_ylabel("power (share of simulated studies with p < alpha)")
    ax.set_ylim(-0.02, 1.02)
    ax.set_title(f"{title}: power against participants (dashed: {target:.0%})", loc="left")
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=7.5, handlelength=1.5)
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
    png, _ = chart(plan, args.out, args.title, args.target)
    print(f"plan_chart: drew {os.path.basename(png)} and power.svg", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
