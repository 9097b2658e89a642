#!/usr/bin/env bash
# End-to-end tests of `blurcue run` on real SQLite files - what the design records and reports: procedures, groups, the codebook, practice, names.
# Usage: session_design_test.sh CASE BLURCUE DIR. DIR holds protocols/ (tests/copy_protocols.cmake) and the scene
# they show. Each case prints what it checked and exits non-zero on the first failure.
set -euo pipefail
CASE=$1 BC=$2 DIR=$3
source "$(dirname "$0")/session_lib.sh"

case $CASE in
adaptive)
  # Adaptive procedures decide each trial from the answers so far; stopped (QUEST+) or killed -9 (the staircase on
  # moving balls) and resumed, the session equals an uninterrupted one with the same seed: the same levels shown,
  # the same answers. A record whose level was tampered with is refused rather than continued from a wrong state.
  shown() {
    sql "$1" "SELECT t.trial_index, t.factors, r.choice, r.shown FROM trials t JOIN sessions s ON s.id = t.session_id
              JOIN participants p ON p.id = s.participant_id JOIN responses r ON r.trial_id = t.id
              WHERE p.code = '$2' ORDER BY t.trial_index"
  }
  $BC run "$P/quest-blur-difference.json" --participant A1 --db "$W/whole.sqlite" --observer sim --seed 4 > /dev/null 2>&1
  $BC run "$P/quest-blur-difference.json" --participant A1 --db "$W/parts.sqlite" --observer sim --seed 4 \
      --stop-after 13 2>/dev/null | grep -q "not finished" || fail "quest: stop-after did not leave the session open"
  $BC run "$P/quest-blur-difference.json" --participant A1 --db "$W/parts.sqlite" --observer sim --seed 4 --resume \
      2>/dev/null | grep -q "40 of 40" || fail "quest: resume did not complete"
  [ "$(shown "$W/whole.sqlite" A1)" = "$(shown "$W/parts.sqlite" A1)" ] || fail "quest: resumed differs"
  levels=$(sql "$W/parts.sqlite" "SELECT count(DISTINCT json_extract(shown, '$.level')) FROM responses")
  [ "$levels" -ge 3 ] || fail "quest showed only $levels levels"
  $BC run "$P/staircase-ball-gain.json" --participant A2 --db "$W/whole.sqlite" --observer sim --seed 6 --sim-fps 2 \
      > /dev/null 2>&1
  $BC run "$P/staircase-ball-gain.json" --participant A2 --db "$W/killed.sqlite" --observer sim --seed 6 --sim-fps 2 \
      > "$W/out" 2>&1 &
  pid=$!
  wait_for_answers "$W/killed.sqlite" 9
  kill -9 $pid; wait $pid 2>/dev/null || true
  answered=$(sql "$W/killed.sqlite" "SELECT count(*) FROM responses")
  [ "$answered" -ge 9 ] && [ "$answered" -lt 60 ] || fail "killed after $answered answers, expected mid-session"
  $BC run "$P/staircase-ball-gain.json" --participant A2 --db "$W/killed.sqlite" --observer sim --seed 6 --sim-fps 2 \
      --resume 2>/dev/null | grep -q "60 of 60" || fail "staircase: resume did not complete"
  [ "$(shown "$W/whole.sqlite" A2)" = "$(shown "$W/killed.sqlite" A2)" ] || fail "staircase: killed+resumed differs"
  # The staircases stop at their 6th reversal (stop rule): every later trial of that staircase is recorded as
  # skipped, not shown - the same ones in the killed and resumed session.
  $PY - "$W/killed.sqlite" <<'PYEOF' || fail "staircase stop rule"
import json, sqlite3, sys
con = sqlite3.connect(sys.argv[1])
rows = con.execute("SELECT t.trial_index, r.choice, r.shown FROM trials t JOIN responses r ON r.trial_id = t.id "
                   "ORDER BY t.trial_index").fetchall()
cells, skipped = {}, 0
for index, choice, shown in rows:
    shown = json.loads(shown)
    cell = cells.setdefault(json.loads(con.execute("SELECT factors FROM trials WHERE trial_index = ?",
                                                   (index,)).fetchone()[0]).get("speed_cm_s"), [])
    cell.append((choice, shown))
for speed, trials in cells.items():
    first = next((i for i, (c, _) in enumerate(trials) if c == "skipped"), None)
    if first is None:
        continue
    assert all(c == "skipped" for c, _ in trials[first:]), speed
    assert all(s["reversals"] == 6 for _, s in trials[first:]), (speed, trials[first])
    assert trials[first - 1][1]["reversals"] in (5, 6), trials[first - 1]
    skipped += len(trials) - first
assert skipped > 0, "no staircase reached its stop rule"
print(skipped, "trials skipped")
PYEOF
  integrity "$W/killed.sqlite"
  # Tampered: a recorded level that the answers before it do not give.
  $BC run "$P/quest-blur-difference.json" --participant A3 --db "$W/tampered.sqlite" --observer sim --seed 4 \
      --stop-after 5 > /dev/null 2>&1
  $PY - "$W/tampered.sqlite" <<'PYEOF'
import sqlite3, sys
con = sqlite3.connect(sys.argv[1])
con.execute("UPDATE responses SET shown = json_set(shown, '$.level', 99) WHERE id = 3")
con.commit()
PYEOF
  set +e
  $BC run "$P/quest-blur-difference.json" --participant A3 --db "$W/tampered.sqlite" --observer sim --seed 4 --resume \
      > /dev/null 2> "$W/err"
  code=$?
  set -e
  [ $code = 3 ] && grep -q "trial 2: the record's procedure level 99" "$W/err" || fail "tampered: exit $code: $(cat "$W/err")"
  echo "ok: QUEST+ stopped and the staircase killed -9 after $answered answers resumed identical to uninterrupted runs" ;;
groups_info)
  # Between-subject groups in balance over the record, participant information recorded and exported, refused
  # when wrong or missing (no terminal to ask in), kept by a resumed session and by merge.
  G="$P/groups-and-info.json"
  info=(--info age=30 --info handedness=right --info vision=normal)
  for id in G1 G2 G3 G4; do $BC run "$G" --participant $id --db "$W/g.sqlite" --observer sim "${info[@]}" > /dev/null 2>&1; done
  $BC run "$G" --participant G5 --db "$W/g.sqlite" --observer sim "${info[@]}" --info notes="glasses, fine" \
      --stop-after 3 > /dev/null 2>&1
  set +e
  $BC run "$G" --participant G5 --db "$W/g.sqlite" --observer sim --resume --info age=31 > /dev/null 2> "$W/err1"
  c1=$?
  $BC run "$G" --participant G6 --db "$W/g.sqlite" --observer sim --info age=30 < /dev/null > /dev/null 2> "$W/err2"
  c2=$?
  $BC run "$G" --participant G6 --db "$W/g.sqlite" --observer sim "${info[@]}" --info shoe=42 > /dev/null 2> "$W/err3"
  c3=$?
  $BC run "$G" --participant G6 --db "$W/g.sqlite" --observer sim --info age=12 --info handedness=right \
      --info vision=normal > /dev/null 2> "$W/err4"
  c4=$?
  set -e
  [ $c1 = 3 ] && grep -q "info age: the unfinished session recorded 30, got 31" "$W/err1" || fail "changed info on resume: $c1 $(cat "$W/err1")"
  [ $c2 = 2 ] && grep -q "asks for handedness (left / right / both); give --info handedness=VALUE" "$W/err2" || fail "missing info: $c2 $(cat "$W/err2")"
  [ $c3 = 2 ] && grep -q "asks for age, handedness, vision, notes (participant_info), not shoe" "$W/err3" || fail "unknown info: $c3 $(cat "$W/err3")"
  [ $c4 = 2 ] && grep -q "info age=12: must be a whole number in \[16, 99\]" "$W/err4" || fail "bad info: $c4 $(cat "$W/err4")"
  $BC run "$G" --participant G5 --db "$W/g.sqlite" --observer sim --resume > /dev/null 2>&1 || fail "resume with the recorded info"
  # sessions names each session's group and observer.
  $BC sessions --db "$W/g.sqlite" > "$W/sessions"
  grep -Eq "groups-and-info +1 +G1 +1 +estimated +simulated +completed +12/12 +0 +0 " "$W/sessions" \
    && grep -Eq "groups-and-info +1 +G2 +1 +no_blur +simulated +completed +12/12 +0 +0 " "$W/sessions" \
    || fail "sessions: $(cat "$W/sessions")"
  $BC export --db "$W/g.sqlite" --out "$W/tables" > /dev/null
  $PY - "$W/tables/trials.csv" <<'PYEOF' || fail "groups and info in trials.csv"
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
group = {}
for r in rows:
    group.setdefault(r["participant"], set()).add((r["group"], r["block_name"]))
    assert r["info_age"] and r["info_handedness"] == "right" and r["info_vision"] == "normal", r
assert {p: len(g) for p, g in group.items()} == {f"G{i}": 1 for i in range(1, 6)}, group
names = [next(iter(group[f"G{i}"]))[0] for i in range(1, 6)]
assert names == ["estimated", "no_blur", "estimated", "no_blur", "estimated"], names  # balanced, in turn
assert all((g == "estimated") == (b == "measured-vs-estimated") for p in group for g, b in group[p]), group
assert {r["info_notes"] for r in rows if r["participant"] == "G5"} == {"glasses, fine"}
print("groups", names)
PYEOF
  $BC merge "$W/g.sqlite" --out "$W/merged.sqlite" > /dev/null
  $BC export --db "$W/merged.sqlite" --out "$W/merged-tables" > /dev/null
  cmp "$W/tables/trials.csv" "$W/merged-tables/trials.csv" || fail "merge lost groups or info"
  echo "ok: groups balanced over the record, participant information checked, recorded, kept on resume and merge" ;;
codebook)
  # Every exported table, read with pandas by the types of the export's own codebook: every column is in it, every
  # value reads back as what was written, every seed (most are above 2^53) is the record's digit for digit.
  for p in test1-static-grids quest-blur-difference odd-one-out-grids yes-no-ball pre-research-depth-matching; do
    $BC run "$P/$p.json" --participant C1 --db "$W/c.sqlite" --observer sim > /dev/null 2>&1 || fail "$p did not run"
  done
  $BC run "$P/groups-and-info.json" --participant C2 --db "$W/c.sqlite" --observer sim --info age=33 \
      --info handedness=left --info vision=normal --info "notes=reads, with glasses" > /dev/null 2>&1 || fail "groups"
  $BC export --db "$W/c.sqlite" --out "$W/tables" > /dev/null
  $PY "$(dirname "$0")/codebook_check.py" "$W/tables" "$W/c.sqlite" > "$W/out" || fail "$(cat "$W/out")"
  grep -q "adjustments.csv" "$W/tables/codebook.csv" || fail "adjustments.csv not in the codebook"
  # "Which fits the scene better?" has no correct answer: test 1's rows leave correct empty; QUEST+'s fill it.
  $PY - "$W/tables/trials.csv" <<'PYEOF' || fail "correct where nothing is correct"
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
assert all(r["correct"] == "" for r in rows if r["study"] == "test1-static-grids"), "test 1 scored"
assert all(r["correct"] in ("0", "1") for r in rows if r["study"] == "quest-blur-difference" and r["status"] == "answered")
PYEOF
  echo "ok: $(tail -1 "$W/out" | sed 's/^ok: //'); $(grep seeds "$W/out" | head -1)" ;;
report_aborted)
  # A participant's first session given up (sessions --abort) and a new one with the same seed, so the same first
  # trials: the report leaves the aborted answers out and its summary says how many (they used to be counted with
  # the new session's); --include-aborted counts them and says so. A record holding only an aborted session is not
  # analysed as if it were the study's: its report says "aborted".
  $BC run "$P/test1-static-grids.json" --participant P1 --db "$W/s.sqlite" --observer sim --stop-after 8 > /dev/null 2>&1
  $BC sessions --db "$W/s.sqlite" --abort 1 | grep -q "session 1 closed as aborted" || fail "abort"
  $BC run "$P/test1-static-grids.json" --participant P1 --db "$W/s.sqlite" --observer sim > /dev/null 2>&1 || fail "P1 again"
  $BC run "$P/test1-static-grids.json" --participant P2 --db "$W/s.sqlite" --observer sim > /dev/null 2>&1 || fail "P2"
  # From the export, apart from the report: the aborted session's answers and the decisive measured-vs-estimated
  # answers with and without it.
  counts() {
    $PY - "$1" <<'PYEOF'
import csv, sys
rows = [r for r in csv.DictReader(open(sys.argv[1], encoding="utf-8")) if r["practice"] == "0"]
aborted = [r for r in rows if r["session_status"] == "aborted"]
def decisive(rows):
    return sum(1 for r in rows if r["chosen_side"] in ("left", "right")
               and {r["left_source"], r["right_source"]} == {"measured", "estimated"})
print(sum(r["status"] == "answered" for r in aborted), decisive([r for r in rows if r not in aborted]), decisive(rows))
PYEOF
  }
  MPLCONFIGDIR=$W/mpl $BC report --db "$W/s.sqlite" --out "$W/report" --bench "$W/no-bench" --boot 20 > /dev/null 2> "$W/err" \
    || fail "report: $(tail -3 "$W/err")"
  read -r answers kept all <<< "$(counts "$W/report/tables/trials.csv")"
  [ "$answers" -gt 0 ] && [ "$all" -gt "$kept" ] || fail "the aborted session has no decisive answers: $answers $kept $all"
  grep -q "left out 1 aborted session (P1 (session id 1)) with $answers answers: closed with blurcue sessions --abort" \
    "$W/report/index.html" || fail "the summary does not say what it left out: $(grep -o 'aborted[^<]*' "$W/report/index.html")"
  grep -q "report: left out 1 aborted session" "$W/err" || fail "stderr: $(cat "$W/err")"
  grep -q "of $kept decisive answers" "$W/report/index.html" || fail "not $kept decisive answers: $(grep -o 'of [0-9]* decisive answers' "$W/report/index.html")"
  MPLCONFIGDIR=$W/mpl $BC report --db "$W/s.sqlite" --out "$W/report-all" --bench "$W/no-bench" --boot 20 --include-aborted \
    > /dev/null 2> "$W/err" || fail "report --include-aborted: $(tail -3 "$W/err")"
  grep -q "included 1 aborted session (P1 (session id 1)) with $answers answers" "$W/report-all/index.html" || fail "--include-aborted not said"
  grep -q "of $all decisive answers" "$W/report-all/index.html" || fail "--include-aborted: not $all decisive answers"
  # Only an aborted session.
  $BC run "$P/test1-static-grids.json" --participant P9 --db "$W/o.sqlite" --observer sim --stop-after 8 > /dev/null 2>&1
  $BC sessions --db "$W/o.sqlite" --abort 1 > /dev/null
  MPLCONFIGDIR=$W/mpl $BC report --db "$W/o.sqlite" --out "$W/report-only" --bench "$W/no-bench" --boot 20 > /dev/null 2> "$W/err" \
    || fail "report of an aborted session only: $(tail -3 "$W/err")"
  grep -q "left out 1 aborted session (P9 (session id 1))" "$W/report-only/index.html" || fail "the report does not say aborted"
  grep -q "decisive answers" "$W/report-only/index.html" && fail "an aborted session only was analysed"
  echo "ok: an aborted session's $answers answers left out and said ($kept decisive answers, $all with --include-aborted)" ;;
report_any_study)
  # Studies unlike the thesis's - QUEST+ on a blur difference, an odd one out, yes/no and rating, a 2IFC - run by
  # simulated observers of known parameters: the report gives each a section with charts and statistics (none is
  # "ignored"), and the QUEST+ threshold's interval holds the threshold the observers were given. The pages then open
  # in a real browser without a broken image, a missing link or a console message.
  for id in Q1 Q2 Q3 Q4 Q5; do
    $BC run "$P/quest-blur-difference.json" --participant $id --db "$W/s.sqlite" --observer sim:jnd=1.4,lapse=0.02,bias=0 \
      > /dev/null 2>&1 || fail "quest $id"
  done
  for id in S1 S2; do
    for p in odd-one-out-grids yes-no-ball 2ifc-grids; do
      $BC run "$P/$p.json" --participant $id --db "$W/s.sqlite" --observer sim > /dev/null 2>&1 || fail "$p $id"
    done
  done
  # A third odd-one-out observer: a test against chance takes participants as the unit, and needs three.
  $BC run "$P/odd-one-out-grids.json" --participant S3 --db "$W/s.sqlite" --observer sim > /dev/null 2>&1 || fail "odd S3"
  MPLCONFIGDIR=$W/mpl $BC report --db "$W/s.sqlite" --out "$W/report" --bench "$W/no-bench" --boot 60 2> "$W/err" \
    || fail "report: $(tail -3 "$W/err")"
  grep -q "ignored" "$W/err" && fail "a study was ignored: $(grep ignored "$W/err")"
  $PY - "$W/report" "$W/report/tables/trials.csv" > "$W/fit" <<'PYEOF' || fail "report for any study: $(cat "$W/fit")"
import csv, math, os, sys
from statistics import NormalDist
out, trials = sys.argv[1], sys.argv[2]
index = open(os.path.join(out, "index.html"), encoding="utf-8").read()
for study in ("quest-blur-difference", "odd-one-out-grids", "yes-no-ball", "2ifc-grids"):
    assert f"study {study}" in index, f"no section for {study}"
for png in ("quest-blur-difference-simulated-psychometric.png", "quest-blur-difference-simulated-tracks.png",
            "odd-one-out-grids-simulated-per-edge.png", "yes-no-ball-yes_no-simulated-per-blur.png",
            "yes-no-ball-rating-simulated-rating-per-blur.png", "2ifc-grids-simulated-per-edge.png"):
    assert os.path.isfile(os.path.join(out, png)), png
    assert f"<img src='{png}'" in index, png
# The truth: the observer picks the more blurred side with P = Phi(d / jnd) (1 - lapse) + lapse / 2, d the radius
# difference in photo px. The report reads a QUEST+ cell's threshold at QUEST+'s own criterion (analysis/criteria.py):
# 1 - 1/e of the way from guessing (0.5) to the top (1 - lapse / 2), so P* = 0.5 + (0.5 - lapse / 2)(1 - 1/e), at
# d = jnd * Phi^-1((P* - lapse / 2) / (1 - lapse)), in arcmin via the display's arcmin per photo px (the export's
# r_left_arcmin / r_left_px).
rows = [r for r in csv.DictReader(open(trials)) if r["study"] == "quest-blur-difference" and r["r_left_px"]
        and float(r["r_left_px"]) > 0]
arcmin_per_px = float(rows[0]["r_left_arcmin"]) / float(rows[0]["r_left_px"])
jnd, lapse = 1.4, 0.02
target = 0.5 + (0.5 - lapse / 2) * (1 - math.exp(-1))
truth = jnd * NormalDist().inv_cdf((target - lapse / 2) / (1 - lapse)) * arcmin_per_px
fit = next(csv.DictReader(open(os.path.join(out, "quest-blur-difference-simulated-psychometric.csv"))))
assert fit["criterion"] == "81.6 % correct without lapses", fit["criterion"]
# What the fitted function gives there, said beside it (its lapse lowers the share): its own criterion_share_correct.
share = float(fit["criterion_share_correct"])
assert fit["criterion_fitted"] == fit["criterion"] or f"gives {100 * share:.1f} % there" in fit["criterion_fitted"], fit
assert fit["unit"] == "arcmin", fit["unit"]
lo, th, hi = float(fit["threshold_low"]), float(fit["threshold"]), float(fit["threshold_high"])
print(f"QUEST+ threshold {th:.3f} [{lo:.3f}, {hi:.3f}] arcmin; the observers' {truth:.3f}")
assert lo <= truth <= hi, (lo, th, hi, truth)
# Each QUEST+ track's threshold is its posterior median over the grid, with a credible interval inside the grid, or
# "not determined" in words (no number).
tracks = list(csv.DictReader(open(os.path.join(out, "quest-blur-difference-simulated-tracks.csv"))))
assert len(tracks) == 5 and all(t["method"].startswith("QUEST+ posterior over the protocol's grid") for t in tracks), tracks
for t in tracks:
    if t["threshold_says"] == "determined":
        assert 0.25 <= float(t["threshold_low"]) <= float(t["threshold"]) <= float(t["threshold_high"]) <= 6, t
    else:
        assert t["threshold_says"].startswith("not determined") and t["threshold"] == "", t
# The odd one out is found above chance (1/3) where the odd card differs most (edge 9), by the exact test of the
# three participants' answers under every one of them guessing (analysis/study_tests.py: chance other than 0.5).
odd = list(csv.DictReader(open(os.path.join(out, "odd-one-out-grids-simulated-per-edge.csv"))))
nine = next(r for r in odd if r["edge"] == "9")
assert float(nine["share"]) > 1 / 3 and nine["test"].startswith("exact binomial test of 3 participants' answers") and float(nine["p"]) < 0.05, nine
# The summary says what each study found.
assert "Summary" in index and "threshold" in index and "chance 0.33" in index, "summary"
PYEOF
  $PY "$(dirname "$0")/browser_check.py" "$W/report" index.html bench.html > "$W/browser" || fail "$(cat "$W/browser")"
  $PY "$(dirname "$0")/report_numbers_check.py" "$W/report" > "$W/numbers" || fail "$(cat "$W/numbers")"
  echo "ok: every study has its section; $(cat "$W/fit"); $(cat "$W/browser" | sed 's/^ok: //'); $(sed 's/^ok: //' "$W/numbers")" ;;
practice_criterion)
  # A practice block run until a criterion (80 % correct in one run of its design, at most 3 runs): an observer who
  # sees every difference meets it in the first run and the two runs after it are recorded as skipped; one who
  # guesses (jnd 50 px, 6 answers a run, criterion 100 %) runs all three. Stopped mid-way and resumed, the record is
  # the uninterrupted one.
  $PY - "$P/test1-static-grids.json" "$W/p.json" <<'PYEOF'
import json, sys
t = json.load(open(sys.argv[1]))
p = {"name": "practice-criterion", "version": 1, "scene": t["scene"], "content": {"type": "grid"},
     "task": "forced_choice", "sides": {"left": "measured", "right": "none"}, "counterbalance": "swap_copies",
     "blocks": [{"name": "warmup", "practice": True, "criterion": {"correct": 0.8, "max_repeats": 3},
                 "factors": {"edge": [4, 7, 10]}, "instructions": "Which grid is more blurred?"},
                {"name": "main", "factors": {"edge": [3, 9]}}],
     "timing": {"feedback_ms": 300}}
json.dump(p, open(sys.argv[2], "w"))
PYEOF
  sed -i "s|\"\.\./|\"$P/../|g" "$W/p.json"
  $BC run "$W/p.json" --participant G1 --db "$W/s.sqlite" --observer sim:jnd=0.05,lapse=0 > "$W/out" 2>&1 \
    || fail "good observer: $(tail -1 "$W/out")"
  grep -q "12 practice trials skipped now: the criterion was met" "$W/out" || fail "good observer: $(tail -1 "$W/out")"
  grep -q "procedure had stopped" "$W/out" && fail "good observer: a stop rule named where none ran: $(tail -1 "$W/out")"
  # sessions counts the skipped practice trials apart, never as answered: 6 + 4 answered of 22, 12 skipped.
  $BC sessions --db "$W/s.sqlite" | grep -Eq "practice-criterion +1 +G1 +1 +- +simulated +completed +10/22 +12 +0 " \
    || fail "sessions: $($BC sessions --db "$W/s.sqlite")"
  # Another protocol text under the study's name in the same record: a new version.
  sed 's/"correct": 0.8/"correct": 1/; s/"version": 1/"version": 2/' "$W/p.json" > "$W/strict.json"
  $BC run "$W/strict.json" --participant B1 --db "$W/s.sqlite" --observer sim:jnd=50,lapse=0 > "$W/out" 2>&1 \
    || fail "guessing observer: $(tail -1 "$W/out")"
  grep -q "22 of 22 trials answered" "$W/out" || fail "guessing observer: $(tail -1 "$W/out")"
  $BC export --db "$W/s.sqlite" --out "$W/tables" > /dev/null
  $PY - "$W/tables/trials.csv" <<'PYEOF' || fail "practice runs in the record"
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
good = [r for r in rows if r["participant"] == "G1" and r["block_name"] == "warmup"]
assert [r["round"] for r in good] == ["1"] * 6 + ["2"] * 6 + ["3"] * 6, [r["round"] for r in good]
assert all(r["status"] == "answered" and r["correct"] == "1" for r in good[:6]), good[:6]
assert all(r["status"] == "skipped" and not r["chosen_side"] for r in good[6:]), good[6:]
bad = [r for r in rows if r["participant"] == "B1" and r["block_name"] == "warmup"]
assert all(r["status"] == "answered" for r in bad) and len(bad) == 18
for run in ("1", "2", "3"):
    assert sum(r["correct"] == "1" for r in bad if r["round"] == run) < 6, run  # never all six
print("ok")
PYEOF
  $BC run "$W/p.json" --participant G2 --db "$W/split.sqlite" --observer sim:jnd=0.05,lapse=0 --stop-after 4 \
    > /dev/null 2>&1
  $BC run "$W/p.json" --participant G2 --db "$W/split.sqlite" --observer sim:jnd=0.05,lapse=0 --resume > /dev/null 2>&1
  $BC run "$W/p.json" --participant G2 --db "$W/whole.sqlite" --observer sim:jnd=0.05,lapse=0 > /dev/null 2>&1
  [ "$(fingerprint "$W/split.sqlite" G2)" = "$(fingerprint "$W/whole.sqlite" G2)" ] || fail "resumed practice differs"
  # Tampered records whose skips the answers before them do not give are refused on resume, exit 3, nothing added:
  # a skipped practice trial recorded as shown, and a shown one recorded as skipped.
  # An answer no key gives, and an answer deleted from the middle (a gap), are refused too.
  for tamper in "6 left|trial 6: the record shows it, but the answers before it skip it (criterion met in run 1)" \
                "2 skipped|trial 2: the record skips it, but the answers before it show it" \
                "3 bogus|trial 3: the record's answer 'bogus' is none this trial can have" \
                "2 DELETE|its first unanswered trial is 2, but the record holds answers or frames of trials after it"; do
    index=${tamper%% *}; rest=${tamper#* }; choice=${rest%%|*}; message=${tamper#*|}
    rm -f "$W/t.sqlite"
    $BC run "$W/p.json" --participant G3 --db "$W/t.sqlite" --observer sim:jnd=0.05,lapse=0 --stop-after 8 \
      > /dev/null 2>&1
    $PY - "$W/t.sqlite" "$index" "$choice" <<'PYEOF'
import sqlite3, sys
con = sqlite3.connect(sys.argv[1])
if sys.argv[3] == "DELETE":
    n = con.execute("DELETE FROM responses WHERE trial_id = (SELECT id FROM trials WHERE trial_index = ?)",
                    (int(sys.argv[2]),)).rowcount
else:
    n = con.execute("UPDATE responses SET choice = ? WHERE trial_id = (SELECT id FROM trials WHERE trial_index = ?)",
                    (sys.argv[3], int(sys.argv[2]))).rowcount
assert n == 1, n
con.commit()
PYEOF
    before=$($PY -c "import sqlite3,sys; print(sqlite3.connect(sys.argv[1]).execute('SELECT COUNT(*) FROM responses').fetchone()[0])" "$W/t.sqlite")
    set +e
    $BC run "$W/p.json" --participant G3 --db "$W/t.sqlite" --observer sim:jnd=0.05,lapse=0 --resume \
      > /dev/null 2> "$W/err"
    code=$?
    set -e
    [ $code = 3 ] && grep -qF "$message" "$W/err" && grep -q "it cannot be resumed$" "$W/err" || fail "tampered ($tamper): exit $code: $(cat "$W/err")"
    [ "$($PY -c "import sqlite3,sys; print(sqlite3.connect(sys.argv[1]).execute('SELECT COUNT(*) FROM responses').fetchone()[0])" "$W/t.sqlite")" = "$before" ] || fail "tampered ($tamper): answers added"
  done
  echo "ok: a practice run that met its criterion skipped the runs after it; a guessing observer ran all three; resumable; tampered skips refused" ;;
level_names)
  # A design's columns are names blurcue reads or labels: a conditions table's status (a name trials.csv records of
  # its own, which nothing reads as a level) is refused at validate with the label it could be. Labels named like
  # what trials.csv records - label_status, label_participant, label_r_left_px, label_info_age; a staircase table's
  # label_level, label_test_side, label_correct - validate, run and come out of export with the table's values,
  # beside the columns the record fills (the radius shown, the staircase's level, the participant's age).
  $PY - "$P/test1-static-grids.json" "$W" <<'PYEOF'
import json, sys
t, w = json.load(open(sys.argv[1])), sys.argv[2]
open(w + "/unread.csv", "w").write("edge,status\n3,answered\n")
open(w + "/rows.csv", "w").write("edge,label_status,label_participant,label_r_left_px,label_info_age\n"
                                 "3,answered,P9,7.5,41\n6,x,P8,1,42\n")
open(w + "/stairs.csv", "w").write("edge,label_level,label_test_side,label_correct\n6,99,left,1\n3,98,right,0\n")
common = {"version": 1, "scene": t["scene"], "content": {"type": "grid"}, "task": "forced_choice"}
json.dump(dict(common, name="unread-table",
               blocks=[{"name": "tab", "conditions": "unread.csv", "sides": {"left": "measured", "right": "none"}}]),
          open(w + "/unread.json", "w"))
json.dump(dict(common, name="clash-table", participant_info=[{"key": "age", "type": "integer", "min": 16, "max": 99}],
               blocks=[{"name": "tab", "conditions": "rows.csv", "sides": {"left": "measured", "right": "none"}}]),
          open(w + "/table.json", "w"))
json.dump(dict(common, name="clash-stairs", responses={"cant_tell": None},
               blocks=[{"name": "st", "conditions": "stairs.csv",
                        "procedure": {"type": "staircase", "variable": "relative_difference", "reference": "measured",
                                      "trials": 3, "start": 1, "min": 0.1, "max": 2, "up": 1, "down": 2,
                                      "steps": [0.5]}}]),
          open(w + "/stairs.json", "w"))
PYEOF
  sed -i "s|\"\.\./|\"$P/../|g" "$W/unread.json" "$W/table.json" "$W/stairs.json"
  code=0
  $BC validate "$W/unread.json" > "$W/out" 2>&1 || code=$?
  [ "$code" = 3 ] || fail "validate of a table with a column nobody reads: exit $code, expected 3"
  grep -q "unread.csv line 1, column 2: no part of blurcue reads a column status; to record it as a label nobody reads, name it label_status" "$W/out" ||
    fail "validate of an unread column: $(tail -1 "$W/out")"
  for p in table stairs; do
    $BC validate "$W/$p.json" > "$W/out" 2>&1 || fail "validate $p: $(tail -1 "$W/out")"
  done
  $BC run "$W/table.json" --participant P1 --db "$W/s.sqlite" --observer sim --info age=30 > "$W/out" 2>&1 ||
    fail "run table: $(tail -1 "$W/out")"
  $BC run "$W/stairs.json" --participant P2 --db "$W/s.sqlite" --observer sim > "$W/out" 2>&1 ||
    fail "run stairs: $(tail -1 "$W/out")"
  $BC export --db "$W/s.sqlite" --out "$W/tables" > /dev/null
  $PY - "$W/tables" <<'PYEOF' || fail "labels named like recorded columns"
import csv, sys
d = sys.argv[1]
header = next(csv.reader(open(d + "/trials.csv")))
assert len(header) == len(set(header)), sorted(h for h in header if header.count(h) > 1)
rows = list(csv.DictReader(open(d + "/trials.csv")))
table = [r for r in rows if r["study"] == "clash-table"]
assert len(table) == 2, len(table)
for r in table:
    designed = {"3": ("answered", "P9", "7.5", "41"), "6": ("x", "P8", "1", "42")}[r["edge"]]
    got = (r["label_status"], r["label_participant"], r["label_r_left_px"], r["label_info_age"])
    assert got == designed, (r["edge"], got)
    assert (r["participant"], r["status"], r["info_age"]) == ("P1", "answered", "30"), r
    assert r["r_left_px"] and r["r_left_px"] != r["label_r_left_px"], r["r_left_px"]  # the radius shown
stairs = [r for r in rows if r["study"] == "clash-stairs"]
assert len(stairs) == 6, len(stairs)
for r in stairs:
    designed = {"6": ("99", "left", "1"), "3": ("98", "right", "0")}[r["edge"]]
    assert (r["label_level"], r["label_test_side"], r["label_correct"]) == designed, r
    assert 0.1 <= float(r["level"]) <= 2 and r["test_side"] in ("left", "right") and r["correct"] in ("0", "1"), r
codebook = {row["column"]: row["meaning"] for row in csv.DictReader(open(d + "/codebook.csv")) if row["table"] == "trials.csv"}
assert "factor label_r_left_px" in codebook["label_r_left_px"], codebook["label_r_left_px"]
print("ok")
PYEOF
  echo "ok: a column nobody reads is refused at validate; a table's label_status, label_participant, label_r_left_px, label_info_age and a staircase table's label_level, label_test_side, label_correct come out with their values, beside the recorded columns" ;;
odd_names)
  # Names that validate and run must report (issue 24: report exited 10, and one such session in a merged record
  # withheld the whole report). A factor and a conditions table's column named with a '/' (label_a/b) are kept
  # verbatim in the page and in trials.csv, their files named without the '/'. A pattern id Infinity, and ids or a
  # participant spelled NA or nan (text pandas and R read as no value or an infinite number), are refused by validate
  # and run, naming the field and the value.
  $PY - "$P/test1-static-grids.json" "$W" <<'PYEOF'
import json, sys
t, w = json.load(open(sys.argv[1])), sys.argv[2]
open(w + "/rows.csv", "w").write("edge,left,right,label_c/d\n3,measured,estimated,x/1\n9,measured,estimated,y/2\n"
                                 "6,estimated,measured,x/1\n")
common = {"version": 1, "scene": t["scene"], "content": {"type": "grid"}, "task": "forced_choice"}
json.dump(dict(common, name="slash-factor", counterbalance="swap_copies",
               factors={"edge": [3, 9], "label_a/b": ["p/q", "r/s"],
                        "pair": [{"id": "m/e", "left": "measured", "right": "estimated"},
                                 {"id": "e/n", "left": "estimated", "right": "none"}]}),
          open(w + "/factor.json", "w"))
t = json.load(open(w + "/factor.json"))
t["factors"]["side/pair"] = t["factors"].pop("pair")
json.dump(t, open(w + "/analysed.json", "w"))
json.dump(dict(common, name="slash-table", blocks=[{"name": "tab", "conditions": "rows.csv"}]),
          open(w + "/table.json", "w"))
# Numeric ids no reader holds exactly (1e308, 2^64 - 1): refused too (the adversary's ids that validated).
for name, pid in (("huge", 1e308), ("wide", 18446744073709551615)):
    json.dump(dict(common, name="id-" + name, factors={"pattern": [{"id": pid, "left": "measured", "right": "none"}],
                                                       "edge": [3]}),
              open(w + "/" + name + ".json", "w"))
for name, pid in (("infinity", "Infinity"), ("nan", "nan")):
    json.dump(dict(common, name="id-" + name, factors={"pattern": [{"id": pid, "left": "measured", "right": "none"},
                                                                   {"id": 2, "left": "estimated", "right": "none"}],
                                                       "edge": [3]}),
              open(w + "/" + name + ".json", "w"))
PYEOF
  sed -i "s|\"\.\./|\"$P/../|g" "$W"/*.json
  for p in infinity nan; do
    code=0
    $BC validate "$W/$p.json" > "$W/out" 2>&1 || code=$?
    [ "$code" = 3 ] || fail "validate of a pattern id $p: exit $code, expected 3: $(tail -1 "$W/out")"
    grep -q "/factors/pattern/0/id: an id is text the readers of the exported tables (pandas, R) take as a missing value or an infinite number, not as a name" "$W/out" ||
      fail "validate of a pattern id $p: $(tail -1 "$W/out")"
  done
  # A factor of object levels (analysed: a term of the report's models) named side/pair: refused by validate and run.
  for cmd in "validate $W/analysed.json" "run $W/analysed.json --participant P1 --db $W/refused.sqlite --observer sim"; do
    code=0
    $BC $cmd > "$W/out" 2>&1 || code=$?
    [ "$code" = 3 ] || fail "$cmd: exit $code, expected 3: $(tail -1 "$W/out")"
    grep -qF "/factors/side~1pair: the factor side/pair names a term of the report's models" "$W/out" ||
      fail "$cmd: $(tail -1 "$W/out")"
  done
  for p in huge wide; do
    code=0
    $BC validate --no-files "$W/$p.json" > "$W/out" 2>&1 || code=$?
    [ "$code" = 3 ] && grep -q "/factors/pattern/0/id: an id must be text or a whole number below 2^53" "$W/out" ||
      fail "validate of a pattern id $p: exit $code: $(tail -1 "$W/out")"
  done
  code=0
  $BC run "$W/factor.json" --participant NA --db "$W/na.sqlite" --observer sim > "$W/out" 2>&1 || code=$?
  [ "$code" = 2 ] || fail "run of participant NA: exit $code, expected 2: $(tail -1 "$W/out")"
  grep -q "missing value" "$W/out" || fail "run of participant NA: $(tail -1 "$W/out")"
  for p in factor table; do
    $BC validate "$W/$p.json" > "$W/out" 2>&1 || fail "validate $p: $(tail -1 "$W/out")"
    $BC run "$W/$p.json" --participant P1 --db "$W/s.sqlite" --observer sim > "$W/out" 2>&1 || fail "run $p: $(tail -1 "$W/out")"
  done
  code=0
  MPLCONFIGDIR=$W/mpl $BC report --db "$W/s.sqlite" --out "$W/report" --bench "$W/no-bench" --boot 20 > "$W/out" 2>&1 ||
    code=$?
  [ "$code" = 0 ] || fail "report of names with '/': exit $code: $(tail -3 "$W/out")"
  # The pattern's ids with a '/' are shown verbatim; the labels are recorded as they are.
  for name in "m/e" "e/n"; do
    grep -qF "$name" "$W/report/index.html" || fail "the page does not show $name verbatim"
  done
  for name in "label_a/b" "label_c/d"; do
    head -1 "$W/report/tables/trials.csv" | grep -qF "$name" || fail "trials.csv has no column $name"
  done
  # Every file the page links to is in the report's folder, and no file name has a folder in it.
  $PY - "$W/report" <<'PYEOF' || fail "the report's links"
import html, os, re, sys
d = sys.argv[1]
page = open(os.path.join(d, "index.html"), encoding="utf-8").read()
links = [html.unescape(l) for l in re.findall(r"(?:src|href)='([^'#:]+)'", page)]
assert links, "no links"
missing = [l for l in links if not os.path.isfile(os.path.join(d, l))]
assert not missing, missing
assert not any(os.path.isdir(os.path.join(d, e)) and e not in ("tables",) for e in os.listdir(d)), os.listdir(d)
PYEOF
  # One such session inside a merged record: merged with another station's record (test 1, one session completed and
  # one killed), the whole record still reports (exit 0), the '/' names verbatim beside test 1's rows.
  $BC run "$P/test1-static-grids.json" --participant P1 --db "$W/other.sqlite" --observer sim > /dev/null 2>&1 ||
    fail "run test 1"
  $BC run "$P/test1-static-grids.json" --participant P2 --db "$W/other.sqlite" --observer sim --stop-after 4 \
    > /dev/null 2>&1 || fail "run test 1, stopped"
  $BC merge "$W/s.sqlite" "$W/other.sqlite" --out "$W/merged.sqlite" > "$W/out" 2>&1 || fail "merge: $(tail -1 "$W/out")"
  code=0
  MPLCONFIGDIR=$W/mpl $BC report --db "$W/merged.sqlite" --out "$W/merged-report" --bench "$W/no-bench" --boot 20 \
    > "$W/out" 2>&1 || code=$?
  [ "$code" = 0 ] || fail "report of a merged record holding names with '/': exit $code: $(tail -3 "$W/out")"
  grep -qF "m/e" "$W/merged-report/index.html" || fail "the merged record's page does not show m/e verbatim"
  $PY - "$W/merged-report/tables/trials.csv" <<'PYEOF' || fail "the merged record's trials.csv"
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
studies = {r["study"] for r in rows}
assert studies == {"slash-factor", "slash-table", "test1-static-grids"}, studies
assert {r["label_a/b"] for r in rows if r["study"] == "slash-factor"} == {"p/q", "r/s"}
PYEOF
  echo "ok: labels and ids with '/' report (exit 0), kept verbatim, alone and merged with another station's record; a factor side/pair, ids Infinity, nan, 1e308 and 2^64 - 1 and a participant NA refused" ;;
collided_names)
  # Two design variables recorded in one column are refused by validate (with and without --no-files) and by run,
  # naming both, before anything is recorded (issue 24: a factor status and a factor factor_status validated, and
  # factor_status was recorded with status's levels, b1/b2 stored nowhere). A factor of object levels may take any
  # name, so status (a column trials.csv writes itself, its levels recorded as factor_status) meets factor_status.
  $PY - "$P/test1-static-grids.json" "$W" <<'PYEOF'
import json, sys
t, w = json.load(open(sys.argv[1])), sys.argv[2]
common = {"version": 1, "scene": t["scene"], "content": {"type": "grid"}, "task": "forced_choice",
          "sides": {"left": "measured", "right": "estimated"}}
ids = lambda *names: [{"id": n} for n in names]
json.dump(dict(common, name="collided", factors={"edge": [2, 5], "status": ids("a1", "a2"),
                                                 "factor_status": ids("b1", "b2")}),
          open(w + "/status.json", "w"))
json.dump(dict(common, name="collided", factors={"edge": [2, 5], "correct": ids("a1", "a2"),
                                                 "factor_correct": ids("b1", "b2")}),
          open(w + "/correct.json", "w"))
PYEOF
  sed -i "s|\"\.\./|\"$P/../|g" "$W"/*.json
  for name in status correct; do
    # The factors in name order: correct before factor_correct, factor_status before status.
    if [ $name = correct ]; then
      want="/factors/factor_$name: the factor factor_$name is recorded in the column factor_$name, as is the factor $name (/factors/$name)"
    else
      want="/factors/$name: the factor $name is recorded in the column factor_$name, as is the factor factor_$name (/factors/factor_$name)"
    fi
    for cmd in "validate $W/$name.json" "validate --no-files $W/$name.json" \
               "run $W/$name.json --participant P1 --db $W/s.sqlite --observer sim"; do
      code=0
      $BC $cmd > "$W/out" 2>&1 || code=$?
      [ "$code" = 3 ] || fail "$cmd: exit $code, expected 3: $(tail -1 "$W/out")"
      grep -qF "$want" "$W/out" || fail "$cmd: $(cat "$W/out")"
    done
  done
  [ ! -e "$W/s.sqlite" ] || [ "$(sql "$W/s.sqlite" "SELECT count(*) FROM sessions")" = 0 ] || fail "run recorded a session"
  echo "ok: status/factor_status and correct/factor_correct refused by validate, validate --no-files and run, naming both" ;;
*) fail "unknown case $CASE" ;;
esac
