#!/usr/bin/env bash
# kill -9 of track, ar and init while they write over an earlier output (issue 39): usage:
#   outputs_take_kill_test.sh CASE BLURCUE DIR      CASE: track | ar | init
# Two reference outputs A and B are made first; then the command is started KILLS times (20), writing A or B in
# turn over what is there, and killed after a random delay within one run's time, every other one near its end
# (seeded: OUTPUTS_KILL_SEED, printed).
# After each kill the output must be exactly one whole reference (tests/outputs_same.py: every file, timings aside) -
# the earlier one or the new one, never a mix and never half - or, for init, which never overwrites, none at all.
# ar's video, CSV and frames folder are three paths moved in one after the other: each must be whole (old or new);
# a kill between the moves is allowed and counted.
# Then a rerun must succeed, and leave nothing of the killed runs beside its output.
set -euo pipefail
CASE=$1 BC=$2 DIR=$3
W=$DIR/outputs-kill-$CASE
rm -rf "$W" && mkdir -p "$W"
source "$(dirname "$0")/lib.sh"
SAME="$PY $(dirname "$0")/outputs_same.py"
KILLS=${OUTPUTS_KILL_COUNT:-20}
SEED=${OUTPUTS_KILL_SEED:-39}
RANDOM=$SEED
echo "seed $SEED (OUTPUTS_KILL_SEED), $KILLS kills"

# run WHICH OUT: the command writing reference WHICH (a or b) to OUT. It ends in exec, so that, started with &, $! is
# the command itself (a kill of a subshell would leave it running); called in the foreground, it runs in ( ).

# Two small takes that differ in length and motion, each tracked (ar draws on take A).
takes() {
  $BC synth-take --out "$W/take-a" --frames 3 --supersample 1 --seed 1 --quiet
  $BC synth-take --out "$W/take-b" --frames 4 --supersample 1 --seed 2 --from-lateral-mm -10 --to-lateral-mm 10 --quiet
}
case $CASE in
track)
  takes
  run() { exec $BC track "$W/take-$1/take.avi" --camera "$W/take-$1/camera.json" --out "$2" --quiet; }
  OUT=$W/out ;;
ar)
  takes
  $BC track "$W/take-a/take.avi" --camera "$W/take-a/camera.json" --out "$W/track" --quiet
  # The video, its CSV and the frames folder together in one folder: the three are one output.
  run() {
    mkdir -p "$2"
    local ball=$([ $1 = a ] && echo 50,125 || echo 110,100)
    exec $BC ar "$W/take-a/take.avi" --track "$W/track" --ball $ball --out "$2/ar.avi" --frames "$2/frames" --quiet
  }
  OUT=$W/out ;;
init)
  # A study on a photo of one's own (here a frame of each take): the whole of init - copies, camera, calibrate,
  # protocol, README, validate - in about a second, where a synthetic scene takes five.
  takes
  run() { exec $BC init "$2" --photo "$W/take-$1/frame-0000.png" --camera "$W/take-$1/camera.json" > /dev/null; }
  OUT=$W/study ;;
*) fail "unknown case $CASE" ;;
esac

# The references under the output's own name (init's README names its folder).
REF_A=$W/ref-a/$(basename "$OUT") REF_B=$W/ref-b/$(basename "$OUT")
mkdir -p "$W/ref-a" "$W/ref-b"
start=$(date +%s%N)
(run a "$REF_A") > /dev/null
took_ms=$((($(date +%s%N) - start) / 1000000))
(run b "$REF_B") > /dev/null
[ "$($SAME "$REF_A" "$REF_B")" != 0 ] || fail "the two references are alike"
[ "$($SAME "$REF_A" "$REF_A")" = 0 ] || fail "a reference differs from itself"
# An earlier output to write over (init: none; it never overwrites).
[ $CASE = init ] || (run a "$OUT") > /dev/null
echo "one run: $took_ms ms"

killed=0 old=0 new=0 none=0 between=0
for i in $(seq 1 "$KILLS"); do
  if [ $CASE = init ]; then which=$([ $((i % 2)) = 1 ] && echo a || echo b); before=none
  else before=$($SAME "$OUT" "$REF_A" "$REF_B"); which=$([ "$before" = 0 ] && echo b || echo a); fi
  # Every other kill near the end, where the output is written: anywhere in the run, or in 70-120 % of it.
  if [ $((i % 2)) = 1 ]; then delay_ms=$((RANDOM % (took_ms + 1)))
  else delay_ms=$((took_ms * 7 / 10 + RANDOM % (took_ms / 2 + 1))); fi
  run $which "$OUT" > /dev/null 2>&1 &
  pid=$!
  sleep "$(printf '%d.%03d' $((delay_ms / 1000)) $((delay_ms % 1000)))"
  kill -9 $pid 2>/dev/null && killed=$((killed + 1)) || true
  wait $pid 2>/dev/null || true
  after=$($SAME "$OUT" "$REF_A" "$REF_B")
  want=$([ $which = a ] && echo 0 || echo 1)
  if [ $CASE = ar ] && [ "${after:0:4}" = none ]; then
    # ar's three outputs are three paths of the user's choosing, moved in one after the other (no one rename can
    # swap them together): each must be whole, the earlier or the new, and a kill between the moves is counted.
    for part in ar.avi ar.csv frames; do
      got=$($SAME "$OUT/$part" "$REF_A/$part" "$REF_B/$part")
      [ "${got:0:4}" != none ] || fail "ar killed after $delay_ms ms (kill $i) left $part half written: $got"
    done
    between=$((between + 1)); after=$want
  fi
  if [ $CASE = init ]; then
    if [ -e "$OUT" ]; then
      [ "$after" = "$want" ] || fail "init killed after $delay_ms ms left a study that is not whole: $after"
      new=$((new + 1)); rm -rf "$OUT"
    else none=$((none + 1)); fi
  elif [ "$after" = "$before" ]; then old=$((old + 1))
  elif [ "$after" = "$want" ]; then new=$((new + 1))
  else fail "$CASE killed after $delay_ms ms (kill $i, writing $which over ref $before) left neither the earlier output nor the new one: $after"
  fi
done

# A rerun succeeds, is whole, and removes what the killed runs left beside it.
(run b "$OUT") > /dev/null 2> "$W/rerun.err" || fail "the rerun failed: $(cat "$W/rerun.err")"
[ "$($SAME "$OUT" "$REF_B")" = 0 ] || fail "the rerun's output is not whole: $($SAME "$OUT" "$REF_B")"
left=$(cd "$(dirname "$OUT")" && ls -A | grep -E '\.(partial|tmp|old)-[0-9]+' || true)
[ $CASE = ar ] && left="$left$(cd "$OUT" && ls -A | grep -E '\.(partial|tmp|old)-[0-9]+' || true)"
[ -z "$left" ] || fail "left after the rerun: $left"
if [ $CASE = init ]; then
  echo "ok: init killed $killed of $KILLS times at random points: $none left no study, $new a whole one; the rerun" \
       "made a whole study and removed every leftover"
else
  echo "ok: $CASE killed $killed of $KILLS times at random points over an earlier output: $old left the earlier" \
       "output, $new the whole new one$([ $CASE = ar ] && echo " (of which $between between the moves of its three" \
       "outputs, each whole)" || echo ", never a mix"); the rerun was whole and removed every leftover"
fi
