"""Display timing: frame-to-frame intervals of the sessions that ran in a real window (frames.csv).

  frame intervals     histogram of the intervals between consecutive flips of a trial, per session, against one
                      60 Hz refresh (16.7 ms) and the runner's dropped-frame threshold (1.5 refresh periods)

frames.csv (`blurcue export`, beside trials.csv; columns in codebook.csv): study, participant, session_id, window, trial_index, frame_index,
flip_time_s, dropped; one row per recorded flip, flip_time_s from the trial's first flip, dropped = the runner's
verdict (an interval > 1.5 refresh periods). Only sessions with window = 1 are timed: a headless session (window = 0)
runs on a simulated clock, whose flips are spaced by the simulation and say nothing about the display.
"""
import os

import numpy as np
import pandas as pd

import matplotlib.pyplot as plt

from common import Chart, Skip, read_text_csv, save

FRAME_COLUMNS = ["study", "participant", "session", "window", "trial_index", "frame_index", "flip_time_s", "dropped"]
REFRESH_MS = 1000 / 60   # one refresh of a 60 Hz display
DROP_FACTOR = 1.5        # the runner calls an interval longer than 1.5 refresh periods a dropped frame
CLIP_MS = 120            # the histogram ends here; longer intervals are counted in its last bin
BIN_MS = 0.2
SESSION_KEYS = ["study", "participant", "session"]
SESSION_COLORS = ["#0072B2", "#E69F00", "#009E73", "#CC79A7", "#D55E00", "#56B4E9", "#F0E442", "#000000"]


def load_frames(path):
    """frames.csv -> DataFrame (numbers typed); Skip naming the file when it is missing, unreadable, or has no window
    column (then real-window and headless sessions cannot be told apart)."""
    path = str(path)
    if not os.path.isfile(path):
        raise Skip(f"{path}: no such file - display timing skipped (written by `blurcue export` beside trials.csv)")
    try:
        d = read_text_csv(path)
    except ValueError as e:
        raise Skip(f"{path}: {e} - display timing skipped")
    d = d.rename(columns={"session_id": "session"})  # the record's session id (codebook.csv)
    if "window" not in d.columns and all(c in d.columns for c in FRAME_COLUMNS if c != "window"):
        raise Skip(f"{path}: no window column (an export from before it was added?) - real-window sessions cannot be "
                   f"told from headless ones on a simulated clock; display timing skipped")
    missing = [c for c in FRAME_COLUMNS if c not in d.columns]
    if missing:
        raise Skip(f"{path}: not a blurcue frames.csv (missing column{'s' if len(missing) > 1 else ''} "
                   f"{', '.join(missing)}) - display timing skipped")
    for c in FRAME_COLUMNS[2:]:
        d[c] = pd.to_numeric(d[c].replace("", np.nan), errors="coerce")
    return d


def intervals(frames):
    """One row per pair of consecutive flips of a trial (frame_index k-1 -> k): the session keys, trial_index,
    frame_index (of the later flip), interval_ms and the runner's dropped flag of the later flip."""
    d = frames.dropna(subset=["session", "trial_index", "frame_index", "flip_time_s"])
    d = d.sort_values(SESSION_KEYS + ["trial_index", "frame_index"], kind="stable")
    g = d.groupby(SESSION_KEYS + ["trial_index"], sort=False)
    step = g["frame_index"].diff()
    out = d.assign(interval_ms=g["flip_time_s"].diff() * 1000)
    columns = SESSION_KEYS + ["trial_index", "frame_index", "interval_ms", "dropped"]
    return out.loc[step == 1, columns].reset_index(drop=True)


def summary(frames):
    """Per session: trials, frames, intervals, median / p95 / p99 / max interval (ms; percentiles interpolate
    linearly between ranks), the runner's dropped count and its share of the intervals, and as a cross-check the
    intervals longer than 1.5 x the session's median."""
    per_session = {key: g["interval_ms"].to_numpy() for key, g in intervals(frames).groupby(SESSION_KEYS)}
    rows = []
    for key, f in frames.groupby(SESSION_KEYS, sort=True):
        ms = per_session.get(key, np.array([]))
        row = dict(zip(SESSION_KEYS, key))
        median = float(np.median(ms)) if len(ms) else np.nan
        dropped = int((f["dropped"] == 1).sum())
        row.update(trials=f["trial_index"].nunique(), frames=len(f), intervals=len(ms), median_ms=median,
                   p95_ms=float(np.percentile(ms, 95)) if len(ms) else np.nan,
                   p99_ms=float(np.percentile(ms, 99)) if len(ms) else np.nan,
                   max_ms=float(ms.max()) if len(ms) else np.nan,
                   rate_hz=1000 / median if len(ms) and median > 0 else np.nan,
                   dropped=dropped, dropped_share=dropped / len(ms) if len(ms) else np.nan,
                   long_vs_median=int((ms > DROP_FACTOR * median).sum()) if len(ms) else 0)
        rows.append(row)
    return pd.DataFrame(rows)


def _label(row):
    return f"{row['study']} {row['participant']} session {row['session']}"


def charts(path, out_dir):
    """The frame-interval histogram and the per-session table, from frames.csv at `path` (window sessions only)."""
    frames = load_frames(path)
    if frames.empty:
        raise Skip(f"{path}: no frames recorded - display timing skipped")
    sessions = frames.groupby(SESSION_KEYS).ngroups
    window = frames[frames["window"] == 1]
    if window.empty:
        raise Skip(f"{path}: no window sessions - all {sessions} session{'s' if sessions != 1 else ''} ran headless "
                   f"on a simulated clock, whose flips are spaced by the simulation and say nothing about display timing")
    t = summary(window)
    iv = intervals(window)
    if iv.empty:
        raise Skip(f"{path}: the window sessions have no two consecutive flips in a trial - nothing to time")

    fig, ax = plt.subplots(figsize=(8.2, 4.2))
    # From half a refresh (or the shortest interval) to two refreshes (or the longest, up to CLIP_MS): the spike at one
    # refresh, its tail and the dropped-frame threshold all get room.
    low = float(np.floor(min(0.5 * REFRESH_MS, iv["interval_ms"].min() - 1)))
    top = float(min(CLIP_MS, max(2 * REFRESH_MS, iv["interval_ms"].max() * 1.05)))
    width = BIN_MS if top - low <= 60 else 4 * BIN_MS
    bins = np.arange(max(0.0, low), top + width, width)
    one = len(t) == 1
    by_session = t.set_index(SESSION_KEYS, drop=False)
    for i, (key, g) in enumerate(iv.groupby(SESSION_KEYS, sort=True)):
        row = by_session.loc[key]
        color = SESSION_COLORS[i % len(SESSION_COLORS)]
        label = (f"{_label(row)}: {row['frames']} frames, median {row['median_ms']:.2f} ms, "
                 f"{row['dropped']} dropped")
        ax.hist(np.clip(g["interval_ms"], bins[0], bins[-1] - 1e-9), bins=bins,
                histtype="stepfilled" if one else "step", color=color, alpha=0.85 if one else 1.0, lw=1.2, label=label)
    ax.axvline(REFRESH_MS, color="#333333", lw=1, ls="--", label=f"one 60 Hz refresh ({REFRESH_MS:.1f} ms)")
    ax.axvline(DROP_FACTOR * REFRESH_MS, color="#D55E00", lw=1, ls=":",
               label=f"dropped above {DROP_FACTOR:g} refreshes ({DROP_FACTOR * REFRESH_MS:.1f} ms at 60 Hz)")
    ax.set_yscale("log")
    ax.set_ylim(0.7, None)
    ax.set_xlim(bins[0], bins[-1])
    ax.set_xlabel(f"interval between consecutive flips of a trial (ms; {width:g} ms bins)")
    ax.set_ylabel("intervals (log scale)")
    ax.set_title(f"Display timing, window sessions: {len(iv)} frame intervals in {len(t)} "
                 f"session{'s' if len(t) != 1 else ''}", loc="left")
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.17), ncol=1, handlelength=1.6)
    png, svg = save(fig, out_dir, "frame-intervals")

    headless = sessions - len(t)
    notes = [f"{len(t)} window session{'s' if len(t) != 1 else ''} timed"
             + (f"; {headless} headless session{'s' if headless != 1 else ''} left out (simulated clock)"
                if headless else ""),
             "interval: time between flips k-1 and k of one trial (flip_time_s runs from the trial's first flip, so "
             "the gap between trials is not an interval); percentiles interpolate linearly between ranks",
             "dropped: the runner's verdict (interval > 1.5 refresh periods of the display it ran on), dropped_share "
             "of the intervals; long_vs_median: intervals > 1.5 x the session's median, a check independent of the "
             "refresh rate the runner assumed; rate_hz = 1000 / median interval"]
    clipped = int((iv["interval_ms"] > bins[-1]).sum())
    if clipped:
        notes.append(f"{clipped} interval{'s' if clipped != 1 else ''} longer than {bins[-1]:.0f} ms drawn in the "
                     f"histogram's last bin (max {iv['interval_ms'].max():.0f} ms)")
    below = int((iv["interval_ms"] < bins[0]).sum())
    if below:
        notes.append(f"{below} interval{'s' if below != 1 else ''} shorter than {bins[0]:.0f} ms drawn in the "
                     f"histogram's first bin")
    for row in t.itertuples():
        if row.long_vs_median != row.dropped:
            notes.append(f"{_label(row._asdict())}: {row.long_vs_median} intervals > 1.5 x the median "
                         f"({row.median_ms:.2f} ms) but the runner flagged {row.dropped} as dropped")
    short = int((iv["interval_ms"] < 0.5 * REFRESH_MS).sum())
    if short:
        notes.append(f"{short} interval{'s' if short != 1 else ''} shorter than half a 60 Hz refresh - flips not "
                     f"tied to the display's refresh (no vsync?)")
    gaps = int(len(window) - window.groupby(SESSION_KEYS + ["trial_index"]).ngroups - len(iv))
    if gaps:
        notes.append(f"{gaps} flip{'s' if gaps != 1 else ''} after a gap in frame_index: no interval counted there")
    return [Chart("frame-intervals", png, svg, t, notes)]
