"""Shared helpers of the analysis scripts: reading trials.csv, the chart record, the paper style, saving figures."""
import contextlib
import json
import math
import os
import re
import sys
from collections import namedtuple

import matplotlib

matplotlib.use("Agg")  # files only, no display
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

from stats import wilson  # noqa: E402

# What every chart function returns, one per chart: png/svg are None for a table-only entry or a skipped section.
Chart = namedtuple("Chart", "name png svg table notes")

STUDY_DEPTH = "pre-research-depth-matching"
STUDY_TEST1 = "test1-static-grids"
STUDY_TEST2 = "test2-moving-balls"
STUDY_TEST3 = "test3-no-board"
FORCED_CHOICE_STUDIES = (STUDY_TEST1, STUDY_TEST2, STUDY_TEST3)
STUDY_TITLES = {
    STUDY_DEPTH: "pre-research depth matching",
    STUDY_TEST1: "test 1 (static grids)",
    STUDY_TEST2: "test 2 (moving balls)",
    STUDY_TEST3: "test 3 (no board)",
}

# trials.csv as `blurcue export` writes it (codebook.csv beside it says what each column holds).
REQUIRED = ["study", "participant", "observer", "session_id", "trial_index", "block_name", "task", "practice",
            "swapped", "left_source", "left_fixed", "right_source", "right_fixed", "status", "chosen_side",
            "chosen_interval", "yes_no", "rating", "adjusted_level", "rt_ms"]
NUMERIC = ["edge", "section", "distance_m", "r_left_px", "r_right_px", "r_scene_px", "start_level", "rt_ms",
           "trial_index", "session", "speed_cm_s", "level", "adjusted_level", "r_scene_arcmin", "picture_width_arcmin"]
FIXED_UNITS = {"fixed_px": "px", "fixed_screen_px": "screen px", "fixed_arcmin": "arcmin"}

# One colour per blur source, the same in every chart (colour-blind-safe Okabe-Ito hues).
SOURCE_COLORS = {"measured": "#0072B2", "estimated": "#E69F00", "none": "#999999", "fitted": "#009E73",
                 "cant_tell": "#CC79A7"}
SOURCE_LABELS = {"measured": "measured", "estimated": "estimated", "none": "no blur", "fitted": "fitted model",
                 "cant_tell": "can't tell"}


class TrialsError(Exception):
    """trials.csv is missing or unreadable; the message names the file."""


class Skip(Exception):
    """A section cannot be drawn from these data; the message says why (shown in index.html)."""


# --------------------------------------------------------------------------------------------------------------------
# Reading


def _flag(value):
    """0/1 flags as the export writes them: '0'/'1', or JSON 'true'/'false' (a bool factor dumped as JSON)."""
    text = str(value).strip().lower()
    if text in ("1", "true", "1.0"):
        return 1
    if text in ("0", "false", "0.0", ""):
        return 0
    return np.nan


def text(series):
    """A column's cells as text, stripped: a value the analysis made missing (NaN, None) is "", a level written
    "NA", "nan", "None" or "null" stays what it says (read_text_csv keeps them; no NaN stands for a level)."""
    return series.map(lambda v: "" if v is None or (isinstance(v, float) and math.isnan(v)) else str(v).strip())


def read_text_csv(path):
    """A CSV with every cell as text (an empty cell stays empty, never NaN or 0); ValueError with a one-line reason
    when the file cannot be read as CSV."""
    try:
        return pd.read_csv(path, dtype=str, keep_default_na=False, na_values=[], encoding="utf-8")
    except (pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError, OSError) as e:
        first = str(e).strip().splitlines()[0] if str(e).strip() else type(e).__name__
        raise ValueError(f"not a readable CSV ({first})")


def load_trials(path):
    """trials.csv -> DataFrame with typed columns; raises TrialsError naming the file when it cannot be used.

    Cells are read as text first (an empty cell is 'not applicable', not 0), then the numeric columns are converted.
    The analysis's working columns are made here, in one place, from the tidy ones: session (session_id), left and
    right (a side's source, or "fixed R UNIT"), choice (the answer of whatever kind, "none" past a deadline),
    answered (bool), practice/swapped as 0/1, and pattern_id from a pattern factor.
    """
    path = str(path)
    if not os.path.isfile(path):
        raise TrialsError(f"{path}: no such file")
    try:
        df = read_text_csv(path)
    except ValueError as e:
        raise TrialsError(f"{path}: {e}")
    missing = [c for c in REQUIRED if c not in df.columns]
    if missing:
        raise TrialsError(f"{path}: not a blurcue trials.csv (missing column{'s' if len(missing) > 1 else ''} "
                          f"{', '.join(missing)})")
    df["session"] = df["session_id"]
    df = _with_procedures(df, os.path.join(os.path.dirname(os.path.abspath(path)), "procedures.csv"))
    for c in NUMERIC:
        if c in df.columns:
            df[c] = pd.to_numeric(df[c].replace("", np.nan), errors="coerce")
    for c in ("practice", "swapped"):
        df[c] = df[c].map(_flag) if c in df.columns else 0
    for side in ("left", "right"):
        source, fixed = df[f"{side}_source"], df[f"{side}_fixed"]
        df[side] = [f"fixed {v} {FIXED_UNITS[s]}" if s in FIXED_UNITS else s for s, v in zip(source, fixed)]
    # The answer, whatever its kind (each has its own column in the export).
    choice = df["status"].map({"timed_out": "none"}).fillna("")
    for column in ("chosen_side", "chosen_interval", "yes_no", "rating", "adjusted_level"):
        choice = choice.where(choice != "", text(df[column]))
    df["choice"] = choice
    df["answered"] = df["status"].isin(["answered", "timed_out"])
    if "pattern" in df.columns:
        df["pattern_id"] = pd.to_numeric(df["pattern"].replace("", np.nan), errors="coerce")
    return df


# What analysis/tracks.py reads of each procedure's parameters (procedures.csv, `blurcue export`).
PROCEDURE_KEYS = {"staircase": ("start", "min", "max", "up", "down", "steps"),
                  "quest_plus": ("stimuli", "thresholds", "slopes", "lapses", "guess")}


def _with_procedures(df, path):
    """trials with procedure_parameters (JSON text, empty outside a procedure) joined from procedures.csv by study,
    protocol version and block; unchanged without the file (an export of before it). TrialsError naming the file, the
    row and the field for a file that cannot be used."""
    if not os.path.isfile(path):
        return df
    try:
        table = read_text_csv(path)
    except ValueError as e:
        raise TrialsError(f"{path}: {e}")
    missing = [c for c in ("study", "protocol_hash", "block", "parameters") if c not in table.columns]
    if missing:
        raise TrialsError(f"{path}: not a blurcue procedures.csv (missing column {', '.join(missing)})")
    by = {}
    for i, row in table.iterrows():
        where = f"{path}: row {i + 2} parameters"
        try:
            parameters = json.loads(row["parameters"])
        except ValueError:
            raise TrialsError(f"{where}: not JSON ({row['parameters'][:40]!r})")
        kind = parameters.get("procedure") if isinstance(parameters, dict) else None
        if kind not in PROCEDURE_KEYS:
            raise TrialsError(f"{where}: procedure must be one of {', '.join(PROCEDURE_KEYS)}, got {kind!r}")
        lacking = [k for k in PROCEDURE_KEYS[kind] if k not in parameters]
        if lacking:
            raise TrialsError(f"{where}: a {kind} needs {', '.join(lacking)}")
        by[(row["study"], row["protocol_hash"], row["block"])] = row["parameters"]
    df["procedure_parameters"] = [by.get(key, "") for key in zip(df["study"], df["protocol_hash"], df["block"])]
    return df


def aborted_rows(df):
    """The rows of aborted sessions (session_status, as `blurcue export` writes it; none in an export without it)."""
    if "session_status" not in df.columns:
        return df.iloc[0:0]
    return df[df["session_status"] == "aborted"]


def without_aborted(df):
    """trials without the rows of aborted sessions (closed with blurcue sessions --abort: given up, not data)."""
    if "session_status" not in df.columns:
        return df
    return df[df["session_status"] != "aborted"].copy()


def unfinished_rows(df):
    """The rows of unfinished sessions (session_status running: stopped, killed, or still being written)."""
    if "session_status" not in df.columns:
        return df.iloc[0:0]
    return df[df["session_status"] == "running"]


def without_unfinished(df):
    """trials without the rows of unfinished sessions (their answers are a part of a session, not a session)."""
    if "session_status" not in df.columns:
        return df
    return df[df["session_status"] != "running"].copy()


def session_numbers(df):
    """Each row's session as the analysis counts it: 1 + how many sessions of the study its participant completed
    before it (in the order started). A participant's --again session after a completed one is 2; a session after an
    aborted (given up) one is still a first session. From session_number and session_status (1 for every row of an
    export from before them; session_number alone without session_status)."""
    if "session_number" not in df.columns:
        return pd.Series(1, index=df.index)
    number = pd.to_numeric(df["session_number"], errors="coerce").fillna(1).astype(int)
    if "session_status" not in df.columns:
        return number
    s = pd.DataFrame({"study": df["study"], "participant": df["participant"], "session_id": df["session_id"],
                      "n": number, "done": (df["session_status"] == "completed").astype(int)})
    s = s.drop_duplicates("session_id")
    rank = {}
    for _, g in s.groupby(["study", "participant"]):
        for sid, n in zip(g["session_id"], g["n"]):
            rank[sid] = 1 + int(g.loc[g["n"] < n, "done"].sum())  # completed sessions started before this one
    return df["session_id"].map(rank).astype(int)


def session_words(df):
    """Each row's session said as what it is, for a label beside a participant: "aborted session", "unfinished
    session", "first session" or "repeated session N" (session_numbers: a session after an aborted one is still a
    first session), with the record's session id ("first session, id 2": what blurcue sessions lists)."""
    numbers = session_numbers(df)
    status = df["session_status"].astype(str) if "session_status" in df.columns else pd.Series("", index=df.index)
    kind = np.where(status == "aborted", "aborted session", np.where(
        status == "running", "unfinished session", np.where(numbers > 1, "repeated session " + numbers.astype(str),
                                                            "first session")))
    return pd.Series(kind, index=df.index) + ", id " + df["session_id"].astype(str)


def protocol_versions(df):
    """Each row's protocol version as text ("" in an export from before versions were recorded). A version that a
    merge brought with two texts (two stations ran one version number with different protocols; run refuses that in
    one record, merge warns) is two versions here, each named by its text's hash: "1 (text 5c3e4c56)"."""
    if "protocol_version" not in df.columns:
        return pd.Series("", index=df.index)
    versions = text(df["protocol_version"])
    if "protocol_hash" in df.columns and len(df):
        hashes = df["protocol_hash"].astype(str).str.strip()
        key = (df["study"].astype(str) + "\x00" if "study" in df.columns else "") + versions
        texts = hashes.groupby(key).transform("nunique")
        versions = versions.where(texts <= 1, versions + " (text " + hashes.str[:8] + ")")
    return versions


def study_parts(rows):
    """A study's rows split where they must not be pooled: by protocol version (where the study has more than one)
    and by session number (a participant's first sessions apart from their second, third, ...). Returns
    [(label, rows)] in order, label "" for the only part of a study with one version and first sessions only, else
    e.g. "version 2", "session 2", "version 2, session 3"."""
    versions, numbers = protocol_versions(rows), session_numbers(rows)
    several = versions.nunique() > 1
    out = []
    for version in sorted(versions.unique(), key=lambda v: (len(v), v)):
        for number in sorted(numbers[versions == version].unique()):
            part = rows[(versions == version) & (numbers == number)]
            label = ", ".join(([f"version {version}"] if several else []) +
                              ([f"session {number}"] if number > 1 else []))
            out.append((label, part))
    return out


def main_rows(df):
    """The rows the thesis's views and the observed-vs-model step read: every study's first sessions of its latest
    protocol version (the rest is analysed apart, part by part, study_parts)."""
    if df.empty:
        return df
    keep = session_numbers(df) == 1
    versions = protocol_versions(df)
    for study, d in df.groupby("study"):
        v = versions[d.index]
        if v.nunique() > 1:
            latest = max(v.unique(), key=lambda x: (len(x), x))
            keep[d.index] &= v == latest
    return df[keep].copy()


def study_rows(df, study):
    """The study's non-practice rows (practice == 1 is excluded from every analysis)."""
    d = df[(df["study"] == study) & (df["practice"] != 1)]
    return d.copy()


def forced_choice(df):
    """Adds chosen_source (the left/right column named by choice, or 'cant_tell') and decisive (left/right answer).

    Answers other than left / right / cant_tell are treated as unanswered (and counted in 'invalid').
    """
    d = df.copy()
    choice = d["choice"].str.strip()
    d["chosen_source"] = np.where(choice == "left", d["left"],
                                  np.where(choice == "right", d["right"],
                                           np.where(choice == "cant_tell", "cant_tell", None)))
    d["invalid"] = d["answered"] & ~choice.isin(["left", "right", "cant_tell"])
    d["answered"] = d["answered"] & ~d["invalid"]
    d["decisive"] = choice.isin(["left", "right"])
    return d


def participants_note(d):
    n = d["participant"].nunique()
    return f"{n} participant{'s' if n != 1 else ''}"


# --------------------------------------------------------------------------------------------------------------------
# Drawing


def setup_style():
    """Paper style: readable fonts, light grid, no top/right spines; SVG text stays text (searchable, editable)."""
    plt.rcParams.update({
        "figure.dpi": 110, "savefig.dpi": 150, "font.size": 10.5, "axes.titlesize": 11.5, "axes.labelsize": 10.5,
        "legend.fontsize": 9, "xtick.labelsize": 9.5, "ytick.labelsize": 9.5, "axes.spines.top": False,
        "axes.spines.right": False, "axes.grid": True, "grid.alpha": 0.3, "grid.linewidth": 0.6,
        "legend.frameon": False, "svg.fonttype": "none", "errorbar.capsize": 2.5,
    })


_STEM_PLAIN = frozenset(b"abcdefghijklmnopqrstuvwxyz0123456789-_.")
_STEM_KEPT = _STEM_PLAIN | frozenset(b"ABCDEFGHIJKLMNOPQRSTUVWXYZ")
_HEX = frozenset(b"0123456789abcdef")


def fnv1a64_hex(data):
    """FNV-1a 64 of DATA (bytes) as 16 lower-case hex digits: the project's hash of texts (src/core/hash.h)."""
    h = 0xcbf29ce484222325
    for byte in data:
        h = ((h ^ byte) * 0x100000001b3) & 0xFFFFFFFFFFFFFFFF
    return "%016x" % h


def file_stem(name, max_bytes=100):
    """A NAME of the record or a chart (a study's, a factor's, a group's) as a file name's stem: the one rule the
    report and blurcue export make file names by (src/store/export.h FileStem, its twin; tests/data/file_stems.csv
    pins both). NAME itself when it is 1 to MAX_BYTES bytes of lower-case ASCII letters, digits, '-', '_' and '.', not
    starting with '.' and not itself ending in '-' and 16 hex digits; otherwise SAFE-HASH: SAFE the name's UTF-8 bytes
    with every other byte (and a leading '.') written '_', cut to MAX_BYTES - 17 bytes, HASH the 16 hex digits of
    FNV-1a 64 of the name's exact bytes. So a stem fits every file system (72 CJK characters are 216 bytes), and two
    names differing anywhere ("pilot 1" and "pilot/1", a zero-width space, case only) are two files. A factor named a/b
    used to be a folder in the file name (exit 10), and two studies "pilot 1" and "pilot/1" shared their charts. The
    page shows NAME itself. A shorter MAX_BYTES (a study's part of a chart's name) keeps room for what follows."""
    name = str(name)
    raw = name.encode("utf-8", "surrogatepass")
    safe = bytearray(c if c in _STEM_KEPT else 0x5F for c in raw)
    if safe[:1] == b".":
        safe[0] = 0x5F  # neither hidden nor "." nor ".."
    looks_hashed = len(raw) > 17 and raw[-17] == 0x2D and all(c in _HEX for c in raw[-16:])
    if raw and len(raw) <= max_bytes and raw[:1] != b"." and not looks_hashed and all(c in _STEM_PLAIN for c in raw):
        return name
    return safe[:max_bytes - 17].decode("ascii") + "-" + fnv1a64_hex(raw)


@contextlib.contextmanager
def writing(path):
    """Names PATH in an OSError raised while it is written: a full disk fails a file's write or close with no file
    name (a real 2 MiB tmpfs gave "report: cannot write (No space left on device)", naming nothing)."""
    try:
        yield
    except OSError as e:
        if e.filename:
            raise
        raise OSError(e.errno, e.strerror or str(e), path) from e


def chart_stem(name):
    """A chart's file stem: NAME as it is when it is already one (1-100 bytes of file_stem's plain characters: a name
    composed of stems and this code's own words), else file_stem(NAME). A composed name's parts were stemmed where
    they were made (a study's, a cell's), so it is not hashed a second time for the hash one of them carries."""
    raw = str(name).encode("utf-8", "surrogatepass")
    if raw and len(raw) <= 100 and raw[:1] != b"." and all(c in _STEM_PLAIN for c in raw):
        return str(name)
    return file_stem(name)


def distinct_stems(names, max_bytes=48):
    """{name: stem} for names that share a folder (a study's cells): each name's plain form (lower case, any other
    byte '_') where no other name has the same one, file_stem(name) - with its hash - where two would meet ("edge=3"
    and "edge_3")."""
    plain = {n: re.sub(r"[^a-z0-9_.-]", "_", str(n).lower())[:max_bytes] or "_" for n in names}
    taken = {}
    for p in plain.values():
        taken[p] = taken.get(p, 0) + 1
    return {n: p if taken[p] == 1 and not p.startswith(".") else file_stem(n, max_bytes) for n, p in plain.items()}


def save(fig, out_dir, name):
    """Writes chart_stem(NAME).png and .svg into out_dir; returns their paths and closes the figure."""
    os.makedirs(out_dir, exist_ok=True)
    png = os.path.join(out_dir, chart_stem(name) + ".png")
    svg = os.path.join(out_dir, chart_stem(name) + ".svg")
    try:
        # The tight box once for both files (bbox_inches="tight" draws the figure again for each file to find it).
        fig.draw_without_rendering()
        bbox = fig.get_tightbbox(fig.canvas.get_renderer()).padded(plt.rcParams["savefig.pad_inches"])
        for path in (png, svg):
            with writing(path):
                fig.savefig(path, bbox_inches=bbox)
    finally:
        plt.close(fig)
    return png, svg


def chart_command(argv, default_csv, command, columns, chart):
    """A bench chart's command line: `python3 X_chart.py [CSV [OUT_DIR]]` draws chart(table, out_dir) from the CSV
    `blurcue COMMAND` wrote (default default_csv); exit 3 with one line when it is missing or lacks a column."""
    path = argv[1] if len(argv) > 1 else default_csv
    out_dir = argv[2] if len(argv) > 2 else os.path.dirname(path) or "."
    if not os.path.isfile(path):
        print(f"{path}: no such file (run blurcue {command})", file=sys.stderr)
        return 3
    df = pd.read_csv(path)
    missing = [c for c in columns if c not in df.columns]
    if missing:
        print(f"{path}: missing columns {', '.join(missing)}", file=sys.stderr)
        return 3
    png, _ = chart(df, out_dir)
    print(f"wrote {png}")
    return 0


def wilson_columns(table, k_col, n_col, prefix):
    """Adds PREFIX, PREFIX_low, PREFIX_high (Wilson 95 %) for k_col of n_col to a table, row by row."""
    values = [wilson(k, n) for k, n in zip(table[k_col], table[n_col])]
    table[prefix] = [v[0] for v in values]
    table[prefix + "_low"] = [v[1] for v in values]
    table[prefix + "_high"] = [v[2] for v in values]
    return table


def error_bars(p, lo, hi):
    """Asymmetric error-bar lengths for matplotlib from a proportion and its interval (NaN -> 0)."""
    p, lo, hi = (np.asarray(v, float) for v in (p, lo, hi))
    return np.clip(np.vstack([np.nan_to_num(p - lo), np.nan_to_num(hi - p)]), 0, None)  # rounding dust at 0 and 1


def p_text(p):
    if p is None or (isinstance(p, float) and math.isnan(p)):
        return ""
    return "p < 0.001" if p < 0.001 else f"p = {p:.3f}"


def stars(p):
    if p is None or (isinstance(p, float) and math.isnan(p)):
        return ""
    return "***" if p < 0.001 else "**" if p < 0.01 else "*" if p < 0.05 else ""


# --------------------------------------------------------------------------------------------------------------------
# Units and numbers as a reader checks them

# A procedure's variable (procedures.csv's "variable", protocol/vocabulary.h ProcedureVariable) and its level's unit.
LEVEL_UNITS = {"relative_difference": "ratio - 1", "difference_arcmin": "arcmin"}
# A design column's unit read off its name, as protocol::UnitOf gives the codebook (src/protocol/level.cc).
NAME_UNITS = (("_cm_s", "cm/s"), ("_mm", "mm"), ("_cm", "cm"), ("_ms", "ms"), ("_px", "px"), ("_arcmin", "arcmin"),
              ("_deg", "deg"), ("_m", "m"), ("_s", "s"))
# What a reader gets where nothing says the unit: said, never left out.
UNKNOWN_UNIT = "unit not recorded"


def _unit_words(unit):
    """A codebook's unit as an axis says it: the relative difference's long words cut to 'ratio - 1'."""
    unit = str(unit or "").strip()
    if unit.startswith("ratio - 1"):
        return LEVEL_UNITS["relative_difference"]
    return "" if unit.startswith("the procedure's variable") else unit


def _units_of_parameters(values):
    units = []
    for v in values:
        if isinstance(v, str):
            try:
                v = json.loads(v) if v.strip() else None
            except ValueError:
                v = None
        if isinstance(v, dict) and v.get("variable") in LEVEL_UNITS:
            unit = LEVEL_UNITS[v["variable"]]
            if unit not in units:
                units.append(unit)
    return units


def level_unit(source, column="level"):
    """The unit words of a procedure's level (column "level": "ratio - 1" for relative_difference, "arcmin" for
    difference_arcmin) or of another column of trials.csv, from whatever says it:
      a procedure's parameters (a dict, or its JSON text: procedures.csv's, with its "variable"),
      rows of trials.csv (a DataFrame with procedure_parameters, as common.load_trials joins them),
      a codebook: a DataFrame of codebook.csv, the path of codebook.csv or of the trials.csv beside it, or a
      {column: row} mapping whose row has a unit (an attribute or a key);
    for a column other than the level, its name's suffix (speed_cm_s: cm/s) where the source says nothing. Procedures
    of different variables give both ("ratio - 1 or arcmin"); nothing known gives "" (see axis_label)."""
    units = []
    if isinstance(source, str) and source.lstrip().startswith("{"):
        units = _units_of_parameters([source]) if column == "level" else []
    elif isinstance(source, dict) and column == "level" and "variable" in source:
        units = _units_of_parameters([source])
    elif isinstance(source, pd.DataFrame) and "procedure_parameters" in source and column == "level":
        units = _units_of_parameters(source["procedure_parameters"].dropna().unique())
    elif isinstance(source, pd.DataFrame) and {"column", "unit"} <= set(source.columns):
        rows = source[(source["column"] == column) & (source["table"] == "trials.csv" if "table" in source else True)]
        units = [u for u in (_unit_words(u) for u in rows["unit"]) if u]
    elif isinstance(source, str) and source.endswith(".csv") and os.path.isfile(source):
        path = source if os.path.basename(source) == "codebook.csv" else \
            os.path.join(os.path.dirname(os.path.abspath(source)), "codebook.csv")
        return level_unit(read_text_csv(path), column) if os.path.isfile(path) else level_unit(None, column)
    elif isinstance(source, dict) and column in source:
        row = source[column]
        unit = getattr(row, "unit", None) if not isinstance(row, dict) else row.get("unit")
        units = [u for u in [_unit_words(unit)] if u]
    if not units and column != "level":
        units = [u for suffix, u in NAME_UNITS if column.endswith(suffix) and len(column) > len(suffix)][:1]
    return " or ".join(dict.fromkeys(units))


def axis_label(what, unit):
    """'level shown (ratio - 1)': a quantity with its unit in brackets; without a known unit it says so."""
    return f"{what} ({unit or UNKNOWN_UNIT})"


# A side's source written as a level of the design ("object=4", "left=measured;right=3"): a number is a radius in photo
# px (protocols/README.md: a side's fixed radius), written with its unit.
_SIDE_NUMBER = re.compile(r"(?<![A-Za-z0-9_])(object|left|right)=([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)(?=;|$)")


def level_text(value):
    """A level as a reader checks it: a number at the precision the protocol gave it (0.2, never the binary sum
    0.19999999999999996 an older export wrote; 3.0 as 3), a side's radius with its unit ("object=4 photo px"), a level
    a row does not have (NaN) blank."""
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return ""
    if isinstance(value, (int, np.integer)) and not isinstance(value, bool):
        return str(int(value))
    if isinstance(value, (float, np.floating)):
        return f"{float(value):.12g}"
    words = str(value).strip()
    if re.fullmatch(r"[-+]?\d+", words):
        return words  # an integer as written (an id's digits are never rounded)
    if re.fullmatch(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?", words):
        return f"{float(words):.12g}"
    return _SIDE_NUMBER.sub(lambda m: f"{m.group(1)}={float(m.group(2)):.12g} photo px", words)


def factor_label(name, codebook=None):
    """A factor as an axis names it: with its unit where the codebook or its name gives one ("speed_cm_s (cm/s)"),
    bare where it has none (an edge's number, a source's name)."""
    unit = level_unit(codebook, name) if codebook is not None else level_unit(None, name)
    if not unit and name != "level":
        unit = level_unit(None, name)
    return f"{name} ({unit})" if unit else str(name)
