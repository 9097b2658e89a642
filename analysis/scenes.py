"""What each study showed its objects over, as the record's protocol says: a photo, or a tracked video (a take and the
folder `blurcue track` wrote for it). One line per study whose scene is a video, for the report's summary:

  video-ball-depth: a tracked video: take ../results/demo/take/take.avi, track folder ../results/demo/track (as the
  protocol names them); 5 frames at 30 fps (2 found, 3 tracked, 0 lost), one lens model: focus 339.6 mm, ...;
  exposure 16.7 ms; motion streak on screen ...; frames of the take presented per trial (frames.csv): median 2

Reads the record (SQLite: the protocol text of each study's versions), trials.csv (exposure_ms and the motion
columns, as recorded per trial) and frames.csv (frames per trial). The record keeps a protocol's text, not where the
protocol file was, so the take's paths (relative to the protocol) are looked for from the folders the caller gives
(the working directory, its protocols/ folder and the record's folder); where none holds the track folder the take's
frames are "not determined" in words.
"""
import csv
import json
import math
import os
import sqlite3

import pandas as pd


def protocol_versions(db_path):
    """[(study, hash, version number or None, protocol JSON (dict))] of every protocol version in the record at
    db_path, in the order the record holds them (a record of merged stations can hold several per study)."""
    con = sqlite3.connect(f"file:{db_path}?mode=ro", uri=True)
    try:
        try:
            rows = con.execute("SELECT s.name, pv.hash, pv.version, pv.json FROM protocol_versions pv "
                               "JOIN studies s ON s.id = pv.study_id ORDER BY pv.id").fetchall()
        except sqlite3.OperationalError:  # a record from before protocol versions were numbered
            rows = [(a, b, None, c) for a, b, c in con.execute(
                "SELECT s.name, pv.hash, pv.json FROM protocol_versions pv JOIN studies s ON s.id = pv.study_id "
                "ORDER BY pv.id").fetchall()]
    finally:
        con.close()
    out = []
    for study, hash_, version, text in rows:
        try:
            out.append((study, str(hash_), version, json.loads(text)))
        except ValueError:
            continue  # not a protocol blurcue wrote: nothing to describe
    return out


def read_track(folder):
    """track.csv of a track folder: (rows as dicts), or None when it is not there or not readable."""
    path = os.path.join(folder, "track.csv")
    try:
        with open(path, newline="", encoding="utf-8") as f:
            return list(csv.DictReader(f))
    except (OSError, UnicodeDecodeError, csv.Error):
        return None


def _number(text):
    try:
        value = float(text)
    except (TypeError, ValueError):
        return math.nan
    return value if math.isfinite(value) else math.nan


def describe_take(track_rows):
    """The take as track.csv gives it: frames, rate, how each was found, and the take's one lens model."""
    n = len(track_rows)
    statuses = [r.get("status", "") for r in track_rows]
    counts = ", ".join(f"{statuses.count(s)} {s}" for s in ("found", "tracked", "lost"))
    times = [_number(r.get("time_s")) for r in track_rows]
    steps = [b - a for a, b in zip(times, times[1:]) if math.isfinite(a) and math.isfinite(b) and b > a]
    rate = f" at {1 / (sum(steps) / len(steps)):.3g} fps" if steps else ""
    text = f"{n} frame{'' if n == 1 else 's'}{rate} ({counts})"
    posed = [r for r in track_rows if r.get("status") != "lost"]
    focus = {round(_number(r.get("focus_mm")), 3) for r in posed}
    aperture = {round(_number(r.get("aperture_mm")), 4) for r in posed}
    if len(focus) == 1 and len(aperture) == 1 and all(math.isfinite(v) for v in focus | aperture):
        text += f", one lens model: focus {next(iter(focus)):.1f} mm, aperture {next(iter(aperture)):.2f} mm"
    elif focus:
        finite = [v for v in focus if math.isfinite(v)]
        if finite:
            text += f", focus per frame {min(finite):.1f}-{max(finite):.1f} mm"
    return text


def _shown(trials, frames, study, hashes=None):
    """Exposure, motion and frames per trial as the study's trials recorded them (practice left out; only the trials
    of the protocol versions `hashes` where trials.csv names them)."""
    d = trials[(trials["study"] == study)]
    if hashes is not None and "protocol_hash" in d:
        d = d[d["protocol_hash"].astype(str).isin(hashes)]
    if "practice" in d:
        d = d[pd.to_numeric(d["practice"], errors="coerce") != 1]
    parts = []
    if "exposure_ms" in d:
        exposure = pd.to_numeric(d["exposure_ms"], errors="coerce").dropna().unique()
        if len(exposure) == 1:
            parts.append(f"exposure {exposure[0]:g} ms" + (" (no motion blur)" if exposure[0] == 0 else ""))
        elif len(exposure) > 1:
            parts.append(f"exposure {min(exposure):g}-{max(exposure):g} ms")
    f = None
    if frames is not None and not frames.empty and "study" in frames:
        f = frames[frames["study"] == study]
        keys = ["session_id", "trial_index"]
        if all(k in f and k in d for k in keys):  # the frames of the trials described (practice and others left out)
            def key(t):  # "session/trial" from numbers, however the CSV typed them (1, 1.0, "1")
                n = [pd.to_numeric(t[k], errors="coerce") for k in keys]
                return n[0].map("{:g}".format) + "/" + n[1].map("{:g}".format)
            f = f[key(f).isin(set(key(d)))]
        if f.empty:
            f = None

    def streaks(table, unit_suffix):
        out = []
        for side in ("left", "right"):
            x, y = f"motion_{side}_x_{unit_suffix}", f"motion_{side}_y_{unit_suffix}"
            if x in table and y in table:
                length = (pd.to_numeric(table[x], errors="coerce") ** 2
                          + pd.to_numeric(table[y], errors="coerce") ** 2) ** 0.5
                length = length.dropna()
                if len(length) and length.max() > 0:  # all 0: no motion blur, which the exposure says
                    out.append(f"{side} {length.mean():.2f} (max {length.max():.2f})")
        return out

    # On video the camera streaks the objects frame by frame (frames.csv, photo px); a trial's own streak (trials.csv)
    # is its objects' motion alone.
    per_frame = streaks(f, "px") if f is not None else []
    if per_frame:
        parts.append("motion streak per frame (frames.csv), mean over frames: " + ", ".join(per_frame) + " photo px")
    else:
        per_trial_streaks = streaks(d, "screen_px")
        if per_trial_streaks:
            parts.append("motion streak on screen, mean over trials: " + ", ".join(per_trial_streaks) + " screen px")
    if f is not None:
        # The frames that showed the take: after a timed stimulus the answer screen's frames show none.
        shown = f[f["take_status"].fillna("").astype(str) != ""] if "take_status" in f else f
        per_trial = shown.groupby(["session_id", "trial_index"]).size()
        if len(per_trial):
            parts.append(f"frames of the take presented per trial (frames.csv): median {per_trial.median():g} "
                         f"({per_trial.min()}-{per_trial.max()})")
        if "take_status" in f:
            status = shown["take_status"].dropna()
            if len(status):
                held = int((status == "held").sum())
                parts.append(f"{len(status) - held} of {len(status)} frames at the take frame's own pose, {held} "
                             f"held (a lost frame, or past the take's end)")
    return parts


def read_frames(path):
    """frames.csv (written by `blurcue export` beside trials.csv), or None."""
    try:
        return pd.read_csv(path) if path and os.path.exists(path) else None
    except (OSError, ValueError):
        return None


def video_scene_lines(db_path, trials, frames_path=None, search_dirs=()):
    """[(study, line)] for each take a study of the record was shown on: one line per distinct (video, track) of its
    protocol versions whose scene is a tracked video; where a study's versions name different takes (a record merged
    from stations with their own takes), each line names its versions and describes only their trials."""
    frames = read_frames(frames_path)
    takes = {}  # study -> {(video, track): [(hash, version)]}, in the record's order
    for study, hash_, version, protocol in protocol_versions(db_path):
        scene = protocol.get("scene") if isinstance(protocol, dict) else None
        if not isinstance(scene, dict) or "video" not in scene:
            continue
        # The take's identity as run (recorded_take: blurcue adds it to a video study's recorded text), so that one
        # protocol file run on two stations' own takes is two takes here.
        recorded = protocol.get("recorded_take")
        key = (str(scene.get("video", "")), str(scene.get("track", "")),
               json.dumps(recorded, sort_keys=True) if isinstance(recorded, dict) else "")
        takes.setdefault(study, {}).setdefault(key, []).append((hash_, version))
    lines = []
    for study in sorted(takes):
        several = len(takes[study]) > 1
        for (video, track, recorded), versions in takes[study].items():
            text = f"a tracked video: take {video}, track folder {track} (as the protocol names them, relative to it)"
            if several:
                names = ", ".join((f"{v} " if v is not None else "") + f"({h[:8]})" for h, v in versions)
                text = (f"{len(takes[study])} takes in this record's protocol versions; version"
                        f"{'s' if len(versions) > 1 else ''} {names}: " + text)
            found = None
            for base in search_dirs:
                folder = os.path.normpath(os.path.join(base, track))
                rows = read_track(folder)
                if rows is not None:
                    found = (folder, rows)
                    break
            if found:
                text += f"; the take ({found[0]}): " + describe_take(found[1])
            else:
                as_run = json.loads(recorded) if recorded else {}
                text += ("; the take's frames: not determined (the record keeps the protocol's text, not its folder, "
                         "and no track.csv was found from " + ", ".join(search_dirs or ["here"]) + ")" +
                         (f"; as run: {as_run['frames']} frames at {as_run['fps']:g} fps"
                          if {"frames", "fps"} <= set(as_run) else ""))
            hashes = [h for h, _ in versions]
            parts = _shown(trials, frames, study, hashes) if "study" in trials else []
            lines.append((study, text + ("; " + "; ".join(parts) if parts else "")))
    return lines
