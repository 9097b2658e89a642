"""Chart of `blurcue bench track` (results/bench/track.csv): time per frame against accuracy for tracking, full
detection on every frame, calibrate on every frame in the same process, and `blurcue calibrate` run as a command
on every frame (calibrate-process; its accuracy is the in-process calibrate's, NaN where its numbers differed).

  left    wall time per frame (ms, log) against the frame's median |error| / r of the measured r_px, one point per
          frame, one colour per mode; the 33 ms line (a 30 fps camera)
  right   the same time against the worst section's depth error (%); the 0.1 % line

Usage: track_chart.py [results/bench/track.csv] [OUT_DIR]   (writes OUT_DIR/bench-track.png and .svg)
"""
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

from common import chart_command, save

COLUMNS = ["mode", "frame", "status", "frame_ms", "cpu_ms", "max_depth_error_rel", "r_median_rel_error"]
COLORS = {"track": "#0072B2", "track-inline": "#009E73", "track-serial": "#56B4E9", "detect": "#E69F00", "calibrate": "#D55E00", "calibrate-process": "#CC79A7"}
FRAME_BUDGET_MS = 1000 / 30
DEPTH_TARGET = 0.001


def chart(df, out_dir):
    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    for mode, part in df.groupby("mode", sort=False):
        kw = dict(color=COLORS.get(mode, "#444444"), label=f"{mode} (median {part.frame_ms.median():.0f} ms wall, "
                  f"{part.cpu_ms.median():.0f} ms CPU)", alpha=0.8)
        axes[0].scatter(part.frame_ms, 100 * part.r_median_rel_error, **kw)
        axes[1].scatter(part.frame_ms, 100 * part.max_depth_error_rel, **kw)
    for ax in axes:
        ax.set_xscale("log")
        ax.axvline(FRAME_BUDGET_MS, color="#888888", ls="--", lw=1)
        ax.set_xlabel("ms per frame (wall; dashed: 33 ms)")
    axes[0].set_ylabel("median |r_px error| / r of the frame, %")
    axes[1].set_ylabel("worst section depth error, %")
    axes[1].axhline(100 * DEPTH_TARGET, color="#888888", ls=":", lw=1)
    axes[0].legend(fontsize=8)
    quick = " (quick run)" if "quick" in df and df["quick"].astype(bool).any() else ""
    fig.suptitle("blurcue bench track: time per frame against accuracy" + quick)
    return save(fig, out_dir, "bench-track")


def main(argv):
    return chart_command(argv, "results/bench/track.csv", "bench track", COLUMNS, chart)


if __name__ == "__main__":
    sys.exit(main(sys.argv))
