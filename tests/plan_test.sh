#!/usr/bin/env bash
# End-to-end tests of `blurcue plan`: usage: plan_test.sh CASE BLURCUE DIR
# DIR holds protocols/ (tests/copy_protocols.cmake) and the scene they show. Each case prints what it checked and
# exits non-zero on the first failure.
set -euo pipefail
CASE=$1 BC=$2 DIR=$3
P=$DIR/protocols
W=$DIR/plan-$CASE
rm -rf "$W" && mkdir -p "$W"
source "$(dirname "$0")/lib.sh"
# A copy of protocol $1 changed by the Python statement $3 (on the parsed protocol p) into $2, paths kept.
variant() {
  $PY - "$1" "$2" "$3" <<'PYEOF'
import json, sys
p = json.load(open(sys.argv[1]))
exec(sys.argv[3])
json.dump(p, open(sys.argv[2], "w"), indent=1)
PYEOF
  sed -i "s|\"\.\./|\"$P/../|g" "$2"
}
# Every answer the plan's study 1 gave ($1: answers.csv) against what `blurcue run` records for the same
# participants and seeds (through export's trials.csv), protocol $2, observer $3.
same_as_run() {
  local answers=$1 protocol=$2 observer=$3 db=$W/run-$(basename "$2" .json).sqlite
  tail -n +2 "$answers" | cut -d, -f1,2 | sort -u | while IFS=, read -r id seed; do
    # The seed as answers.csv writes it (s<digits>, as export does): run takes it as written.
    $BC run "$protocol" --participant "$id" --seed "$seed" --db "$db" --observer "$observer" > /dev/null 2>&1 \
      || fail "run $id $seed"
  done
  $BC export --db "$db" --out "$W/tables-$(basename "$2" .json)" > /dev/null 2>&1 || fail "export"
  $PY - "$answers" "$W/tables-$(basename "$2" .json)/trials.csv" <<'PYEOF' || fail "answers differ ($protocol)"
import csv, sys
plan = {(r["participant"], int(r["trial_index"])): r["choice"] for r in csv.DictReader(open(sys.argv[1]))}
run = {}
for r in csv.DictReader(open(sys.argv[2])):
    status = r["status"]
    choice = {"timed_out": "none", "skipped": "skipped"}.get(status) or next(
        (r[c] for c in ("chosen_side", "chosen_interval", "yes_no", "rating", "adjusted_level") if r[c]), "")
    run[(r["participant"], int(r["trial_index"]))] = choice
if set(plan) != set(run):
    sys.exit(f"trials differ: plan {len(plan)}, run {len(run)}")
bad = [(k, plan[k], run[k]) for k in sorted(plan) if plan[k] != run[k]]
if bad:
    sys.exit(f"{len(bad)} of {len(plan)} answers differ, first {bad[:3]}")
kinds = sorted(set(plan.values()))
print(f"  {len(plan)} answers of {len({k[0] for k in plan})} participants identical; answers seen: {kinds}")
PYEOF
}

case $CASE in
same_as_run)
  # A plan's simulated participant answers exactly as `blurcue run --observer ... --seed` records: a pair with
  # can't tell and swapped sides (test 1), a QUEST+ whose deadline some answers miss (levels follow the answers), a
  # staircase with a stop rule (skipped trials) over moving balls, and a practice block run to a criterion.
  $BC plan "$P/test1-static-grids.json" --participants 3 --studies 1 --seed 7 --no-chart --out "$W/t1" > /dev/null 2>&1 \
    || fail "plan test1"
  same_as_run "$W/t1/answers.csv" "$P/test1-static-grids.json" sim
  variant "$P/quest-blur-difference.json" "$W/quest-deadline.json" 'p["timing"]["deadline_ms"] = 1000'
  $BC plan "$W/quest-deadline.json" --participants 2 --studies 1 --seed 8 --observer sim:lapse=0.1 --no-chart \
    --out "$W/q" > /dev/null 2>&1 || fail "plan quest"
  grep -q ",none$" "$W/q/answers.csv" || fail "the deadline case has no missed deadline"
  same_as_run "$W/q/answers.csv" "$W/quest-deadline.json" sim:lapse=0.1
  $BC plan "$P/staircase-ball-gain.json" --participants 2 --studies 1 --seed 9 --no-chart --out "$W/s" > /dev/null 2>&1 \
    || fail "plan staircase"
  grep -q ",skipped$" "$W/s/answers.csv" || fail "the staircase case skips nothing"
  same_as_run "$W/s/answers.csv" "$P/staircase-ball-gain.json" sim
  $BC plan "$P/pre-research-depth-matching.json" --participants 2 --studies 1 --seed 10 --no-chart --out "$W/d" \
    > /dev/null 2>&1 || fail "plan depth matching"
  same_as_run "$W/d/answers.csv" "$P/pre-research-depth-matching.json" sim
  echo "ok: plan's simulated participants answer as blurcue run records them (pair, QUEST+ with deadline, staircase with stop rule, depth matching in arcmin)" ;;
depth_slope)
  # Depth matching's slope test: observers given the power law c = 20 d^-0.5 (model=pixel) give a mean slope of -0.5
  # and a test that finds it; observers given no slope (0) are rejected at the test's level, alpha = 0.05, at every
  # N (within 3 binomial sds of 400 studies: 0.05 +- 0.033) - the t-test's size, not assumed but counted.
  $BC plan "$P/pre-research-depth-matching.json" --participants 6 --studies 400 --seed 3 --no-chart --out "$W/slope" \
    --observer sim:cutoff1m=20,slope=-0.5,sdlog=0.3,tol=0.05 > "$W/slope.out" 2>&1 || fail "plan: $(tail -2 "$W/slope.out")"
  $BC plan "$P/pre-research-depth-matching.json" --participants 6 --studies 400 --seed 4 --no-chart --out "$W/flat" \
    --observer sim:cutoff1m=20,slope=0,sdlog=0.3,tol=0.05 > "$W/flat.out" 2>&1 || fail "plan: $(tail -2 "$W/flat.out")"
  $PY - "$W/slope/plan.csv" "$W/flat/plan.csv" <<'PYEOF' || fail "slope rows"
import csv, sys
def rows(path):
    return [r for r in csv.DictReader(open(path)) if r["test"] == "slope_t"]
slope, flat = rows(sys.argv[1]), rows(sys.argv[2])
assert len(slope) == 6 and len(flat) == 6, (len(slope), len(flat))
b = float(slope[0]["expected_share"])
assert abs(b + 0.5) < 0.03, b
assert float(slope[1]["power"]) > 0.2 and float(slope[5]["power"]) > 0.95, [r["power"] for r in slope]
assert float(slope[0]["power"]) == 0 and slope[0]["wilson_width"] == "", slope[0]  # one participant: no test
for r in flat[1:]:
    assert abs(float(r["power"]) - 0.05) < 0.033, r
assert abs(float(flat[0]["expected_share"])) < 0.03, flat[0]
print(f"slope -0.5: mean b {b:.3f}, power at N = 2..6 {[r['power'][:5] for r in slope[1:]]}; slope 0: rejected "
      f"{[r['power'][:5] for r in flat[1:]]}")
PYEOF
  grep -q "cut-off ~ distance = depth matching" "$W/slope.out" || fail "summary: $(cat "$W/slope.out")"
  echo "ok: depth matching's slope test finds c = 20 d^-0.5 and keeps its level when there is no slope" ;;
power_exact)
  # A design whose answers are binomial with a known p: one condition (edge 5), 10 repetitions, a strict 2AFC
  # between no blur and 30 px (the observer's noise 0.001 px: it always prefers the side nearer the scene's own
  # blur, except in a lapse, a coin flip with probability 0.7): P(first source) = 0.7 / 2 + 0.3 x [first preferred],
  # 0.65 or 0.35. The report's test with participants as the unit: one participant - the exact binomial of their 10
  # answers, whose power has a closed form (P(X <= c) + P(X >= 10 - c) at the critical value c, computed here); two
  # to five - no p can fall below 0.05 (the sign-flip test's least p is 2 / 2^N), power 0; six - the sign-flip test
  # of their shares, its power estimated here by drawing 4000 studies of six Binomial(10, p) participants and testing
  # each with the report's own analysis/study_tests.py sign_flip_p (not the plan's C++), within 4.5 standard errors.
  variant "$P/test1-static-grids.json" "$W/binomial.json" '
p["factors"] = {"edge": [5]}; p["repetitions"] = 10; p["practice"] = {"count": 0}
p["sides"] = {"left": "none", "right": 30}; p["responses"]["cant_tell"] = None'
  $BC plan "$W/binomial.json" --participants 6 --studies 4000 --seed 3 --observer sim:jnd=0.001,bias=0,lapse=0.7 \
    --no-chart --out "$W/p" > "$W/out" 2> "$W/err" || fail "plan: $(tail -1 "$W/err")"
  $PY - "$W/p/plan.csv" "$(dirname "$0")/../analysis" <<'PYEOF' || fail "power differs from the report's test"
import csv, math, sys
import numpy as np
sys.path.insert(0, sys.argv[2])
import study_tests
rows = [r for r in csv.DictReader(open(sys.argv[1])) if r["test"] == "exact"]
assert len(rows) == 6, rows
share = float(rows[0]["expected_share"])
p = 0.65 if share > 0.5 else 0.35
assert abs(share - p) < 0.005, f"expected share {share}, closed form {p}"
pmf = lambda k, n, q: math.comb(n, k) * q ** k * (1 - q) ** (n - k)
c = max([c for c in range(5) if 2 * sum(pmf(j, 10, 0.5) for j in range(c + 1)) < 0.05], default=-1)
one = sum(pmf(j, 10, p) for j in range(c + 1)) + sum(pmf(j, 10, p) for j in range(10 - c, 11)) if c >= 0 else 0.0
rng = np.random.default_rng(38)
draws = rng.binomial(10, p, size=(4000, 6))
six = float(np.mean([study_tests.sign_flip_p(k, [10] * 6) < 0.05 for k in draws]))
expected = {1: one, 2: 0.0, 3: 0.0, 4: 0.0, 5: 0.0, 6: six}
for r in rows:
    n = int(r["participants"])
    got, want = float(r["power"]), expected[n]
    se = math.sqrt(max(want * (1 - want), 1e-4) / 4000) * (math.sqrt(2) if n == 6 else 1)
    print(f"  N = {n}: power {got:.4f}, expected {want:.4f}")
    assert abs(got - want) < 4.5 * se, f"N = {n}: {got} vs {want} (se {se:.4f})"
PYEOF
  echo "ok: the plan's power is the report's exact test's at every N (binomial, none, sign-flip)" ;;
same_seed)
  # The same seed gives the same plan, byte for byte, whatever the thread count; another seed another plan.
  for t in 1 2 3; do
    $BC plan "$P/test1-static-grids.json" --participants 5 --studies 20 --seed 11 --threads $t --no-chart \
      --out "$W/t$t" > "$W/out$t" 2> "$W/err$t" || fail "plan --threads $t: $(tail -1 "$W/err$t")"
  done
  for t in 2 3; do
    cmp "$W/t1/plan.csv" "$W/t$t/plan.csv" || fail "plan.csv with $t threads differs"
    cmp "$W/t1/answers.csv" "$W/t$t/answers.csv" || fail "answers.csv with $t threads differs"
    cmp <(head -n -1 "$W/out1") <(head -n -1 "$W/out$t") || fail "the summary with $t threads differs"
  done
  $BC plan "$P/test1-static-grids.json" --participants 5 --studies 20 --seed 12 --no-chart --out "$W/other" > /dev/null 2>&1
  cmp -s "$W/t1/plan.csv" "$W/other/plan.csv" && fail "another seed gave the same plan"
  echo "ok: seed 11 gives byte-identical plan.csv, answers.csv and summary with 1, 2 and 3 threads; seed 12 another" ;;
chart)
  # The chart through the analysis's Python: a real PNG, and the plan folder replaced whole by a second run.
  $BC plan "$P/test1-static-grids.json" --participants 4 --studies 10 --out "$W/c" > "$W/out" 2> "$W/err" \
    || fail "plan: $(tail -1 "$W/err")"
  [ "$(head -c 8 "$W/c/power.png" | od -An -tx1 | tr -d ' \n')" = 89504e470d0a1a0a ] || fail "power.png is no PNG"
  $PY -c "import xml.dom.minidom, sys; xml.dom.minidom.parse(sys.argv[1])" "$W/c/power.svg" || fail "power.svg"
  grep -q "stand-in for the report.s GLMM" "$W/out" || fail "summary names the stand-in"
  grep -q "smallest_n" "$W/c/plan.json" || fail "plan.json"
  echo "ok: power.png and power.svg drawn; plan.json written" ;;
prediction)
  # The report's Python prediction (analysis/prediction.py, the model's closed form) against the plan's simulated
  # answers to test 1 (the C++ observer, 4000 participants per edge): each edge's shares of first source, second
  # source and can't tell within 4.5 standard errors. The radii come from a run's own record of the same protocol.
  $BC plan "$P/test1-static-grids.json" --participants 20 --studies 200 --no-chart --out "$W/p" > /dev/null 2>&1 \
    || fail "plan"
  $BC run "$P/test1-static-grids.json" --participant P1 --db "$W/r.sqlite" --observer sim > /dev/null 2>&1 || fail "run"
  $BC export --db "$W/r.sqlite" --out "$W/tables" > /dev/null 2>&1 || fail "export"
  $PY - "$W/tables/trials.csv" "$W/p/plan.csv" "$(dirname "$0")/../analysis" <<'PYEOF' || fail "prediction"
import math, sys
import numpy as np, pandas as pd
sys.path.insert(0, sys.argv[3])
import prediction
t = pd.read_csv(sys.argv[1])
t = t[(t.practice == 0) & (t.swapped == 0)]
plan = pd.read_csv(sys.argv[2])
plan = plan[(plan.test == "exact") & (plan.participants == 20)]
worst = 0
for _, r in t.iterrows():
    shares = prediction.pair_choice(np.array([r.r_left_arcmin]), np.array([r.r_right_arcmin]), np.array([r.r_scene_arcmin]))
    p = plan[plan.condition == f"edge={int(r.edge)}"].iloc[0]
    for predicted, got in zip(shares, (p.share_first, p.share_second, p.share_cant_tell)):
        z = abs(got - predicted[0]) / math.sqrt(predicted[0] * (1 - predicted[0]) / 4000)
        worst = max(worst, z)
        assert z < 4.5, f"edge {r.edge}: plan {got:.4f}, predicted {predicted[0]:.4f} ({z:.1f} SE)"
print(f"  11 edges x 3 shares: the largest difference {worst:.1f} standard errors")
PYEOF
  echo "ok: the report's prediction matches the plan's simulated observer on every edge of test 1" ;;
threshold_truth)
  # QUEST+ plans its threshold, not its share correct: the observer's true threshold against the closed form worked
  # here from the observer model (the Weibull's threshold point of a 2AFC, P = 1 - 0.5 / e before lapses: the seen
  # blur E = sqrt((r / 2)^2 + 0.6^2) grows by (1 + 0.35)^(z(P) / z(0.75)) from the reference's, which a run records
  # in arcmin), the bias as mean - truth, the interval width as 2 t(0.975, N - 1) sd / sqrt(N) within the spread of
  # the studies' sds, and no share-correct binomial row (it had power 1 at N = 1: the procedure sets the share).
  $BC plan "$P/quest-blur-difference.json" --participants 8 --studies 60 --seed 5 --no-chart --out "$W/q" \
    > "$W/q.out" 2>&1 || fail "plan: $(tail -2 "$W/q.out")"
  $BC run "$P/quest-blur-difference.json" --participant P1 --db "$W/r.sqlite" --observer sim > /dev/null 2>&1 || fail "run"
  $BC export --db "$W/r.sqlite" --out "$W/tables" > /dev/null 2>&1 || fail "export"
  $PY - "$W/q/plan.csv" "$W/tables/trials.csv" <<'PYEOF' || fail "threshold rows"
import csv, math, sys
from scipy.stats import norm, t as student
rows = list(csv.DictReader(open(sys.argv[1])))
assert not [r for r in rows if r["test"] in ("exact", "participants_t")], "a procedure cell's share was tested"
th = [r for r in rows if r["test"] == "threshold"]
assert len(th) == 8 and th[0]["condition"] == "edge=9", [r["condition"] for r in th]
trials = [r for r in csv.DictReader(open(sys.argv[2])) if r["practice"] == "0"]
ref = {float(r["r_right_arcmin"] if r["test_side"] == "left" else r["r_left_arcmin"]) for r in trials}
assert len(ref) == 1, ref
r_ref = ref.pop()
k = norm.ppf(1 - 0.5 / math.e) / norm.ppf(0.75)
e_test = math.hypot(r_ref / 2, 0.6) * 1.35 ** k
truth = 2 * math.sqrt(e_test ** 2 - 0.36) - r_ref
got = float(th[0]["true_threshold"])
assert abs(got - truth) < 2e-4, (got, truth)  # the record rounds the reference to 1e-4 arcmin
mean, bias, sd = (float(th[0][c]) for c in ("mean_estimate", "bias", "sd_estimate"))
assert abs(bias - (mean - got)) < 1e-5 and sd > 0.05, th[0]
for r in th[2:]:
    n = int(r["participants"])
    width = 2 * student.ppf(0.975, n - 1) * sd / math.sqrt(n)
    assert abs(float(r["interval_width"]) - width) < 0.35 * width, (n, r["interval_width"], width)
print(f"  truth {got:.4f} arcmin (closed form {truth:.4f} from r_ref {r_ref}), mean estimate {mean:.3f}, "
      f"bias {bias:+.3f}, sd {sd:.3f}")
PYEOF
  grep -q "procedure cells: the threshold each estimates" "$W/q.out" || fail "summary: $(cat "$W/q.out")"
  # A truth outside the tested range is said in words, and no bias is printed or written.
  variant "$P/quest-blur-difference.json" "$W/narrow.json" 'p["blocks"][0]["procedure"]["threshold"] = [0.25, 0.5, 0.75, 1]'
  $BC plan "$W/narrow.json" --participants 3 --studies 2 --no-chart --out "$W/n" > "$W/n.out" 2>&1 \
    || fail "plan narrow: $(tail -2 "$W/n.out")"
  grep -q "edge=9: the true threshold is above the tested range (0.25 to 1), so no bias is given" "$W/n.out" \
    || fail "narrow summary: $(cat "$W/n.out")"
  $PY - "$W/n/plan.csv" <<'PYEOF' || fail "narrow rows"
import csv, sys
th = [r for r in csv.DictReader(open(sys.argv[1])) if r["test"] == "threshold"]
assert th and all(r["true_threshold"] == "" and r["bias"] == "" and r["mean_estimate"] != "" for r in th), th[0]
PYEOF
  # validate --plan: the shipped grid holds the observer; a slope grid of 1.5-5 does not, and the observer's slope there
  # is the closed form's: x dP/dx at the threshold x, over a Weibull's (1 - 0.5 - lapse / 2) / e, with
  # P = lapse / 2 + (1 - lapse) Phi(z75 ln(E(r + x) / E(r)) / ln 1.35) and d ln E / dx = (r + x) / 4 / E(r + x)^2.
  $BC validate "$P/quest-blur-difference.json" --plan > "$W/v.out" 2>&1 || fail "validate --plan shipped: $(tail -2 "$W/v.out")"
  variant "$P/quest-blur-difference.json" "$W/steep.json" 'p["blocks"][0]["procedure"]["slope"] = [1.5, 2.5, 3.5, 5]'
  set +e
  $BC validate "$W/steep.json" --plan > "$W/steep.out" 2>&1
  code=$?
  set -e
  [ "$code" = 3 ] || fail "validate --plan steep grid: exit $code, $(cat "$W/steep.out")"
  $PY - "$W/steep.out" "$W/tables/trials.csv" <<'PYEOF' || fail "validate --plan slope: $(cat "$W/steep.out")"
import csv, math, re, sys
from scipy.optimize import brentq
from scipy.stats import norm
text = open(sys.argv[1]).read().strip()
assert len(text.splitlines()) == 1 and "steep.json: /blocks/0/procedure/slope: the observer's Weibull slope" in text, text
said = float(re.search(r"threshold \(([0-9.]+)\) is ([0-9.]+), outside the slope grid 1.5 to 5", text).group(2))
row = next(r for r in csv.DictReader(open(sys.argv[2])) if r["practice"] == "0")
r = float(row["r_right_arcmin"] if row["test_side"] == "left" else row["r_left_arcmin"])
E = lambda v: math.hypot(v / 2, 0.6)
z75, lapse = norm.ppf(0.75), 0.04
P = lambda x: lapse / 2 + (1 - lapse) * norm.cdf(z75 * math.log(E(r + x) / E(r)) / math.log(1.35))
x = brentq(lambda v: P(v) - (0.5 + (0.5 - lapse / 2) * (1 - 1 / math.e)), 1e-6, 50)
z = z75 * math.log(E(r + x) / E(r)) / math.log(1.35)
slope = x * (1 - lapse) * norm.pdf(z) * z75 / math.log(1.35) * (r + x) / 4 / E(r + x) ** 2 * math.e / (0.5 - lapse / 2)
assert abs(said - slope) < 0.006, (said, slope)
print(f"  validate --plan: the observer's slope {said} (closed form {slope:.4f}) outside 1.5-5, exit 3")
PYEOF
  # Several cells outside the slope grid: each its own line (they were joined into one with a literal "\n").
  $PY - "$(dirname "$0")/data/quest-per-depth.json" "$P/quest-blur-difference.json" "$W/per-depth.json" <<'PYEOF'
import json, sys
p, shipped = json.load(open(sys.argv[1])), json.load(open(sys.argv[2]))
p["scene"] = shipped["scene"]  # the CLI tests' scene
json.dump(p, open(sys.argv[3], "w"))
PYEOF
  sed -i "s|\"\.\./|\"$P/../|g" "$W/per-depth.json"
  set +e
  $BC validate "$W/per-depth.json" --plan > "$W/per-depth.out" 2>&1
  code=$?
  set -e
  [ "$code" = 3 ] && [ "$(grep -c "per-depth.json: /blocks/0/procedure/slope: the observer's Weibull slope" "$W/per-depth.out")" = 3 ] \
    && ! grep -qF '\n' "$W/per-depth.out" || fail "validate --plan, three cells: exit $code, $(cat "$W/per-depth.out")"
  echo "ok: QUEST+ plans its threshold: the observer's truth by the closed form, bias, sd and interval width; a truth beyond the range in words; validate --plan checks the grid holds the observer's slope" ;;
difference_power)
  # The power of a declared difference: a second cell like edge=9 in the same participants, 0.5 arcmin more. Its
  # paired differences have sd sqrt(2) x the estimates' sd, so the t-test's power is the noncentral t's (df N - 1,
  # noncentrality 0.5 sqrt(N) / (sqrt 2 sd)) - estimates are not quite normal, so within 0.08; a declared difference
  # of 1e-9 is rejected at alpha (0.05 within 3 standard errors of 300 studies). A staircase's two speeds have one
  # true threshold (the relative level scales both radii alike): the model's own paired difference keeps alpha too.
  for d in 0.5 1e-9; do
    $BC plan "$P/quest-blur-difference.json" --participants 12 --studies 300 --seed 6 --difference $d --no-chart \
      --out "$W/d$d" > "$W/d$d.out" 2>&1 || fail "plan --difference $d: $(tail -2 "$W/d$d.out")"
  done
  $BC plan "$P/staircase-ball-gain.json" --participants 8 --studies 300 --seed 7 --no-chart --out "$W/s" \
    > "$W/s.out" 2>&1 || fail "plan staircase: $(tail -2 "$W/s.out")"
  $PY - "$W/d0.5/plan.csv" "$W/d1e-9/plan.csv" "$W/s/plan.csv" <<'PYEOF' || fail "difference power"
import csv, math, sys
from scipy.stats import nct, t as student
def rows(path, test):
    return [r for r in csv.DictReader(open(path)) if r["test"] == test]
sd = float(rows(sys.argv[1], "threshold")[0]["sd_estimate"])
power = rows(sys.argv[1], "second_cell_t")
assert len(power) == 12 and float(power[0]["difference"]) == 0.5, power[0]
for r in power[3:]:
    n = int(r["participants"])
    crit = student.ppf(0.975, n - 1)
    nc = 0.5 * math.sqrt(n) / (math.sqrt(2) * sd)
    expected = nct.sf(crit, n - 1, nc) + nct.cdf(-crit, n - 1, nc)
    assert abs(float(r["power"]) - expected) < 0.08, (n, r["power"], expected)
se = math.sqrt(0.05 * 0.95 / 300)
assert all(math.isnan(float(r["power"] or "nan")) for r in rows(sys.argv[2], "second_cell_t")[:2])  # N < 3: no test
for r in rows(sys.argv[2], "second_cell_t")[2:]:
    assert abs(float(r["power"]) - 0.05) < 3 * se + 0.005, ("size", r["participants"], r["power"])
own = [r for r in rows(sys.argv[3], "paired_t") if "model's own" in r["condition"]]
assert len(own) == 8 and abs(float(own[0]["difference"])) < 1e-9, own[0]
for r in own[2:]:
    assert abs(float(r["power"]) - 0.05) < 3 * se + 0.005, ("staircase size", r["participants"], r["power"])
print(f"  sd {sd:.3f}; power at N = 12 {power[-1]['power']} (noncentral t {expected:.3f}); size "
      f"{[r['power'][:5] for r in rows(sys.argv[2], 'second_cell_t')[2:]]}")
PYEOF
  echo "ok: a declared difference's power matches the noncentral t; a null difference keeps alpha" ;;
groups)
  # A between-subject design is compared, not pooled: each group's own t-test against chance and Welch's t-test of
  # the participants' shares between the groups; no pooled row. Participants alternate groups (balanced), so with 2
  # participants each group has one and no test can run (power 0); the Welch row's share is the groups' difference.
  $BC plan "$P/groups-and-info.json" --participants 6 --studies 100 --seed 8 --no-chart --out "$W/g" > "$W/g.out" 2>&1 \
    || fail "plan: $(tail -2 "$W/g.out")"
  $PY - "$W/g/plan.csv" <<'PYEOF' || fail "group rows"
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
assert not [r for r in rows if r["condition"] == "all"], "pooled over the groups"
est = [r for r in rows if r["test"] == "participants_t" and r["condition"] == "group=estimated"]
none = [r for r in rows if r["test"] == "participants_t" and r["condition"] == "group=no_blur"]
welch = [r for r in rows if r["test"] == "groups_t"]
assert len(est) == len(none) == len(welch) == 6, (len(est), len(none), len(welch))
assert welch[0]["condition"] == "group no_blur - estimated", welch[0]
assert float(welch[1]["power"]) == 0 and float(est[1]["power"]) == 0, (welch[1], est[1])
diff = float(none[0]["expected_share"]) - float(est[0]["expected_share"])
assert abs(float(welch[0]["expected_share"]) - diff) < 1e-5, (welch[0], diff)
assert float(welch[-1]["power"]) > float(welch[2]["power"]), [r["power"] for r in welch]
print(f"  groups' difference {diff:.3f}; Welch power at N = 3..6 {[r['power'][:5] for r in welch[2:]]}")
PYEOF
  grep -q "groups are compared, not pooled" "$W/g.out" || fail "summary: $(cat "$W/g.out")"
  # A procedure in two groups (each group its own copy of QUEST+'s block): the groups' thresholds compared by Welch,
  # the same true threshold in both (the same cell), and a declared difference compared instead of a second cell.
  variant "$P/quest-blur-difference.json" "$W/quest-groups.json" '
p["groups"] = {"names": ["a", "b"], "assign": "balanced"}
p["blocks"] = [dict(p["blocks"][0], name="quest-" + g, groups=[g]) for g in ("a", "b")]'
  $BC plan "$W/quest-groups.json" --participants 8 --studies 100 --seed 9 --difference 0.5 --no-chart \
    --out "$W/qg" > "$W/qg.out" 2>&1 || fail "plan quest groups: $(tail -2 "$W/qg.out")"
  $PY - "$W/qg/plan.csv" <<'PYEOF' || fail "threshold group rows"
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
truths = {r["condition"]: float(r["true_threshold"]) for r in rows if r["test"] == "threshold"}
assert set(truths) == {"quest-a: edge=9", "quest-b: edge=9"} and abs(truths["quest-a: edge=9"] - truths["quest-b: edge=9"]) < 1e-9, truths
own = [r for r in rows if r["test"] == "groups_t" and "model's own" in r["condition"]]
declared = [r for r in rows if r["test"] == "groups_t" and "declared +0.5" in r["condition"]]
assert len(own) == len(declared) == 8 and abs(float(own[0]["difference"])) < 1e-9, own[0]
assert float(declared[0]["difference"]) == 0.5 and not [r for r in rows if r["test"] == "second_cell_t"], declared[0]
assert float(declared[-1]["power"]) > float(own[-1]["power"]), (declared[-1]["power"], own[-1]["power"])
PYEOF
  echo "ok: groups are compared (per group and Welch between them), not pooled; a procedure's thresholds too" ;;
difference_meaningless)
  # A declared difference is planned only where it means something: from a known true threshold to a second one the
  # procedure can measure. --difference 1e308 (a 300-digit difference was printed), -200 % (a negative threshold), an
  # absolute difference on a staircase pinned at its bound and on a QUEST+ whose stimuli lie outside its threshold
  # grid (their estimates barely scatter: "power 1.000 at N = 2") are each said in a note, with no power row.
  variant "$P/quest-blur-difference.json" "$W/stimuli-low.json" 'p["blocks"][0]["procedure"]["stimuli"] = [0.01, 0.02, 0.03]'
  variant "$P/staircase-ball-gain.json" "$W/pinned.json" 'p["blocks"][0]["procedure"].update(start=3, min=2.9)'
  run_case() {  # name protocol difference expected-note
    $BC plan "$2" --participants 3 --studies 4 --seed 1 --difference "$3" --no-chart --out "$W/$1" > "$W/$1.out" 2>&1 \
      || fail "plan $1: $(tail -2 "$W/$1.out")"
    grep -qF "$4" "$W/$1.out" || fail "$1: no note '$4': $(cat "$W/$1.out")"
    ! grep -q "(declared\|second_cell_t  " "$W/$1.out" || fail "$1: a declared difference was planned: $(cat "$W/$1.out")"
    ! cut -d, -f1,2 "$W/$1/plan.csv" | grep -q "second_cell_t\|declared" || fail "$1: plan.csv has a declared row"
    ! grep -qi "nan\|inf\|e+" "$W/$1/plan.csv" || fail "$1: plan.csv: $(grep -i 'nan\|inf\|e+' "$W/$1/plan.csv" | head -2)"
  }
  run_case huge "$P/quest-blur-difference.json" 1e308 \
    "+ 1e+308) would be above the tested range (0.25 to 6)"
  grep -q "is not planned for edge=9: the second threshold (its true 1\.6[0-9]* + 1e+308)" "$W/huge.out" || fail "huge"
  run_case negative "$P/quest-blur-difference.json" -200% "would be below the tested range (0.25 to 6)"
  run_case stimuli "$W/stimuli-low.json" 0.1 \
    "edge=9: its true threshold is not measured: QUEST+'s stimuli (0.01 to 0.03) lie outside its threshold grid (0.25 to 6)"
  grep -q "edge=9 *difference_arcmin *- .* - " "$W/stimuli.out" || fail "stimuli: a truth or bias printed: $(cat "$W/stimuli.out")"
  run_case pinned "$W/pinned.json" 0.1 "its true threshold is below the tested range (2.9 to 3)"
  # An observer with 90 % lapses drives QUEST+ to the top of its grid (about 5.95 of 6): +0.5 shifts its estimates
  # past what QUEST+ can report (it had "power 1.000 at N = 3").
  variant "$P/quest-blur-difference.json" "$W/lapses.json" 'p["name"] = "quest-lapses"'
  printf '#!/bin/sh\nexec %s "$@" --observer sim:lapse=0.9\n' "$BC" > "$W/bc-lapses" && chmod +x "$W/bc-lapses"
  BC_SAVED=$BC BC=$W/bc-lapses
  run_case lapses "$W/lapses.json" 0.5 "shifted by it would be above the tested range (0.25 to 6), which the procedure cannot report"
  BC=$BC_SAVED
  # Still planned where it means something: 0.5 arcmin from a truth of 1.6 is within 0.25 to 6.
  $BC plan "$P/quest-blur-difference.json" --participants 3 --studies 4 --seed 1 --difference 0.5 --no-chart \
    --out "$W/fine" > "$W/fine.out" 2>&1 || fail "plan fine"
  grep -q "second_cell_t  edge=9 vs a second cell +0.5 difference_arcmin" "$W/fine.out" || fail "fine: $(cat "$W/fine.out")"
  echo "ok: a declared difference that means nothing (beyond the range, from an unknown truth) is said in a note, not powered" ;;
units_and_groups)
  # Only what can be compared is: two QUEST+ cells with thresholds in different units (arcmin, a relative
  # difference) had a paired t-test of arcmin minus fraction ("-1.035, power 1.000 at N = 4"), and a group running no
  # pair block had a t-test and a Welch test with no values ("power 0.000"). Now a note says each, and no such row.
  variant "$P/quest-blur-difference.json" "$W/units.json" '
import copy
c = copy.deepcopy(p["blocks"][0])
c["name"] = "quest-rel"
c["procedure"].update(variable="relative_difference", stimuli=[0.05, 0.1, 0.2, 0.3, 0.5, 0.7, 1, 1.5, 2],
                      threshold=[0.05, 0.1, 0.2, 0.3, 0.5, 0.7, 1, 1.5])
p["blocks"].append(c)'
  variant "$P/quest-blur-difference.json" "$W/half.json" '
p["groups"] = {"names": ["a", "b"], "assign": "balanced"}
p["blocks"][0]["groups"] = ["a"]
p["blocks"].append({"name": "pairs", "groups": ["b"], "factors": {"edge": [1, 9]},
                    "sides": {"left": "measured", "right": "estimated"}})'
  for v in units half; do
    $BC plan "$W/$v.json" --participants 6 --studies 10 --seed 1 --no-chart --out "$W/$v" > "$W/$v.out" 2>&1 \
      || fail "plan $v: $(tail -2 "$W/$v.out")"
  done
  grep -q "note: quest-rel: edge=9 and quest: edge=9 are not compared: their thresholds are in different units (relative_difference, difference_arcmin)" \
    "$W/units.out" || fail "units: $(cat "$W/units.out")"
  ! cut -d, -f1 "$W/units/plan.csv" | grep -q paired_t || fail "units: a paired_t row across units"
  grep -q "note: more_blurred is not compared between groups: group a runs no block that gives it" "$W/half.out" \
    || fail "half: $(cat "$W/half.out")"
  ! grep -q "group=a\|group b - a" "$W/half/plan.csv" || fail "half: a row for group a's missing pairs"
  grep -q "^participants_t,group=b," "$W/half/plan.csv" || fail "half: no row for group b"
  echo "ok: thresholds in different units and a group without the measure are not compared (a note says so)" ;;
groups_shared_block)
  # A block that both groups run is planned per group, not pooled: its conditions (a pair's binomial per edge, a
  # QUEST+ cell's threshold) were one row mixing both groups' participants. Now each is "group=NAME: ...", the
  # groups' thresholds compared by Welch under the cell's own name, and the rows the same with 1 and 2 threads.
  variant "$P/groups-and-info.json" "$W/shared.json" 'p["blocks"] = [{"name": "shared", "sides": {"left": "measured", "right": "estimated"}}]'
  variant "$P/quest-blur-difference.json" "$W/quest-shared.json" 'p["groups"] = {"names": ["a", "b"], "assign": "balanced"}'
  for v in shared quest-shared; do
    for t in 1 2; do
      $BC plan "$W/$v.json" --participants 6 --studies 10 --seed 2 --threads $t --difference 0.5 --no-chart \
        --out "$W/$v-$t" > "$W/$v-$t.out" 2>&1 || fail "plan $v: $(tail -2 "$W/$v-$t.out")"
    done
    cmp -s "$W/$v-1/plan.csv" "$W/$v-2/plan.csv" || fail "$v: plan.csv differs between 1 and 2 threads"
  done
  $PY - "$W/shared-1/plan.csv" "$W/quest-shared-1/plan.csv" <<'PYEOF' || fail "shared block rows"
import csv, sys
pairs = list(csv.DictReader(open(sys.argv[1])))
binomial = sorted({r["condition"] for r in pairs if r["test"] == "exact"})
assert binomial and all(c.startswith(("group=estimated: edge=", "group=no_blur: edge=")) for c in binomial), binomial
assert len(binomial) == 12, binomial
quest = list(csv.DictReader(open(sys.argv[2])))
cells = {r["condition"] for r in quest if r["test"] == "threshold"}
assert cells == {"group=a: edge=9", "group=b: edge=9"}, cells
welch = {r["condition"] for r in quest if r["test"] == "groups_t"}
assert welch == {"group b - a: edge=9 (the model's own)", "group b - a: edge=9 (declared +0.5 difference_arcmin)"}, welch
# Each group's interval width at N = 6 comes from its own 3 participants, never from all 6.
for r in quest:
    if r["test"] == "threshold" and r["participants"] == "6":
        assert float(r["mean_trials"]) == 3, r
PYEOF
  echo "ok: a block both groups run is planned per group (shares and thresholds), compared by Welch, not pooled" ;;
design_warnings)
  # A staircase of 8 trials never gives the report a threshold (fewer than 10 answers is not determined; 12 already
  # do, with wide intervals): validate --plan and plan say so with a WARNING naming the cell and the share; the
  # plan's determined share is the share of simulated tracks the report's rule determines.
  variant "$P/staircase-ball-gain.json" "$W/short.json" 'p["blocks"][0]["procedure"].update(trials=8); p["blocks"][0]["procedure"].pop("stop")'
  $BC validate "$W/short.json" --plan > "$W/validate.out" 2>&1 || fail "validate --plan: $(tail -2 "$W/validate.out")"
  grep -q "WARNING: from_edge=3 speed_cm_s=1.8 to_edge=8: only [0-9]* % of tracks determine their threshold" \
    "$W/validate.out" || fail "no warning from validate --plan: $(grep -i procedure "$W/validate.out")"
  $BC plan "$W/short.json" --participants 10 --studies 10 --no-chart --out "$W/p" > "$W/plan.out" 2>&1 \
    || fail "plan: $(tail -2 "$W/plan.out")"
  grep -q "WARNING: from_edge=3 speed_cm_s=3 to_edge=8: only" "$W/plan.out" || fail "no warning from plan"
  $PY - "$W/p/plan.csv" <<'PYEOF' || fail "determined share"
import csv, sys
rows = [r for r in csv.DictReader(open(sys.argv[1])) if r["test"] == "threshold" and r["participants"] == "10"]
assert len(rows) == 2 and all(float(r["determined_share"]) < 0.8 for r in rows), rows
PYEOF
  # No track determined (8 answers), so no interval to hold the truth: the sentence says so and gives the truth, the
  # plan's true_threshold of the cell (it used to end at "the observer's true threshold is ").
  $PY - "$W/validate.out" "$W/p/plan.csv" <<'PYEOF' || fail "validate --plan's cell lines: $(grep "procedure cell" "$W/validate.out")"
import csv, re, sys
lines = [l.rstrip("\n") for l in open(sys.argv[1]) if l.startswith("  procedure cell ")]
truth = {r["condition"]: float(r["true_threshold"]) for r in csv.DictReader(open(sys.argv[2]))
         if r["test"] == "threshold" and r["participants"] == "10"}
assert len(lines) == 2, lines
for line in lines:
    m = re.fullmatch(r"  procedure cell (.+): 0 % of 200 simulated tracks determine their threshold; so no interval to "
                     r"check against the observer's true threshold, ([0-9.e+-]+) (\w+)", line)
    assert m, line
    assert abs(float(m.group(2)) - truth[m.group(1)]) <= 0.0051 * truth[m.group(1)], (line, truth)
print("validate --plan:", lines)
PYEOF
  echo "ok: a design that rarely determines its threshold is warned of by validate --plan and plan" ;;
more_blurred_as_report)
  # The plan's share of a pair is the report's: the side showing the larger blur radius (chose_more_blurred), not the
  # design's first source (except for the thesis's own studies, whose report view tests the first source). A comparison whose blurrier source changes between its levels (measured against none, and
  # none against measured): before, the plan gave 0.00 at none-vs-measured edge 9 (the first source, none, chosen in
  # no decisive answer) where the report's table says 1.00 for the same answers. The truth: the report's own
  # conditions table on the same participants' answers, recorded by blurcue run with the plan's seeds.
  variant "$P/test1-static-grids.json" "$W/bc.json" 'p.update(name="blurrier-changes", repetitions=4, counterbalance="swap_copies", factors={"edge": [2, 9], "comparison": [{"left": "measured", "right": "none"}, {"left": "none", "right": "measured"}]}); p.pop("sides"); p.pop("practice")'
  $BC plan "$W/bc.json" --participants 3 --studies 1 --seed 5 --no-chart --out "$W/p" > "$W/plan.out" 2>&1 \
    || fail "plan: $(tail -2 "$W/plan.out")"
  grep -q "more blurred: second source" "$W/plan.out" || fail "the summary does not name the blurrier source"
  same_as_run "$W/p/answers.csv" "$W/bc.json" sim > /dev/null
  MPLCONFIGDIR=$W/mpl $BC report --db "$W/run-bc.sqlite" --out "$W/report" --bench "$W/no-bench" --boot 40 \
    > /dev/null 2> "$W/err" || fail "report: $(tail -3 "$W/err")"
  $PY - "$W/p/plan.csv" "$W/report/blurrier-changes-simulated-conditions.csv" <<'PYEOF' || fail "shares differ"
import csv, json, re, sys
plan = {}
for r in csv.DictReader(open(sys.argv[1])):
    if r["test"] == "exact" and r["participants"] == "3":
        m = re.fullmatch(r"comparison=(\{.*\}) edge=(\d+)", r["condition"])
        level = ";".join(f"{k}={v}" for k, v in sorted(json.loads(m[1]).items()))
        plan[(level, m[2])] = (float(r["expected_share"]), r["more_blurred_source"])
report = {(r["comparison"], r["edge"]): float(r["share"]) for r in csv.DictReader(open(sys.argv[2]))}
assert set(plan) == set(report) and len(plan) == 4, (sorted(plan), sorted(report))
for key, (share, source) in plan.items():
    assert abs(share - report[key]) < 1e-6, (key, share, report[key])
    assert source == ("first" if key[0] == "left=measured;right=none" else "second"), (key, source)
far = report[("left=none;right=measured", "9")]
assert far > 0.5, far  # the blurred side is seen at edge 9, though it is the second source
print(f"  the plan's 4 shares are the report's ({', '.join(f'{k[0]} edge {k[1]}: {v[0]:.3f}' for k, v in sorted(plan.items()))})")
PYEOF
  # The thesis's own test 1 keeps the first source: its report view (forced_choice.py) tests that share.
  $BC plan "$P/test1-static-grids.json" --participants 3 --studies 1 --seed 5 --no-chart --out "$W/t1" > /dev/null 2>&1 \
    || fail "plan test1"
  same_as_run "$W/t1/answers.csv" "$P/test1-static-grids.json" sim > /dev/null
  MPLCONFIGDIR=$W/mpl $BC report --db "$W/run-test1-static-grids.sqlite" --out "$W/report1" --bench "$W/no-bench" \
    --boot 40 > /dev/null 2> "$W/err" || fail "report test1: $(tail -3 "$W/err")"
  $PY - "$W/t1/plan.csv" "$W/report1/test1-per-edge.csv" <<'PYEOF' || fail "test 1 shares differ"
import csv, math, sys
plan = {r["condition"]: r for r in csv.DictReader(open(sys.argv[1])) if r["test"] == "exact" and r["participants"] == "3"}
report = {f"edge={r['edge']}": r for r in csv.DictReader(open(sys.argv[2]))}
assert set(plan) == set(report) and len(plan) == 11, (sorted(plan), sorted(report))
for edge, r in plan.items():
    assert r["measure"] == "first_source", r
    want = report[edge]["share_first_of_decisive"]
    assert (r["expected_share"] == "") == (want in ("", "nan")), (edge, r["expected_share"], want)
    if want not in ("", "nan"):
        assert abs(float(r["expected_share"]) - float(want)) < 1e-6, (edge, r["expected_share"], want)
print("  test 1: the first source's share per edge, as its report view")
PYEOF
  echo "ok: plan's share of a pair is the report's chose_more_blurred, the blurrier source named; test 1's the first source, as its report" ;;
*) fail "unknown case $CASE" ;;
esac
