#!/usr/bin/env bash
# The report's thresholds against 30 simulated observers of drawn sensitivity (Weber fraction 0.25-0.7, seeded) on a
# procedure protocol: tests/threshold_coverage_check.py works out each observer's true threshold from docs/observer.md
# and checks the share determined, the intervals' coverage and the mean relative error.
# Usage: threshold_coverage_test.sh BLURCUE PROTOCOL KIND SCRATCH N [CHANGE]
#   FPS (environment, default 2): --sim-fps; 2 keeps frames of 0.5 s, short of any response deadline (at 0.2 every
#   QUEST+ answer timed out); the staircase protocol has none and runs at 0.2 (fewer frames rendered)
#   CHANGE: a Python statement on the parsed protocol p (a variant written beside PROTOCOL, its relative paths kept).
set -euo pipefail
BC=$1 PROTOCOL=$2 KIND=$3 DIR=$4 N=$5 CHANGE=${6:-} FPS=${FPS:-2}
rm -rf "$DIR" && mkdir -p "$DIR"
if [ -n "$CHANGE" ]; then
  variant=$(dirname "$PROTOCOL")/_coverage-$(basename "$DIR").json
  /usr/bin/python3 - "$PROTOCOL" "$variant" "$CHANGE" <<'PYEOF'
import json, sys
p = json.load(open(sys.argv[1]))
exec(sys.argv[3])
json.dump(p, open(sys.argv[2], "w"), indent=1)
PYEOF
  PROTOCOL=$variant
  trap 'rm -f "$variant"' EXIT  # beside the copied protocols, not left for another test to list
fi
weber=$(/usr/bin/python3 -c "import random; r = random.Random(38); print(' '.join(f'{r.uniform(0.25, 0.7):.3f}' for _ in range($N)))")
i=0
for w in $weber; do
  i=$((i + 1))
  "$BC" run "$PROTOCOL" --participant "P$i" --db "$DIR/record.sqlite" --sim-fps "$FPS" \
    --observer "sim:weber=$w,side=0,blurrier=0" > /dev/null 2> "$DIR/run.log" || { cat "$DIR/run.log"; exit 1; }
done
"$BC" export --db "$DIR/record.sqlite" --out "$DIR/export" > /dev/null
# What the plan predicts for the middle observer (Weber fraction 0.475): its share of tracks determined must lie
# within 15 points of what the report determines on the 30.
"$BC" plan "$PROTOCOL" --participants 10 --studies 10 --seed 3 --observer "sim:weber=0.475,side=0,blurrier=0" \
  --no-chart --out "$DIR/plan" > "$DIR/plan.log" 2>&1 || { cat "$DIR/plan.log"; exit 1; }
/usr/bin/python3 "$(dirname "$0")/threshold_coverage_check.py" "$DIR/export" "$KIND" "$DIR/plan/plan.csv"
