#!/usr/bin/env bash
# End-to-end tests of `blurcue report` on studies run by the real `blurcue run` with simulated observers: the report
# analyses the design the record declares - one QUEST+ per depth analysed per depth, between-subject groups compared
# with participants as the unit, unfinished and repeated sessions kept apart.
# Usage: report_design_test.sh CASE BLURCUE DIR. DIR holds protocols/ (tests/copy_protocols.cmake) and the scene
# they show. Each case prints what it checked and exits non-zero on the first failure.
set -euo pipefail
CASE=$1 BC=$2 DIR=$3
P=$DIR/protocols
W=$DIR/report-design-$CASE
rm -rf "$W" && mkdir -p "$W"
source "$(dirname "$0")/lib.sh"
DATA=$(cd "$(dirname "$0")/data" && pwd)
# A protocol of tests/data pointed at the CLI tests' scene, as tests/copy_protocols.cmake does for the shipped ones.
protocol() { sed "s|\"\.\./results/demo/|\"$P/../|g" "$DATA/$1.json" > "$W/$1.json"; }
report() { MPLCONFIGDIR=$W/mpl $BC report --db "$1" --out "$2" --bench "$W/no-bench" --boot 40 "${@:3}"; }

case $CASE in
quest_per_depth)
  # One QUEST+ per depth (edges 3, 6, 9: three procedure cells of one block), three simulated observers: each depth
  # gets its own psychometric function labelled by its edge, over that cell's answers only, and no test against
  # chance (QUEST+ sets the share correct). The truth: the observer's own threshold per depth, from its formula
  # (procedure/observer.h, model=arcmin defaults): a blur of std s = r / 2 arcmin is seen as E = sqrt(s^2 + 0.6^2);
  # P(correct) = lapse / 2 + (1 - lapse) Phi(ln(E_test / E_ref) / sd), sd = ln(1.35) / Phi^-1(0.75), lapse 0.04 - so
  # the extra blur needed for QUEST+'s criterion (its Weibull's scale: 0.5 + 0.5 (1 - 1/e) = 81.6 % correct) grows
  # with the depth's own blur (Weber): the fits must rank the near and the far depth the same way, and the summary
  # must state that criterion for the tracks and the pooled fit alike (criteria.py).
  protocol quest-per-depth
  for id in Q1 Q2 Q3; do
    $BC run "$W/quest-per-depth.json" --participant $id --db "$W/q.sqlite" --observer sim:blurrier=0 > /dev/null 2>&1 \
      || fail "run $id"
  done
  report "$W/q.sqlite" "$W/report" > /dev/null 2> "$W/err" || fail "report: $(tail -3 "$W/err")"
  $PY - "$W/report" <<'PYEOF' > "$W/found" || fail "per depth: $(cat "$W/found")"
import csv, math, os, sys
from statistics import NormalDist
out = sys.argv[1]
rows = [r for r in csv.DictReader(open(os.path.join(out, "tables", "trials.csv"))) if r["status"] == "answered"]
index = open(os.path.join(out, "index.html"), encoding="utf-8").read()
assert not os.path.exists(os.path.join(out, "quest-per-depth-simulated-psychometric.png")), "a fit pooled over depths"
z = NormalDist().inv_cdf
sd, lapse = math.log(1.35) / z(0.75), 0.04
d = sd * z((0.5 + 0.5 * (1 - math.exp(-1)) - lapse / 2) / (1 - lapse))
fitted, truth = {}, {}
for edge in ("3", "6", "9"):
    name = f"quest-per-depth-simulated-psychometric-edge_{edge}"
    assert f"<img src='{name}.png'" in index, name
    fit = next(csv.DictReader(open(os.path.join(out, name + ".csv"))))
    mine = [r for r in rows if r["cell"] == f"edge={edge}"]
    assert fit["cell"] == f"edge={edge}" and int(fit["answers"]) == len(mine) == 96, (fit["cell"], fit["answers"])
    assert fit["threshold"], f"edge {edge}: no threshold"
    fitted[edge] = float(fit["threshold"])
    ref = {float(r["r_right_arcmin"] if r["test_side"] == "left" else r["r_left_arcmin"]) for r in mine}
    assert len(ref) == 1, ref
    e_ref = math.hypot(ref.pop() / 2, 0.6)
    truth[edge] = 2 * math.sqrt((e_ref * math.exp(d)) ** 2 - 0.36) - 2 * math.sqrt(e_ref ** 2 - 0.36)
assert truth["3"] < truth["9"] and fitted["3"] < fitted["9"], (truth, fitted)
# No test against chance anywhere for the adaptive block: not in its table, not in the summary.
table = list(csv.DictReader(open(os.path.join(out, "quest-per-depth-simulated-conditions.csv"))))
assert {r["edge"] for r in table} == {"3", "6", "9"} and not {"p", "p_holm", "chance", "test"} & set(table[0]), table[0]
summary = index.split("<h3>Contents</h3>")[0]
line = summary[summary.index("quest-per-depth (simulated observers)"):]
line = line[:line.index("</tr>")]
assert "chance" not in line and "tracks: edge 3: threshold at 81.6 % correct" in line, line
# The pooled fit is a description in its chart, never a result beside the per-participant thresholds.
assert "psychometric fit of the answers pooled" not in line, line
assert "edge 9: threshold at 81.6 % correct" in line and "75 %" not in line, line
print("thresholds per depth " + ", ".join(f"edge {e}: {fitted[e]:.2f} (observer {truth[e]:.2f})" for e in fitted))
PYEOF
  $PY "$(dirname "$0")/report_numbers_check.py" "$W/report" > "$W/numbers" || fail "$(cat "$W/numbers")"
  echo "ok: one QUEST+ per depth analysed per depth, labelled by edge, no chance test; $(cat "$W/found"); $(sed 's/^ok: //' "$W/numbers")" ;;
groups)
  # Two between-subject groups that see the same trials, answered by simulated observers with a planted difference:
  # group a's observers have no bias toward the more blurred side (blurrier=0), group b's a strong one
  # (blurrier=2, noise sds). The groups are assigned in turn (a, b, a, ...), so odd participants are in a.
  protocol groups-planted
  for i in 1 2 3 4 5 6; do
    if [ $((i % 2)) = 1 ]; then o=sim:blurrier=0; else o=sim:blurrier=2; fi
    $BC run "$W/groups-planted.json" --participant G$i --db "$W/g.sqlite" --observer $o > /dev/null 2>&1 || fail "run G$i"
  done
  report "$W/g.sqlite" "$W/report" > /dev/null 2> "$W/err" || fail "report: $(tail -3 "$W/err")"
  $PY - "$W/report" <<'PYEOF' > "$W/found" || fail "groups: $(cat "$W/found")"
import csv, os, sys
out = sys.argv[1]
rows = [r for r in csv.DictReader(open(os.path.join(out, "tables", "trials.csv")))]
assert {r["participant"]: r["group"] for r in rows} == {f"G{i}": "a" if i % 2 else "b" for i in range(1, 7)}
index = open(os.path.join(out, "index.html"), encoding="utf-8").read()
slug = "groups-planted-simulated"
for g in ("a", "b"):
    table = list(csv.DictReader(open(os.path.join(out, f"{slug}-group-{g}-conditions.csv"))))
    mine = [r for r in rows if r["group"] == g and r["chose_more_blurred"] in ("0", "1")]
    assert sum(int(r["n"]) for r in table) == len(mine), (g, len(mine))
    assert all(r["participants"] == "3" for r in table), table
    assert f"<img src='{slug}-group-{g}-per-edge.png'" in index and f"group {g}" in index, g
effect = {r["group"]: r for r in csv.DictReader(open(os.path.join(out, f"{slug}-per-group.csv")))}
assert effect["a"]["participants"] == effect["b"]["participants"] == "3", effect
# The planted direction, from the participants' own shares (not the answers pooled).
share = {}
for g in ("a", "b"):
    people = {r["participant"] for r in rows if r["group"] == g}
    share[g] = sum(sum(r["chose_more_blurred"] == "1" for r in rows if r["participant"] == p) /
                   sum(r["chose_more_blurred"] in ("0", "1") for r in rows if r["participant"] == p)
                   for p in people) / len(people)
    assert abs(float(effect[g]["participant_mean"]) - share[g]) < 1e-9, (g, effect[g], share[g])
assert share["b"] > share["a"] and float(effect["a"]["p_welch"]) < 0.05, (share, effect["a"])
assert "group b higher than group a" in index, "direction not said"
models = list(csv.DictReader(open(os.path.join(out, f"{slug}-groups-models.csv"))))
assert any("group" in r["term"] for r in models), [r["term"] for r in models]
print(f"group a {share['a']:.2f}, group b {share['b']:.2f}, Welch p = {float(effect['a']['p_welch']):.3g}")
PYEOF
  $PY "$(dirname "$0")/browser_check.py" "$W/report" index.html > "$W/browser" || fail "$(cat "$W/browser")"
  $PY "$(dirname "$0")/report_numbers_check.py" "$W/report" > "$W/numbers" || fail "$(cat "$W/numbers")"
  echo "ok: per-group tables and charts, the planted group difference found with participants as the unit: $(cat "$W/found"); $(sed 's/^ok: //' "$W/browser")" ;;
sessions)
  # Three participants complete the 2IFC study, P1 comes back (--again: session number 2), P4 stops after 3 answers
  # (left running). The report analyses the three first sessions, says it left P4 out, and gives P1's second session
  # a section of its own; --include-unfinished takes P4 in, named as partial data.
  for id in P1 P2 P3; do
    $BC run "$P/2ifc-grids.json" --participant $id --db "$W/s.sqlite" --observer sim > /dev/null 2>&1 || fail "run $id"
  done
  $BC run "$P/2ifc-grids.json" --participant P1 --again --db "$W/s.sqlite" --observer sim > /dev/null 2>&1 || fail "again"
  $BC run "$P/2ifc-grids.json" --participant P4 --db "$W/s.sqlite" --observer sim --stop-after 3 > /dev/null 2>&1 || fail "P4"
  report "$W/s.sqlite" "$W/report" > /dev/null 2> "$W/err" || fail "report: $(tail -3 "$W/err")"
  report "$W/s.sqlite" "$W/report-all" --include-unfinished > /dev/null 2> "$W/err-all" || fail "report: $(tail -3 "$W/err-all")"
  grep -q "^report: left out 1 unfinished session (P4 (session id 5)) with 3 answers" "$W/err" || fail "stderr: $(cat "$W/err")"
  $PY - "$W/report" "$W/report-all" <<'PYEOF' > "$W/found" || fail "sessions: $(cat "$W/found")"
import csv, os, sys
out, out_all = sys.argv[1], sys.argv[2]
rows = [r for r in csv.DictReader(open(os.path.join(out, "tables", "trials.csv"))) if r["practice"] == "0"]
status = {(r["participant"], r["session_number"]): r["session_status"] for r in rows}
assert status == {("P1", "1"): "completed", ("P2", "1"): "completed", ("P3", "1"): "completed",
                  ("P1", "2"): "completed", ("P4", "1"): "running"}, status
def decisive(keep):
    return sum(1 for r in rows if keep(r) and r["chose_more_blurred"] in ("0", "1"))
def analysed(folder, name):
    table = list(csv.DictReader(open(os.path.join(folder, name))))
    return sum(int(r["n"]) for r in table), max(int(r["participants"]) for r in table)
index = open(os.path.join(out, "index.html"), encoding="utf-8").read()
assert "left out 1 unfinished session (P4 (session id 5)) with 3 answers" in index
first = decisive(lambda r: r["session_number"] == "1" and r["session_status"] == "completed")
assert analysed(out, "2ifc-grids-simulated-conditions.csv") == (first, 3), (analysed(out, "2ifc-grids-simulated-conditions.csv"), first)
again = decisive(lambda r: r["session_number"] == "2")
assert analysed(out, "2ifc-grids-session2-simulated-conditions.csv") == (again, 1), again
assert "study 2ifc-grids (session 2, simulated observers)" in index and "1 repeated session (P1 (session number 2): after one the participant completed)" in index
# --include-unfinished: P4's answers in, said to be partial data.
index_all = open(os.path.join(out_all, "index.html"), encoding="utf-8").read()
assert "included 1 unfinished session (P4 (session id 5)) with 3 answers as partial data" in index_all
with_p4 = decisive(lambda r: r["session_number"] == "1")
assert analysed(out_all, "2ifc-grids-simulated-conditions.csv") == (with_p4, 4), with_p4
assert "incl. 1 unfinished session (partial data)" in index_all
print(f"{first} first-session answers of 3 participants, {again} of P1's second session apart, {with_p4 - first} of P4 only with --include-unfinished")
PYEOF
  $PY "$(dirname "$0")/browser_check.py" "$W/report" index.html > "$W/browser" || fail "$(cat "$W/browser")"
  $PY "$(dirname "$0")/report_numbers_check.py" "$W/report" > "$W/numbers" || fail "$(cat "$W/numbers")"
  echo "ok: unfinished session left out and counted, repeated session apart: $(cat "$W/found"); $(sed 's/^ok: //' "$W/browser")" ;;
mixed_blocks)
  # One study, one task, two kinds of block: one QUEST+ per depth and a block of fixed levels (edges 3 and 9,
  # measured against none, 3 repetitions). Each kind is analysed as what it is; the fixed block's answers used to be
  # dropped unsaid because the study counted as adaptive (a procedure's measure is `correct`, which they lack).
  protocol quest-per-depth
  $PY - "$W/quest-per-depth.json" "$W/mixed.json" <<'PYEOF'
import json, sys
p = json.load(open(sys.argv[1]))
p["name"] = "mixed-blocks"
p["blocks"].append({"name": "constant", "factors": {"edge": [3, 9]}, "sides": {"left": "measured", "right": "none"},
                    "repetitions": 3})
json.dump(p, open(sys.argv[2], "w"), indent=1)
PYEOF
  for id in M1 M2 M3; do
    $BC run "$W/mixed.json" --participant $id --db "$W/m.sqlite" --observer sim > /dev/null 2>&1 || fail "run $id"
  done
  report "$W/m.sqlite" "$W/report" > /dev/null 2> "$W/err" || fail "report: $(tail -3 "$W/err")"
  $PY - "$W/report" <<'PYEOF' > "$W/found" || fail "mixed blocks: $(cat "$W/found")"
import csv, glob, os, sys
out = sys.argv[1]
rows = list(csv.DictReader(open(os.path.join(out, "tables", "trials.csv"))))
fixed = [r for r in rows if r["block_name"] == "constant" and r["status"] == "answered" and r["practice"] == "0"]
assert len(fixed) == 3 * 2 * 3, len(fixed)
tables = glob.glob(os.path.join(out, "mixed-blocks-forced_choice_fixed_levels*-conditions.csv"))
assert len(tables) == 1, sorted(os.listdir(out))
n = sum(int(r["n"]) for r in csv.DictReader(open(tables[0])))
assert n == len(fixed), (n, len(fixed))
index = open(os.path.join(out, "index.html"), encoding="utf-8").read()
assert "adaptive procedure" in index and "forced choice between two" in index, "both kinds in the summary"
print(f"the fixed block's {n} answers analysed beside the procedure's cells")
PYEOF
  $PY "$(dirname "$0")/report_numbers_check.py" "$W/report" > "$W/numbers" || fail "$(cat "$W/numbers")"
  echo "ok: an adaptive and a fixed-levels block of one study each analysed as what it is: $(cat "$W/found")" ;;
crossed_hostile)
  # Two within factors crossed in records a reviewer would try: a crossing left out of the design (edge 9 with
  # rotation_deg 30) beside cells three times the size of the others, and a 3 x 2 crossing whose levels carry a
  # comma, quotes, non-ASCII letters and HTML. Before: the empty crossing's interaction term was called separation
  # ("every answer behind this term went one way": it has no answers), the tables did not name it, and a baseline
  # level with a comma was cut at it ("against comparison label=naïve)").
  protocol crossed-empty
  cp "$DATA/crossed-empty.csv" "$W/"
  protocol crossed-labels
  for id in X1 X2 X3; do
    $BC run "$W/crossed-empty.json" --participant $id --db "$W/e.sqlite" --observer sim > /dev/null 2>&1 || fail "run $id"
    $BC run "$W/crossed-labels.json" --participant $id --db "$W/l.sqlite" --observer sim > /dev/null 2>&1 || fail "run $id"
  done
  report "$W/e.sqlite" "$W/empty" > /dev/null 2> "$W/err" || fail "report: $(tail -3 "$W/err")"
  report "$W/l.sqlite" "$W/labels" > /dev/null 2> "$W/err" || fail "report: $(tail -3 "$W/err")"
  $PY - "$W/empty" "$W/labels" <<'PYEOF' > "$W/found" || fail "crossed: $(cat "$W/found")"
import csv, glob, html, os, re, sys
empty, labels = sys.argv[1], sys.argv[2]
def table(folder, suffix):  # the report folder is named for its study: empty -> crossed-empty-simulated-...
    name = f"crossed-{os.path.basename(folder)}-simulated-{suffix}"
    return list(csv.DictReader(open(os.path.join(folder, name), encoding="utf-8")))
cond = table(empty, "conditions.csv")
assert sorted((r["edge"], r["rotation_deg"]) for r in cond) == [("3", "0"), ("3", "30"), ("6", "0"), ("6", "30"), ("9", "0")], cond
assert [r["n"] for r in cond if (r["edge"], r["rotation_deg"]) == ("3", "0")] == ["54"], cond  # 3 x 2 x 3 x 3 participants (the fewest a model across them needs)
inter = table(empty, "models-interaction.csv")
cell = [r for r in inter if r["term"] == "edge 9 x rotation_deg 30 (interaction: beyond the effects added)"]
assert len(cell) == 2, [r["term"] for r in inter]  # the cluster-robust GLM and the GLMM
for r in cell:
    assert r["estimate"] == r["se"] == r["p"] == "" and r["note"].startswith("not determined: no answers at this crossing"), r
for r in inter:  # a separated term: no number either
    if r["note"].startswith("separation"):
        assert r["estimate"] == r["p"] == "", r
page = html.unescape(re.sub(r"<[^>]+>", " ", open(os.path.join(empty, "index.html"), encoding="utf-8").read()))
page = re.sub(r"\s+", " ", page)
assert "no answers at 1 crossing of edge and rotation_deg: edge 9 with rotation_deg 30" in page, "empty crossing not named"
# The labels: the baseline named whole, the HTML shown as text.
cond = table(labels, "conditions.csv")
assert len(cond) == 6 and {r["edge"] for r in cond} == {"3", "6", "9"}, cond
none = 'label=naïve, µ "a";left=measured;right=none'
assert {r["comparison"] for r in cond} == {none, "label=Ω,<b>β</b>;left=measured;right=estimated"}, cond
terms = [r["term"] for r in table(labels, "models-interaction.csv")]
against = [t for t in terms if "(against comparison" in t]
assert against and all(t.endswith(f"(against comparison {none})") for t in against), against
raw = open(os.path.join(labels, "index.html"), encoding="utf-8").read()
assert "<b>β</b>" not in raw and "&lt;b&gt;β&lt;/b&gt;" in raw, "a level's markup reached the page as markup"
print(f"empty crossing named, its term not determined in words; {len(against)} terms name the baseline whole")
PYEOF
  for r in empty labels; do
    $PY "$(dirname "$0")/browser_check.py" "$W/$r" index.html > "$W/browser" || fail "$r: $(cat "$W/browser")"
    $PY "$(dirname "$0")/report_numbers_check.py" "$W/$r" > "$W/numbers" || fail "$r: $(cat "$W/numbers")"
  done
  echo "ok: crossed factors with an empty crossing, unbalanced cells and hostile level names: $(cat "$W/found"); $(sed 's/^ok: //' "$W/numbers")" ;;
*) fail "unknown case $CASE" ;;
esac
