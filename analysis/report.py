#!/usr/bin/python3
"""Every chart and table of a blurcue run, and an index.html that shows them.

  /usr/bin/python3 analysis/report.py --trials DIR/trials.csv [--bench results/bench] --out DIR [--boot 200]
                                      [--db RECORD.sqlite]   (the record: a video study's scene is described)

Writes DIR/<chart>.png, DIR/<chart>.svg, DIR/<table>.csv and DIR/index.html (self-contained, relative links).
Display timing reads frames.csv from trials.csv's folder (written there by `blurcue export`; missing = skipped).
One progress line per step on stderr. A section that the data cannot support (a study nobody ran, no answers, no
bench files) is skipped with a one-line message and a note in index.html. Aborted and unfinished sessions are left out
(--include-aborted, --include-unfinished take them in); repeated sessions and protocol versions get sections of their
own; the summary says what was left out or kept apart.
Exit codes: 0 report written; 2 usage; 3 trials.csv missing or unreadable, or the output folder cannot be written;
10 a section failed unexpectedly (the rest of the report is still written, and the failure is named).
"""
import argparse
import datetime
import errno
import html
import math
import os
import sys
import warnings

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))  # the sibling modules, from any working directory


import numpy as np  # noqa: E402

import any_study  # noqa: E402
import bench_charts  # noqa: E402
import prediction  # noqa: E402
import scenes  # noqa: E402
import common  # noqa: E402
import depth_matching  # noqa: E402
import forced_choice  # noqa: E402
import frame_timing  # noqa: E402
from common import Skip, TrialsError, chart_stem  # noqa: E402
from design import load_codebook  # noqa: E402

EXIT_INPUT = 3
EXIT_INTERNAL = 10


def say(message):
    print(f"report: {message}", file=sys.stderr, flush=True)


def _warning_line(message, category, filename, lineno, file=None, line=None):
    """Library warnings (a fit that did not converge, ...) as one prefixed line, not a two-line source dump."""
    say(f"warning: {category.__name__}: {str(message).splitlines()[0] if str(message) else ''} "
        f"({os.path.basename(filename)}:{lineno})")


def _fmt(value):
    """Table cells in HTML: 4 significant digits for floats, blanks for NaN and for no value (None)."""
    if value is None:
        return ""
    if isinstance(value, float):
        if math.isnan(value):
            return ""
        return f"{value:.4g}"
    return str(value)


# A text cell longer than this is written once under the table and marked in its cells: a test's description repeated
# in every row made each row ten lines tall and pushed the p columns off a 1280 px page (a first-time reader's
# finding). The CSV keeps every cell whole.
LONG_CELL = 48


def _table_html(table):
    if table is None or table.empty:
        return ""
    # No value in an object column is None, which pandas writes as "None" whatever na_rep says: NaN, written blank.
    table = table.where(table.notna(), np.nan)
    marks = {}  # long text -> its mark, in order of first appearance

    def mark(value):
        if not isinstance(value, str) or len(value) <= LONG_CELL:
            return value
        return "(" + marks.setdefault(value, _footnote_mark(len(marks))) + ")"

    table = table.copy()
    for column in table.columns:
        if table[column].dtype == object:
            table[column] = table[column].map(mark)
    body = table.to_html(index=False, na_rep="", formatters={c: _fmt for c in table.columns}, border=0,
                         classes="data")
    if marks:
        body += "<ul class='notes'>" + "".join(f"<li>({m}) {html.escape(text)}</li>" for text, m in marks.items()) + \
            "</ul>"
    return body


def _footnote_mark(i):
    """a, b, ..., z, aa, ab, ...: the i-th long cell's mark."""
    return _footnote_mark(i // 26 - 1) + chr(ord("a") + i % 26) if i >= 26 else chr(ord("a") + i)


def write_index(out_dir, sections, header, name="index.html", title="blurcue analysis report", summary=None,
                links=None):
    """sections: list of (title, [Chart], [skip notes]); header: lines about the inputs; summary: (study, finding)
    pairs shown first; links: (href, text) to the report's other pages."""
    sections = [s for s in sections if s[1] or s[2]]  # a step with nothing to show (bench files read fine) is left out
    parts = ["<!DOCTYPE html>", "<html lang='en'><head><meta charset='utf-8'>",
             f"<title>{html.escape(title)}</title>",
             "<style>body{font-family:sans-serif;max-width:1250px;margin:2em auto;padding:0 1em;color:#222}"
             "h2{border-bottom:1px solid #ccc;padding-bottom:.2em;margin-top:2em}img{max-width:100%;height:auto}"
             "table.data{border-collapse:collapse;font-size:12px;margin:.6em 0}"
             "table.data td,table.data th{border:1px solid #ddd;padding:2px 6px;text-align:right}"
             "table.data th{background:#f3f3f3}.skip{background:#fff6d9;border-left:4px solid #e6b800;"
             "padding:.4em .8em;margin:.6em 0}.notes{font-size:13px;color:#444}.links{font-size:13px}"
             ".scroll{overflow-x:auto}</style></head><body>",
             f"<h1>{html.escape(title)}</h1>"]
    if links:
        parts.append("<p class='links'>" + " | ".join(f"<a href='{html.escape(h)}'>{html.escape(t)}</a>"
                                                      for h, t in links) + "</p>")
    if summary:
        parts.append("<h3>Summary</h3><table class='data'><tr><th>study</th><th>what it found</th></tr>")
        parts += [f"<tr><td style='text-align:left'>{html.escape(s)}</td><td style='text-align:left'>"
                  f"{html.escape(f)}</td></tr>" for s, f in summary]
        parts.append("</table>")
    parts.append("<ul class='notes'>")
    parts += [f"<li>{html.escape(line)}</li>" for line in header]
    parts.append("</ul><h3>Contents</h3><ol>")
    for i, (title, _, _) in enumerate(sections):
        parts.append(f"<li><a href='#s{i}'>{html.escape(title)}</a></li>")
    parts.append("</ol>")
    for i, (title, charts, skips) in enumerate(sections):
        parts.append(f"<h2 id='s{i}'>{html.escape(title)}</h2>")
        shown = {}  # a table's HTML -> the chart that showed it (one factor: its bars' table is the conditions')
        for s in skips:
            parts.append(f"<div class='skip'>Skipped: {html.escape(s)}</div>")
        # Headings without the study's part every chart of the section shares ("my-cards-simulated-"), the whole name
        # (its files') beside them in grey; a one-word share ("side-", "test2-") stays, the heading would lose sense.
        prefix = os.path.commonprefix([c.name for c in charts]) if len(charts) > 1 else ""
        prefix = prefix[:prefix.rfind("-") + 1]
        prefix = prefix if prefix.count("-") >= 2 else ""
        for c in charts:
            short = c.name[len(prefix):]
            parts.append(f"<h3>{html.escape(short)}" +
                         (f" <span class='notes'>({html.escape(c.name)})</span>" if short != c.name else "") +
                         "</h3>")
            links = []
            if c.png:
                png = os.path.basename(c.png)
                parts.append(f"<img src='{html.escape(png)}' alt='{html.escape(c.name)}'>")
                links.append(f"<a href='{html.escape(os.path.basename(c.svg))}'>SVG</a>")
            if c.table is not None and not c.table.empty:
                links.append(f"<a href='{html.escape(chart_stem(c.name))}.csv'>table as CSV</a>")
            if links:
                parts.append(f"<p class='links'>{' | '.join(links)}</p>")
            if c.notes:
                parts.append("<ul class='notes'>" + "".join(f"<li>{html.escape(n)}</li>" for n in c.notes) + "</ul>")
            table = _table_html(c.table)
            if table and table in shown:
                parts.append(f"<p class='notes'>its table is {html.escape(shown[table])}'s, above</p>")
            elif table:
                shown[table] = c.name
                parts.append(f"<div class='scroll'>{table}</div>")
    parts.append("</body></html>")
    path = os.path.join(out_dir, name)
    with common.writing(path), open(path, "w", encoding="utf-8") as f:
        f.write("\n".join(parts) + "\n")
    return path


def thesis_findings(trials, sections):
    """One line per thesis study for the summary: the depth matching's pooled slope of log cut-off on log distance
    (from its chart's table), and for the forced-choice tests how often measured was chosen over estimated where the
    two were shown side by side (Wilson 95 % interval of the answers; the test against 0.5 with participants as the
    unit, study_tests.against_chance)."""
    import stats
    import study_tests
    out = {}
    charts = {c.name: c for _, cs, _ in sections for c in cs}
    dm = charts.get("depth-matching")
    if dm is not None and dm.table is not None and not dm.table.empty and "term" in dm.table:
        t = dm.table
        # The match in arcmin where the record has it, and the thesis's power law (each: the lmer, else the OLS).
        found = []
        for label, term, text in (("set on real", depth_matching.WORDS_MATCH["real_arcmin"],
                                   "set blur against the real picture's blur (arcmin): slope"),
                                  ("power law", "b (per unit of log distance)", "accepted cut-off against "
                                   "distance: c ~ d^b with b")):
            rows = t[t["model"].astype(str).str.startswith(label + ":") & (t["term"] == term) &
                     ~t["model"].astype(str).str.contains("observer ") & t["estimate"].notna()]
            # A row with a test first (a mixed model's slope without its random slope has none), lme4 before OLS.
            rows = rows.assign(_order=rows["p"].isna() * 2 + ~rows["engine"].astype(str).str.startswith("lme4"))
            rows = rows.sort_values("_order", kind="stable")
            if len(rows):
                r = rows.iloc[0]
                half = stats.sps.t.ppf(0.975, r["df"]) * r["se"] if r["df"] > 0 else math.nan
                interval = f" [{r['estimate'] - half:.2f}, {r['estimate'] + half:.2f}]" if math.isfinite(half) else ""
                test = common.p_text(r["p"]) + "; " if math.isfinite(r["p"]) else ""
                if label == "set on real" and test:
                    # The match's slope: against 1 (set as real) first, against 0 beside it (the same fit's row).
                    zero = t[(t["model"] == r["model"]) & (t["term"] == depth_matching.MATCH_SLOPE_AGAINST_0)]
                    test = f"against 1 (set as real): {common.p_text(r['p'])}" + (
                        f"; against 0: {common.p_text(zero['p'].iloc[0])}" if len(zero) and
                        math.isfinite(zero["p"].iloc[0]) else "") + "; "
                found.append(f"{text} = {r['estimate']:.2f}{interval} ({test}{r['model']})")
        if found:
            out[common.STUDY_DEPTH] = "; ".join(found)
    for study in common.FORCED_CHOICE_STUDIES:
        d = common.study_rows(trials, study)
        if d.empty:
            continue
        d = common.forced_choice(d)
        pair = d[d["answered"] & d["decisive"] &
                 (((d["left"] == "measured") & (d["right"] == "estimated")) |
                  ((d["left"] == "estimated") & (d["right"] == "measured")))]
        cant = d[d["answered"]]
        # No answer (practice apart): no share of can't tell to give (it read "can't tell nan%").
        cant_text = (f"; can't tell {(cant['chosen_source'] == 'cant_tell').mean():.0%} of all answers" if len(cant)
                     else "; no answers")
        if len(pair):
            k, n = int((pair["chosen_source"] == "measured").sum()), len(pair)
            p, lo, hi = stats.wilson(k, n)
            # Answers of one participant are not independent: the test against 0.5 takes participants as the unit.
            test = study_tests.against_chance(pair.assign(y=(pair["chosen_source"] == "measured").astype(float)), 0.5)
            people = pair["participant"].nunique()
            out[study] = (f"measured chosen over estimated {p:.2f} [{lo:.2f}, {hi:.2f}] of {n} decisive answers from "
                          f"{people} participant{'s' if people != 1 else ''}; against 0.5: {test['test']}"
                          + (f", {common.p_text(test['p'])}" if not math.isnan(test["p"]) else "") + cant_text)
        else:
            out[study] = "no measured-vs-estimated pairs answered" + cant_text
    return out


def aborted_sessions(trials, included):
    """(study, line) per study holding aborted sessions: how many sessions and answers (practice apart) the report
    leaves out, or with `included` analyses, and why. Empty for a trials.csv without session_status (an export from
    before it): nothing is known to be aborted there."""
    aborted = common.aborted_rows(trials)
    out = []
    for study, d in aborted.groupby("study", sort=True):
        sessions = d.drop_duplicates("session_id")
        who = ", ".join(f"{p} (session id {s})" for p, s in zip(sessions["participant"], sessions["session_id"]))
        n, answers = len(sessions), int((d["answered"] & (d["practice"] != 1)).sum())
        what = f"{n} aborted session{'s' if n != 1 else ''} ({who}) with {answers} answer{'s' if answers != 1 else ''}"
        if included:
            out.append((study, f"included {what} (--include-aborted): sessions closed with blurcue sessions --abort"))
        else:
            out.append((study, f"left out {what}: closed with blurcue sessions --abort, they are not part of the "
                               f"study; blurcue report --include-aborted analyses them"))
    return out


def unfinished_sessions(trials, included):
    """(study, line) per study holding unfinished sessions (session_status running: stopped, killed, or still being
    written): how many sessions and answers the report leaves out, or with `included` analyses as partial data."""
    out = []
    for study, d in common.unfinished_rows(trials).groupby("study", sort=True):
        sessions = d.drop_duplicates("session_id")
        who = ", ".join(f"{p} (session id {s})" for p, s in zip(sessions["participant"], sessions["session_id"]))
        n, answers = len(sessions), int((d["answered"] & (d["practice"] != 1)).sum())
        what = (f"{n} unfinished session{'s' if n != 1 else ''} ({who}) with {answers} "
                f"answer{'s' if answers != 1 else ''}")
        if included:
            out.append((study, f"included {what} as partial data (--include-unfinished): stopped, killed or still "
                               f"running, each is a part of a session"))
        elif answers == 0:  # nothing that --include-unfinished could analyse
            out.append((study, f"left out {what} (of {len(d)} trials): stopped, killed or still running before any "
                               f"answer"))
        else:
            out.append((study, f"left out {what}: stopped, killed or still running, a part of a session is not a "
                               f"participant's data; blurcue report --include-unfinished analyses them as partial data"))
    return out


def nothing_to_analyse(trials, n_read, path):
    """One line where the rows to analyse hold no answer at all (the report is written, with nothing in it to
    analyse, and exits 0 as for a study with no answers), else "". trials: the rows left after the sessions left
    out; n_read: the rows of the file at path."""
    if n_read == 0:
        return f"{path}: no trials - nothing to analyse, every trial section is skipped"
    if trials.empty:
        return (f"nothing to analyse: all {n_read} rows of {path} are of sessions left out (above); "
                "the report holds no result")
    if not trials["answered"].any():
        return f"nothing to analyse: none of the {len(trials)} trials analysed was answered; the report holds no result"
    return ""


def kept_apart(trials):
    """(study, line) per study whose record holds repeated sessions or several protocol versions: what is analysed
    apart, and where."""
    out = []
    for study, d in trials.groupby("study", sort=True):
        numbers = common.session_numbers(d)
        again = d[numbers > 1].drop_duplicates("session_id")
        if len(again):
            who = ", ".join(f"{p} (session number {n})" for p, n in zip(again["participant"], numbers[again.index]))
            out.append((study, f"{len(again)} repeated session{'s' if len(again) != 1 else ''} ({who}: after one the "
                               f"participant completed) analysed apart from first sessions: a section per session "
                               f"number ('session N'); the thesis's views and the observed-vs-model step use first "
                               f"sessions only"))
        versions = common.protocol_versions(d)
        if versions.nunique() > 1:
            listed = sorted(versions.unique(), key=lambda v: (len(v), v))
            out.append((study, f"protocol versions {', '.join(listed)} analysed apart: a section per version "
                               f"('version N'); the thesis's views and the observed-vs-model step use version "
                               f"{listed[-1]}, the latest"))
    return out


# What a full disk, a quota, a read-only file system or a folder taken away mid-report raise: exit 3 naming the file.
WRITE_ERRNOS = {errno.ENOSPC, errno.EDQUOT, errno.EROFS, errno.EACCES, errno.EIO}


def video_scenes(db, trials, frames_path):
    """(study, "scene: ...") for each study whose scene is a tracked video (scenes.py), from the record at db."""
    if not db:
        return []
    bases = [os.getcwd(), os.path.join(os.getcwd(), "protocols"), os.path.dirname(os.path.abspath(db))]
    try:
        lines = scenes.video_scene_lines(db, trials, frames_path, bases)
    except Exception as e:  # noqa: BLE001 - a record this code cannot read: say so, keep the report
        say(f"{db}: the studies' scenes are not described ({type(e).__name__}: {e})")
        return []
    for study, line in lines:
        say(f"scene of {study}: {line}")
    return [(study, "scene: " + line) for study, line in lines]


def main(argv=None):
    try:
        return _main(argv)
    except OSError as e:
        if e.errno not in WRITE_ERRNOS:
            raise
        where = f"{e.filename}: " if e.filename else ""
        print(f"report: {where}cannot write ({e.strerror or e}); nothing was written in its place", file=sys.stderr)
        return EXIT_INPUT


def _main(argv=None):
    parser = argparse.ArgumentParser(description="Charts, tables and index.html from trials.csv and bench CSVs.")
    parser.add_argument("--trials", required=True, help="trials.csv written by `blurcue export`")
    parser.add_argument("--bench",
                        help="folder with measure.csv, render.csv and procedures.csv (default results/bench, when "
                        "it exists: a study's report has no benchmark page unless there are benchmarks)")
    parser.add_argument("--out", required=True, help="output folder")
    parser.add_argument("--final-out", help="where --out is renamed to once complete (blurcue report builds the "
                        "folder beside its target): index.html and messages name paths there")
    parser.add_argument("--db", help="the SQLite record trials.csv was exported from (blurcue report gives it): its "
                        "protocols say what each study's scene was (a video's take, frames and exposure)")
    parser.add_argument("--boot", type=int, default=200, help="bootstrap samples of each psychometric fit (its band and its "
                        "threshold's interval come from the same samples)")
    parser.add_argument("--seed", type=int, default=1, help="bootstrap seed")
    parser.add_argument("--debug", action="store_true", help="let an unexpected error raise (with its traceback)")
    parser.add_argument("--pool-simulated", action="store_true",
                        help="analyse people and simulated observers together (by default apart)")
    parser.add_argument("--include-aborted", action="store_true",
                        help="analyse the answers of aborted sessions too (by default they are left out, and the "
                             "summary says how many)")
    parser.add_argument("--include-unfinished", action="store_true",
                        help="analyse the answers of unfinished sessions (stopped, killed or still running) as partial "
                             "data (by default they are left out, and the summary says how many)")
    args = parser.parse_args(argv)
    warnings.showwarning = _warning_line

    def shown(path):
        """A path as the reader will find it: under --final-out when it lies under --out."""
        if not args.final_out:
            return path
        rel = os.path.relpath(os.path.abspath(path), os.path.abspath(args.out))
        if rel == os.curdir:
            return args.final_out
        return path if rel.startswith(os.pardir) else os.path.join(args.final_out, rel)

    def shown_text(text):
        """A message with every path under --out named as under --final-out."""
        if not args.final_out:
            return text
        text = text.replace(os.path.abspath(args.out), os.path.abspath(args.final_out))
        return text.replace(args.out, args.final_out)

    try:
        os.makedirs(args.out, exist_ok=True)
    except OSError as e:
        say(f"{args.out}: cannot create the output folder ({e.strerror})")
        return EXIT_INPUT
    common.setup_style()

    # The steps: (title shown in progress and index, function returning [Chart]). Data steps need trials.
    holder = {}
    bench = {}

    def load_bench():
        m, r, notes = bench_charts.load_bench(args.bench)
        bench.update(measure=m, render=r)
        if m is None and r is None:
            raise Skip("; ".join(notes) + " - bench charts skipped")
        for n in notes:
            say(f"{n} - its charts are skipped")
        bench["notes"] = notes
        return []

    def needs(key):
        if bench.get(key) is None:
            raise Skip(f"{os.path.join(args.bench, key + '.csv')}: not available")
        return bench[key]

    def procedures_csv():
        table, note = bench_charts.load_procedures(args.bench)
        if table is None:
            raise Skip(note + " - the procedures chart is skipped")
        return table

    df = lambda: holder["trials"]  # noqa: E731
    frames_path = os.path.join(os.path.dirname(args.trials), "frames.csv")  # written beside trials.csv by export
    steps = [
        ("pre-research depth matching (Fig. 3.3)", lambda: depth_matching.charts(df(), args.out)),
        ("test 1 per edge (Fig. 5.2)", lambda: forced_choice.test1_per_edge(df(), args.out)),
        ("test 2 per pattern (Fig. 5.9)", lambda: forced_choice.per_pattern(df(), args.out, common.STUDY_TEST2)),
        ("test 3 per pattern (Fig. 5.13)", lambda: forced_choice.per_pattern(df(), args.out, common.STUDY_TEST3)),
        ("test 2 per section, patterns 2, 4, 6 (Fig. 5.10-5.12)",
         lambda: forced_choice.per_section(df(), args.out, common.STUDY_TEST2)),
        ("test 3 per section, patterns 2, 4, 6", lambda: forced_choice.per_section(df(), args.out, common.STUDY_TEST3)),
        ("the more blurred one against the blur difference (tests 1-3 pooled)",
         lambda: forced_choice.psychometric(df(), args.out, n_boot=args.boot, seed=args.seed)),
        ("side bias (counterbalancing check)", lambda: forced_choice.side_bias(df(), args.out)),
        ("display timing", lambda: frame_timing.charts(frames_path, args.out)),
    ]
    bench_steps = [
        ("bench files", load_bench),
        ("bench: measurement speed vs accuracy",
         lambda: bench_charts.measure_speed_accuracy(needs("measure"), args.out)),
        ("bench: measurement stability", lambda: bench_charts.stability(needs("measure"), args.out)),
        ("bench: rendering speed vs accuracy", lambda: bench_charts.render_speed_accuracy(needs("render"), args.out)),
        ("bench: two-ball frame", lambda: bench_charts.render_frame(needs("render"), args.out)),
        ("bench: how a frame's cost grows", lambda: bench_charts.render_growth(needs("render"), args.out)),
        ("bench: which procedure", lambda: bench_charts.procedures(procedures_csv(), args.out)),
    ]
    try:
        holder["trials"] = common.load_trials(args.trials)
    except TrialsError as e:
        say(str(e))  # the only line: the file and what is wrong with it
        return EXIT_INPUT
    n_read = len(holder["trials"])  # the file's rows, before any session is left out
    # An aborted session was given up (sessions --abort): its answers are not the study's unless asked for.
    session_lines = aborted_sessions(holder["trials"], args.include_aborted)
    if not args.include_aborted:
        holder["trials"] = common.without_aborted(holder["trials"])
    # An unfinished session (running: stopped, killed, still being written) is a part of a session: not analysed
    # unless asked for, and then named as partial data.
    session_lines += unfinished_sessions(holder["trials"], args.include_unfinished)
    if not args.include_unfinished:
        holder["trials"] = common.without_unfinished(holder["trials"])
    # Repeated sessions and protocol versions are analysed apart: the thesis's views and the observed-vs-model step
    # read every study's first sessions of its latest version; every other part gets its own section below.
    all_trials = holder["trials"]
    session_lines += kept_apart(all_trials)
    holder["trials"] = common.main_rows(all_trials)
    trials = holder["trials"]
    codebook = load_codebook(args.trials)

    # Every other study, analysed from what its trials declare (any_study.py); people and simulated observers apart
    # unless --pool-simulated.
    known = set(common.STUDY_TITLES)
    findings = {}  # step title -> one line for the summary

    def study_step(study, rows, group, label):
        def run():
            charts, finding = any_study.analyse(rows, study, codebook, args.out, n_boot=args.boot, seed=args.seed,
                                                group=group, part=label)
            findings[title] = finding
            return charts
        title = f"study {study}" + (f" ({', '.join(filter(None, [label, group]))})" if label or group else "")
        return title, run

    study_steps = []
    for study in sorted(set(all_trials["study"])):
        for label, rows in common.study_parts(all_trials[all_trials["study"] == study]):
            if study in known and rows.index.isin(trials.index).all():
                continue  # a thesis study's first sessions of its latest version: the thesis's own views
            kinds = sorted(set(rows["observer"])) if not args.pool_simulated else ["all"]
            for kind in kinds:
                part = rows if kind == "all" else rows[rows["observer"] == kind]
                group = "" if kind == "all" or kinds == ["person"] else \
                    ("simulated observers" if kind == "simulated" else "people")
                study_steps.append(study_step(study, part, group, label))
    # The thesis's views of the thesis's studies that are in the record (none is a box saying it is missing).
    present = set(trials["study"])
    uses = [{common.STUDY_DEPTH}, {common.STUDY_TEST1}, {common.STUDY_TEST2}, {common.STUDY_TEST3},
            {common.STUDY_TEST2}, {common.STUDY_TEST3}, set(common.FORCED_CHOICE_STUDIES),
            set(common.FORCED_CHOICE_STUDIES)]
    thesis_steps = [step for step, studies in zip(steps[:8], uses) if studies & present]
    # Every study's answers beside the simulated observer's prediction for the same trials (prediction.py).
    predict_step = ("observed vs the observer model",
                    lambda: prediction.charts(df(), args.out, codebook, pool_simulated=args.pool_simulated))
    if args.bench is None:  # not asked for: the benchmark page only where `blurcue bench` wrote its folder
        args.bench = os.path.join("results", "bench")
        if not os.path.isdir(args.bench):
            bench_steps = []
    steps = thesis_steps + study_steps + [predict_step] + steps[8:] + bench_steps
    n_data_steps = len(steps) - len(bench_steps)
    total = len(steps) + 2  # + reading trials.csv + writing the index
    analysed = f" ({len(all_trials)} of them analysed)" if len(all_trials) != n_read else ""
    say(f"[1/{total}] read {shown(args.trials)}: {n_read} rows{analysed}")
    studies = all_trials["study"].value_counts().sort_index()
    known = set(common.STUDY_TITLES)
    n_people = all_trials["participant"].nunique()
    header = [f"trials: {os.path.abspath(shown(args.trials))} - {n_read} rows{analysed}, "
              f"{int(all_trials['answered'].sum())} answered, {n_people} participant{'' if n_people == 1 else 's'}",
              "studies: " + (", ".join(f"{s} ({n} rows)" for s, n in studies.items()) or "none"),
              f"frames: {os.path.abspath(shown(frames_path))}",
              f"bench: {os.path.abspath(args.bench)}" if bench_steps else "bench: none (blurcue bench writes them)",
              f"written {datetime.datetime.now().strftime('%Y-%m-%d %H:%M')}; practice trials excluded everywhere"]
    header[1:1] = [line for _, line in session_lines]
    for _, line in session_lines:
        say(line)
    observers = all_trials.groupby("observer")["participant"].nunique()
    header.insert(1, "participants: " + ", ".join(f"{n} {'people' if k == 'person' else 'simulated'}"
                                                    for k, n in observers.items()) +
                  ("; analysed apart" if len(observers) > 1 and not args.pool_simulated else ""))
    nothing = nothing_to_analyse(all_trials, n_read, shown(args.trials))
    if nothing:
        say(nothing)
        header.insert(0, nothing)

    sections = []
    failed = []
    for i, (title, run) in enumerate(steps, start=2):
        say(f"[{i}/{total}] {title} ...")
        charts, skips = [], []
        try:
            charts = run()
        except Skip as e:
            say(f"  skipped: {shown_text(str(e))}")
            skips.append(shown_text(str(e)))
            if title.startswith("study "):
                findings[title] = "not analysed: " + shown_text(str(e))
        except Exception as e:  # a bug or data this code did not foresee: name it, keep the rest of the report
            if args.debug or (isinstance(e, OSError) and e.errno in WRITE_ERRNOS):
                raise  # a full or read-only disk: no section can be written, said once by main
            message = str(e).strip().splitlines()[0] if str(e).strip() else ""
            say(f"  {title} failed: {type(e).__name__}: {message}")
            skips.append(f"failed unexpectedly: {type(e).__name__}: {message}")
            failed.append(title)
        if title == "bench files":
            skips += [n for n in bench.get("notes", [])]
        charts = [c._replace(notes=[shown_text(n) for n in c.notes]) if c.notes else c for c in charts]
        for c in charts:
            if c.table is not None and not c.table.empty:
                table = os.path.join(args.out, chart_stem(c.name) + ".csv")
                with common.writing(table):
                    c.table.to_csv(table, index=False)
        sections.append((title, charts, skips))

    say(f"[{total}/{total}] index.html ...")
    # The summary: what each study found (the thesis's studies point at their figures).
    summary = list(session_lines)
    thesis = thesis_findings(trials, sections)
    for study in sorted(set(trials["study"]) & known):
        d = trials[(trials["study"] == study) & (trials["practice"] != 1)]
        summary.append((study, f"{common.STUDY_TITLES[study]}: {int(d['answered'].sum())} of {len(d)} trials "
                               f"answered; " + thesis.get(study, "see its figures below")))
    summary += [(title[len("study "):], finding) for title, finding in findings.items()]
    summary += video_scenes(args.db, all_trials, frames_path)
    data_sections, bench_sections = sections[:n_data_steps], sections[n_data_steps:]
    if bench_steps:
        write_index(args.out, bench_sections, [f"bench: {os.path.abspath(args.bench)}"], name="bench.html",
                    title="blurcue software benchmarks", links=[("index.html", "the studies")])
    path = write_index(args.out, data_sections, header, summary=summary,
                       links=[("bench.html", "software benchmarks (speed against accuracy)")] if bench_steps else [])
    n_charts = sum(1 for _, charts, _ in sections for c in charts if c.png)
    n_skipped = sum(1 for _, _, skips in sections if skips)
    say(f"wrote {shown(path)}: {n_charts} charts, {n_skipped} section{'s' if n_skipped != 1 else ''} with notes")
    if failed:
        say(f"{len(failed)} section(s) failed unexpectedly: {', '.join(failed)}")
        return EXIT_INTERNAL
    return 0


if __name__ == "__main__":
    sys.exit(main())
