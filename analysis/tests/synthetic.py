"""Synthetic inputs for the analysis tests: a trials.csv as `blurcue export` writes it (all four studies, simulated
observers) and bench CSVs with the columns src/bench/measure_bench.cc and render_bench.cc write.

The observers follow known curves so the charts have something to show; the numbers in the bench fixtures follow
docs/benchmarks.md's "What the benchmarks measured" (model fit holds to noise 0.02, contrast 0.1, JPEG 80; the thesis
count meets the target nowhere; detection fails from contrast 0.2).
"""
import csv
import json
import math
import os
import zlib

import numpy as np

DEPTH_LEVELS = [2.0, 2.4, 2.8, 3.4, 4.0, 4.8, 5.7, 6.8, 8.2, 9.7, 11.6, 13.8, 16.5, 19.6, 23.4, 27.9, 33.2, 39.6,
                47.2, 56.3, 67.1, 80.0]
DISTANCES = [round(0.4 + i * 3.6 / 26, 3) for i in range(27)]
PATTERNS = [
    {"id": 1, "speed_cm_s": 3, "left": "measured", "right": "none"},
    {"id": 2, "speed_cm_s": 1.8, "left": "measured", "right": "none"},
    {"id": 3, "speed_cm_s": 3, "left": "estimated", "right": "none"},
    {"id": 4, "speed_cm_s": 1.8, "left": "estimated", "right": "none"},
    {"id": 5, "speed_cm_s": 3, "left": "measured", "right": "estimated"},
    {"id": 6, "speed_cm_s": 1.8, "left": "measured", "right": "estimated"},
]
# The fixed columns of a tidy trials.csv (store/export.cc; codebook.csv says what each holds), around the design's.
LEADING = ["study", "protocol_hash", "participant", "observer", "observer_params", "window", "session_id",
           "session_number", "session_status", "seed", "trial_index", "block", "block_name", "task", "practice", "swapped"]
TRAILING = ["left_source", "left_fixed", "right_source", "right_fixed", "status", "chosen_side", "chose_more_blurred",
            "chosen_interval", "yes_no", "rating", "adjusted_level", "correct", "rt_ms", "answered_at"]


def r_measured(edge):
    """Blur radius (px) at a (possibly fractional) edge: focus on edge 1, ~12 px at edge 11."""
    return 1.2 * (edge - 1)


def r_of(source, edge):
    if source == "measured":
        return r_measured(edge)
    if source == "estimated":  # eq. 3.7 reads ~25 % above the measurement at edge 11 (thesis 4.4)
        return r_measured(edge) * (1 + 0.025 * (edge - 1))
    return 0.0


def _answer(rng, r_left, r_right, alpha):
    """A simulated observer: can't tell when the blur difference is small, else mostly picks the more blurred."""
    diff = abs(r_left - r_right)
    if rng.random() < 0.9 * math.exp(-(diff / 0.8) ** 1.5):
        return "cant_tell"
    p_blurred = 0.5 + 0.45 * (1 - math.exp(-(diff / alpha) ** 1.5))
    if diff == 0:
        return "left" if rng.random() < 0.5 else "right"
    more = "left" if r_left > r_right else "right"
    less = "right" if more == "left" else "left"
    return more if rng.random() < p_blurred else less


def _cell(value):
    if value is None:
        return ""
    if isinstance(value, bool):
        return "1" if value else "0"
    if isinstance(value, dict):
        return json.dumps(value, separators=(",", ":"))
    if isinstance(value, float):
        return repr(round(value, 4))
    return str(value)


def trials_rows(participants=("P1", "P2", "P3", "P4", "P5", "P6"), studies=None, seed=7, unanswered=0.03):
    """Rows (dicts) of every study for the given participants."""
    rng = np.random.default_rng(seed)
    studies = studies or ["pre-research-depth-matching", "test1-static-grids", "test2-moving-balls", "test3-no-board"]
    rows = []
    session = 0
    for study in studies:
        for pi, participant in enumerate(participants):
            session += 1
            number = int("".join(ch for ch in participant if ch.isdigit()) or pi + 1)
            alpha = 2.0 * math.exp(rng.normal(0, 0.25))  # this observer's sensitivity to a blur difference
            trials = []
            if study == "pre-research-depth-matching":
                offset = rng.normal(0, 0.2)
                design = [(True, DISTANCES[13])] + [(False, d) for d in rng.permutation(DISTANCES)]
                for practice, d in design:
                    wanted = 35 * d ** -0.8 * math.exp(offset + rng.normal(0, 0.25))
                    cut = min(DEPTH_LEVELS, key=lambda c: abs(math.log(c / wanted)))
                    # The real picture's blur in arcmin, V-shaped around the camera's 1 m focus, and the picture's
                    # width at the eye (content.real_camera): what the depth-matching LMM regresses the set blur on.
                    trials.append(({"block_name": "matching", "distance_m": float(d), "practice": practice,
                                    "start_level": int(rng.integers(0, 22)), "r_scene_arcmin": 6.0 * abs(1 / d - 1),
                                    "picture_width_arcmin": 600.0}, 0, None, None, str(cut)))
            elif study == "test1-static-grids":
                swapped = number % 2 == 0  # by_participant counterbalancing
                edges = list(rng.permutation(range(1, 12)))
                for practice, edge in [(True, int(e)) for e in rng.choice(range(1, 12), 2, replace=False)] + \
                                      [(False, int(e)) for e in edges]:
                    left, right = ("estimated", "measured") if swapped else ("measured", "estimated")
                    rl, rr = r_of(left, edge), r_of(right, edge)
                    trials.append(({"block_name": "grids", "edge": edge, "practice": practice, "swapped": swapped,
                                    "r_left_px": rl, "r_right_px": rr, "r_scene_px": r_measured(edge) * 1.02},
                                   0, left, right, _answer(rng, rl, rr, alpha)))
            else:
                design = []
                for p in PATTERNS:
                    for swapped in (False, True):
                        design.append((0, "task1", p, None, swapped))
                for p in PATTERNS[1::2]:
                    for s in range(1, 11):
                        for swapped in (False, True):
                            design.append((1, "task2", p, s, swapped))
                practice = [design[int(i)] for i in rng.choice(12, 2, replace=False)]
                task1 = [design[int(i)] for i in rng.permutation(12)]
                task2 = [design[12 + int(i)] for i in rng.permutation(60)]
                for is_practice, (block, name, p, s, swapped) in [(True, d) for d in practice] + \
                                                                 [(False, d) for d in task1 + task2]:
                    left, right = (p["right"], p["left"]) if swapped else (p["left"], p["right"])
                    if s is None:  # mean radius over the run edge 1 -> 11
                        rl, rr = r_of(left, 6), r_of(right, 6)
                        r_scene = r_measured(6)
                    else:
                        rl, rr = r_of(left, s + 0.5), r_of(right, s + 0.5)
                        r_scene = r_measured(s + 0.5)
                    trials.append(({"block_name": name, "pattern": p, "practice": is_practice, "section": s,
                                    "swapped": swapped, "r_left_px": rl, "r_right_px": rr, "r_scene_px": r_scene},
                                   block, left, right, _answer(rng, rl, rr, alpha)))
            for index, (factors, block, left, right, choice) in enumerate(trials):
                answered = rng.random() >= unanswered
                rows.append({"study": study, "protocol_hash": "%016x" % zlib.crc32(study.encode()),
                             "participant": participant, "session": session, "seed": 1000 + session,
                             "trial_index": index, "block": block, **factors, "left": left, "right": right,
                             "choice": choice if answered else None,
                             "rt_ms": round(float(rng.lognormal(7.5, 0.4)), 1) if answered else None,
                             "answered_at": f"2025-01-0{1 + pi % 9}T10:{index // 60:02d}:{index % 60:02d}Z"
                             if answered else None})
    return rows


def tidy(row):
    """One synthetic row (session, left, right, choice, pattern object) as `blurcue export` writes it: the session id,
    each side's source, the answer split by kind, a pattern by its id with its speed beside it."""
    r = dict(row)
    r["session_id"] = r.pop("session")
    r["session_number"] = 1
    r["session_status"] = r.get("session_status", "completed")
    r["seed"] = "s%d" % r["seed"]
    r["observer"] = "simulated"
    r["window"] = 0
    adjustment = r["study"] == "pre-research-depth-matching"
    r["task"] = "adjustment" if adjustment else "forced_choice"
    for side in ("left", "right"):
        r[side + "_source"] = r.pop(side, None)
    choice = r.pop("choice", None)
    r["status"] = "unanswered" if choice is None else "answered"
    if choice is not None:
        r["adjusted_level" if adjustment else "chosen_side"] = choice
        if not adjustment and choice in ("left", "right") and r.get("r_left_px") is not None and \
                r["r_left_px"] != r["r_right_px"]:
            r["chose_more_blurred"] = int((choice == "left") == (r["r_left_px"] > r["r_right_px"]))
    for flag in ("practice", "swapped"):
        r[flag] = int(bool(r.get(flag, 0)))
    # Each radius in visual angle too, as the export writes it (a photo px here is 1.5 arcmin on the screen).
    for side in ("left", "right", "scene"):
        if r.get(f"r_{side}_px") is not None:
            r[f"r_{side}_arcmin"] = round(r[f"r_{side}_px"] * 1.5, 4)
    if isinstance(r.get("pattern"), dict):
        p = r["pattern"]
        r["pattern"], r["id"], r["speed_cm_s"] = p["id"], p["id"], p["speed_cm_s"]
    return r


def write_trials_csv(path, rows):
    """Writes rows the way store/export.cc does: every key as a column, sorted between the fixed ones, CRLF."""
    rows = [tidy(r) for r in rows]
    keys = sorted({k for r in rows for k in r} - set(LEADING) - set(TRAILING))
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    with open(path, "w", newline="", encoding="utf-8") as f:
        w = csv.writer(f, lineterminator="\r\n")
        w.writerow(LEADING + keys + TRAILING)
        for r in rows:
            w.writerow([_cell(r.get(c)) for c in LEADING + keys + TRAILING])
    return path


def write_bench_fixtures(folder):
    """measure.csv, render.csv and procedures.csv with realistic values (columns exactly as the C++ writers print
    them)."""
    os.makedirs(folder, exist_ok=True)
    sweeps = [("base", [0]), ("noise", [0.0, 0.002, 0.005, 0.01, 0.02, 0.04]),
              ("contrast", [0.9, 0.5, 0.2, 0.1, 0.05, 0.02]), ("jpeg", [95, 80, 60, 40, 20, 10]),
              ("flaws", [3, 10, 25, 50]), ("blur", [0.5, 1, 2, 4, 8, 12, 16, 20]), ("tilt", [20, 30, 45, 55, 65, 75])]
    breaks = {"model_fit": {"noise": 0.04, "contrast": 0.05, "jpeg": 60},
              "eq37": {"noise": 0.01, "contrast": 0.1, "jpeg": 40},
              "fitted_model": {"jpeg": 10}}
    times = {"model_fit": 107.0, "thesis": 0.8, "eq37": 0.0, "fitted_model": 0.006}
    lines = ["method,factor,level,sections,answered,mean_abs_error_px,median_abs_error_px,p90_abs_error_px,"
             "max_abs_error_px,bias_px,within_target,time_us_per_section,meets_target,board_found"]
    for factor, levels in sweeps:
        for i, level in enumerate(levels):
            hardness = i / max(1, len(levels) - 1)
            found = not (factor == "contrast" and level <= 0.2)
            for method in ("model_fit", "thesis", "eq37", "fitted_model"):
                broke_at = breaks.get(method, {}).get(factor)
                if method == "thesis":
                    err, within = 2.8 + 1.5 * hardness, 0.05
                else:
                    base = {"model_fit": 0.034, "eq37": 0.36, "fitted_model": 0.05}[method]
                    failing = broke_at is not None and (
                        level >= broke_at if factor == "noise" else level <= broke_at)
                    err = base * (1 + 2 * hardness) + (0.6 if failing else 0)
                    within = (0.72 - 0.2 * hardness) if failing else min(1.0, 0.995 - 0.04 * hardness)
                answered = 77 if method != "model_fit" or within > 0.5 else 60
                meets = answered * 2 >= 77 and within >= 0.9
                lines.append(f"{method},{factor},{level:g},77,{answered},{err:.4f},{0.8 * err:.4f},{1.9 * err:.4f},"
                             f"{3.5 * err:.4f},{(0.35 if method == 'eq37' else 0.01):.4f},{within:.3f},"
                             f"{times[method] * (1 + 0.1 * hardness):.2f},{int(meets)},{int(found)}")
    with open(os.path.join(folder, "measure.csv"), "w") as f:
        f.write("\n".join(lines) + "\n")

    lines = ["kind,method,backend,radius_px,width,height,samples,median_ms,p99_ms,mean_abs_error_levels,"
             "max_abs_error_levels,objects"]
    for w, h in ((1280, 720), (1920, 1080), (4592, 3056)):
        scale = w * h / (1920 * 1080)
        for method in ("gaussian", "disc"):
            for r in (1, 4, 8, 16):
                for backend in ("gl", "cpu"):
                    if method == "gaussian":
                        ms = scale * (17 * r ** 0.5 if backend == "gl" else 2.7 * r ** 0.5 + 3)
                    else:
                        ms = scale * (12.5 * r * r if backend == "gl" else 4.0 * r * r + 5)
                    mean = 0.1 if r == 1 else 0.02 if r == 4 else 0.01
                    mx = 3 if r == 1 else 1
                    lines.append(f"blur,{method},{backend},{r},{w},{h},{1 if w > 2000 else 3},{ms:.3f},"
                                 f"{ms * 1.1:.3f},{mean:.4f},{mx:.1f},0")
        lines.append(f"blur,butterworth,cpu,0,{w},{h},1,{60 * scale:.3f},{60 * scale:.3f},0.0000,0.0,0")
    lines.append("frame,region,gl,0,1920,1080,120,6.900,11.000,0.0000,0.0,2")
    lines.append("frame,whole_frame,gl,0,1920,1080,120,1256.000,1301.000,0.0000,6.0,2")
    # How a frame's cost grows: 2 ms a ball, a little with size and radius.
    for n in (1, 2, 8, 32):
        lines.append(f"growth,objects,gl,3,1920,1080,40,{1 + 2 * n:.3f},{1.3 + 2.2 * n:.3f},,,{n}")
    for r in (1, 4, 8, 16):
        lines.append(f"growth,radius,gl,{r},1920,1080,40,{5 + 0.1 * r:.3f},{6 + 0.1 * r:.3f},,,2")
    for w, h in ((1280, 720), (1920, 1080), (3840, 2160)):
        lines.append(f"growth,size,gl,3,{w},{h},40,{3 + w * h / 1e6:.3f},{4 + w * h / 1e6:.3f},,,2")
    with open(os.path.join(folder, "render.csv"), "w") as f:
        f.write("\n".join(lines) + "\n")

    # procedures.csv (`blurcue bench procedures`): errors that shrink as 1 / sqrt(trials), the failures it finds.
    lines = ["procedure,condition,trials,runs,failed,truth,bias,bias_se,sd,rmse,rmse_se,within_target,fails,"
             "us_per_trial"]
    truths = {"constant_stimuli": 1.0, "staircase_1u2d": 0.84, "staircase_1u3d": 0.9, "quest_plus": 1.0}
    spread = {"constant_stimuli": 1.6, "staircase_1u2d": 1.6, "staircase_1u3d": 1.15, "quest_plus": 1.0}
    biases = {"side_bias": 0.45, "beyond_range": -0.25}
    for condition in ("nominal", "lapses", "side_bias", "steep_slope", "beyond_range"):
        for procedure, truth in truths.items():
            for n in (20, 40, 80, 160):
                sd = 0.85 * spread[procedure] * truth / n ** 0.5
                bias = biases.get(condition, 0.01) * truth
                rmse = (sd * sd + bias * bias) ** 0.5
                bias_se, rmse_se = sd / 200 ** 0.5, rmse / 400 ** 0.5  # Monte Carlo errors of 200 runs, roughly
                within = "yes" if rmse + 2 * rmse_se <= 0.1 * truth else \
                    "no" if rmse - 2 * rmse_se > 0.1 * truth else "undecided"
                fails = "yes" if abs(bias) - 2 * bias_se > 0.15 * truth else \
                    "no" if abs(bias) + 2 * bias_se <= 0.15 * truth else "undecided"
                lines.append(f"{procedure},{condition},{n},200,0,{truth},{bias:.5f},{bias_se:.5f},{sd:.5f},"
                             f"{rmse:.5f},{rmse_se:.5f},{within},{fails},35")
    with open(os.path.join(folder, "procedures.csv"), "w") as f:
        f.write("\n".join(lines) + "\n")
    return folder


FRAME_COLUMNS = ["study", "participant", "session_id", "window", "trial_index", "frame_index", "flip_time_s",
                 "dropped"]
REFRESH_MS = 1000 / 60


def frames_rows(study, participant, session, window, trials):
    """frames.csv rows of one session: `trials` is a list with, per trial, the intervals (ms) between its consecutive
    flips (a trial of n intervals has n + 1 flips, the first at 0 s). dropped follows the runner: only in a window, an
    interval > 1.5 refresh periods (60 Hz)."""
    rows = []
    for trial_index, intervals in enumerate(trials):
        t = 0.0
        rows.append({"study": study, "participant": participant, "session_id": session, "window": int(window),
                     "trial_index": trial_index, "frame_index": 0, "flip_time_s": 0.0, "dropped": 0})
        for k, ms in enumerate(intervals, start=1):
            t += ms / 1000
            rows.append({"study": study, "participant": participant, "session_id": session, "window": int(window),
                         "trial_index": trial_index, "frame_index": k, "flip_time_s": t,
                         "dropped": int(bool(window) and ms > 1.5 * REFRESH_MS)})
    return rows


def report_frames(seed=5):
    """A frames.csv for the end-to-end report: two window sessions (jitter around 60 Hz, a few dropped frames) and a
    headless one (evenly spaced at a simulated 4 Hz)."""
    rng = np.random.default_rng(seed)
    rows = []
    for session, participant in ((101, "W1"), (102, "W2")):
        trials = [list(REFRESH_MS + np.abs(rng.normal(0, 0.3, 40))) for _ in range(13)]
        trials[3][10] = 2 * REFRESH_MS
        trials[7][5] = 3 * REFRESH_MS
        rows += frames_rows("test1-static-grids", participant, session, True, trials)
    rows += frames_rows("test1-static-grids", "P1", 2, False, [[250.0] * 8 for _ in range(13)])
    return rows


def write_frames_csv(path, rows):
    """Writes frames rows the way store/export.cc does (CRLF, the columns in FRAME_COLUMNS)."""
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    with open(path, "w", newline="", encoding="utf-8") as f:
        w = csv.writer(f, lineterminator="\r\n")
        w.writerow(FRAME_COLUMNS)
        for r in rows:
            w.writerow([repr(r[c]) if isinstance(r[c], float) else str(r[c]) for c in FRAME_COLUMNS])
    return path
