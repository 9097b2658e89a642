"""Chart of `blurcue bench live` (results/bench/live.csv): what measuring N board sections a frame costs a live view
and the blur accuracy it buys, one point per N.

  left    median latency (arrival to display, ms; p95 as the bar's top) and dropped frames (%, right axis) against N;
          the 33 ms line (a 30 fps camera)
  right   speed against accuracy: median latency against the ball's median |drawn r - true r| / true r over the
          frames drawn (filled) and over their last third (open), each labelled by N

Usage: live_chart.py [results/bench/live.csv] [OUT_DIR]   (writes OUT_DIR/bench-live.png and .svg)
"""
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

from common import chart_command, save

COLUMNS = ["sections_per_frame", "frames_delivered", "frames_dropped", "median_latency_ms", "p95_latency_ms",
           "r_median_rel_error", "r_late_median_rel_error", "load1"]
FRAME_BUDGET_MS = 1000 / 30


def chart(df, out_dir):
    df = df.sort_values("sections_per_frame")
    n = df.sections_per_frame
    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    ax = axes[0]
    x = range(len(df))
    ax.bar(x, df.median_latency_ms, color="#0072B2", label="median latency")
    ax.errorbar(x, df.median_latency_ms, yerr=[[0] * len(df), df.p95_latency_ms - df.median_latency_ms], fmt="none",
                ecolor="#444444", capsize=3, label="to p95")
    ax.axhline(FRAME_BUDGET_MS, color="#888888", ls="--", lw=1)
    ax.set_xticks(list(x), [str(v) for v in n])
    ax.set_xlabel("sections measured a frame (--measure-sections)")
    ax.set_ylabel("latency, ms (dashed: 33 ms)")
    dropped = ax.twinx()
    dropped.plot(list(x), 100 * df.frames_dropped / df.frames_delivered.clip(lower=1), color="#D55E00", marker="o",
                 label="dropped")
    dropped.set_ylabel("frames dropped, %", color="#D55E00")
    dropped.set_ylim(bottom=0)
    ax.legend(fontsize=8, loc="upper left")
    ax = axes[1]
    ax.scatter(df.median_latency_ms, 100 * df.r_median_rel_error, color="#0072B2", label="all frames drawn")
    ax.scatter(df.median_latency_ms, 100 * df.r_late_median_rel_error, facecolors="none", edgecolors="#0072B2",
               label="their last third")
    for _, r in df.iterrows():
        ax.annotate(f"N={r.sections_per_frame:.0f}", (r.median_latency_ms, 100 * r.r_median_rel_error), fontsize=8,
                    xytext=(3, 3), textcoords="offset points")
    ax.set_xlabel("median latency, ms")
    ax.set_ylabel("ball's median |r error| / r, %")
    ax.set_yscale("log")
    ax.legend(fontsize=8)
    quick = " (quick run)" if "quick" in df and df["quick"].astype(bool).any() else ""
    fig.suptitle(f"blurcue bench live: sections measured a frame against latency and blur accuracy{quick} "
                 f"(load {df.load1.min():.1f}-{df.load1.max():.1f})", fontsize=10)
    fig.tight_layout()
    return save(fig, out_dir, "bench-live")


def main(argv):
    return chart_command(argv, "results/bench/live.csv", "bench live", COLUMNS, chart)


if __name__ == "__main__":
    sys.exit(main(sys.argv))
