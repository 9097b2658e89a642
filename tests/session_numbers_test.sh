#!/usr/bin/env bash
# End-to-end tests of sessions numbered per participant and protocol versions kept apart (blurcue run, export):
# usage: session_numbers_test.sh CASE BLURCUE DIR (DIR as for session_test.sh: protocols/ and the scene they show).
set -euo pipefail
CASE=$1 BC=$2 DIR=$3
P=$DIR/protocols
W=$DIR/session-numbers-$CASE
rm -rf "$W" && mkdir -p "$W"
source "$(dirname "$0")/lib.sh"
# test1-static-grids as $2 with `python` assignments $3 applied (p: the protocol), its paths made absolute.
variant() {
  $PY - "$P/$1.json" "$2" "$3" <<'PYEOF'
import json, sys
p = json.load(open(sys.argv[1]))
exec(sys.argv[3])
json.dump(p, open(sys.argv[2], "w"), indent=2)
PYEOF
  sed -i "s|\"\.\./|\"$P/../|g" "$2"
}

case $CASE in
again)
  # --again twice: the participant's sessions 1, 2 and 3, each with a seed of its own (session 1 the default seed of
  # before), so the second is no copy of the first; the numbers in run's summary and in trials.csv. A --seed an
  # earlier session used is refused (exit 3), saying why and what to do.
  $BC run "$P/test1-static-grids.json" --participant A1 --db "$W/s.sqlite" --observer sim > "$W/out1"
  $BC run "$P/test1-static-grids.json" --participant A1 --db "$W/s.sqlite" --observer sim --again > "$W/out2"
  $BC run "$P/test1-static-grids.json" --participant A1 --db "$W/s.sqlite" --observer sim --again > "$W/out3"
  for n in 1 2 3; do
    grep -q "participant A1, session $n, the participant's session $n, seed" "$W/out$n" \
      || fail "summary $n: $(cat "$W/out$n")"
  done
  [ "$(sql "$W/s.sqlite" "SELECT count(DISTINCT seed) FROM sessions")" = 3 ] || fail "seeds: $(sql "$W/s.sqlite" "SELECT seed FROM sessions")"
  orders=$(sql "$W/s.sqlite" "SELECT count(DISTINCT o) FROM (SELECT group_concat(json_extract(factors, '$.edge')) o
           FROM (SELECT * FROM trials ORDER BY trial_index) GROUP BY session_id)")
  [ "$orders" = 3 ] || fail "the sessions' trial orders: $orders distinct of 3"
  $BC export --db "$W/s.sqlite" --out "$W/tables" > /dev/null
  $PY - "$W/tables/trials.csv" "$W/s.sqlite" <<'PYEOF' || fail "session numbers in trials.csv"
import csv, sqlite3, sys
rows = list(csv.DictReader(open(sys.argv[1])))
numbers = sorted({(r["session_id"], r["session_number"], r["protocol_version"], r["seed"]) for r in rows})
assert [n[:3] for n in numbers] == [("1", "1", "1"), ("2", "2", "1"), ("3", "3", "1")], numbers
assert len({n[3] for n in numbers}) == 3, numbers
# Session 1 keeps the seed of before: FNV-1a 64 of "STUDY/PARTICIPANT".
h = 0xcbf29ce484222325
for b in b"test1-static-grids/A1":
    h = ((h ^ b) * 0x100000001b3) % 2**64
assert numbers[0][3] == "s%d" % h, (numbers[0], h)
assert all(r["cell"] == "" for r in rows), "no procedure, no cell"
PYEOF
  seed=$($PY -c "print($(sql "$W/s.sqlite" "SELECT seed FROM sessions WHERE session_number = 2") % 2**64)")
  set +e
  $BC run "$P/test1-static-grids.json" --participant A1 --db "$W/s.sqlite" --observer sim --again --seed "$seed" \
    > /dev/null 2> "$W/err"
  code=$?
  set -e
  [ $code = 3 ] || fail "a used seed: exit $code"
  [ "$(wc -l < "$W/err")" = 1 ] || fail "one line: $(cat "$W/err")"
  grep -q -- "--seed $seed is the seed of participant A1 of study test1-static-grids's session number 2 (session 2): a session with it repeats that session's trial order; leave out --seed" "$W/err" \
    || fail "message: $(cat "$W/err")"
  [ "$(sql "$W/s.sqlite" "SELECT count(*) FROM sessions")" = 3 ] || fail "a refused session was recorded"
  echo "ok: --again twice gave sessions 1, 2, 3 with three seeds and three orders, in run's summary and trials.csv; a used --seed refused" ;;
protocol_version)
  # A protocol changed under the same study name and version is refused (exit 3, one line naming the study, the
  # version, the first pointer that differs with both values, and the way out); raised, it is recorded beside the
  # first and every row of trials.csv says which version its session ran; a lower version with another text is refused.
  variant test1-static-grids "$W/v1.json" 'pass'
  variant test1-static-grids "$W/changed.json" 'p["timing"]["inter_trial_ms"] = 300'
  variant test1-static-grids "$W/v2.json" 'p["timing"]["inter_trial_ms"] = 300; p["version"] = 2'
  $BC run "$W/v1.json" --participant V1 --db "$W/s.sqlite" --observer sim > /dev/null
  set +e
  $BC run "$W/changed.json" --participant V2 --db "$W/s.sqlite" --observer sim > /dev/null 2> "$W/err"
  code=$?
  set -e
  [ $code = 3 ] || fail "changed protocol, same version: exit $code"
  [ "$(cat "$W/err")" = "blurcue: $W/s.sqlite: study test1-static-grids records protocol version 1 with another text (/timing/inter_trial_ms: 500 in the record, 300 now); raise \"version\" to 2 to record it as a new version, or use another record (--db)" ] \
    || fail "message: $(cat "$W/err")"
  [ "$(sql "$W/s.sqlite" "SELECT count(*) FROM sessions")" = 1 ] || fail "a refused session was recorded"
  $BC run "$W/v2.json" --participant V2 --db "$W/s.sqlite" --observer sim > /dev/null
  $BC run "$W/v1.json" --participant V3 --db "$W/s.sqlite" --observer sim > /dev/null  # version 1's own text
  variant test1-static-grids "$W/v1b.json" 'p["timing"]["inter_trial_ms"] = 700'
  set +e
  $BC run "$W/v1b.json" --participant V4 --db "$W/s.sqlite" --observer sim > /dev/null 2> "$W/err"
  code=$?
  set -e
  [ $code = 3 ] && grep -q "records protocol version 2, this protocol says version 1 with another text (/timing/inter_trial_ms: 300 in the record, 700 now); raise \"version\" to 3" "$W/err" \
    || fail "lower version: exit $code, $(cat "$W/err")"
  $BC export --db "$W/s.sqlite" --out "$W/tables" > /dev/null
  $PY - "$W/tables/trials.csv" "$W/tables/codebook.csv" <<'PYEOF' || fail "versions in trials.csv"
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
got = sorted({(r["participant"], r["protocol_version"]) for r in rows})
assert got == [("V1", "1"), ("V2", "2"), ("V3", "1")], got
book = {r["column"]: r for r in csv.DictReader(open(sys.argv[2])) if r["table"] == "trials.csv"}
assert book["edge"]["role"] == "within" and book["edge"]["allowed"] == "1|2|3|4|5|6|7|8|9|10|11", book["edge"]
assert book["practice"]["role"] == "practice", book["practice"]
PYEOF
  echo "ok: a changed protocol under version 1 refused naming /timing/inter_trial_ms; version 2 recorded beside it; a lower version refused; trials.csv says each session's version" ;;
conditions_version)
  # A conditions table is part of the protocol's version (issue 24): a table edited between two sessions under the
  # same version is refused naming the table, and a label cell stays the text it is (007 and 7: two ids in trials.csv).
  printf 'edge,left,right,label_stim\n1,measured,estimated,007\n2,estimated,measured,7\n' > "$W/t.csv"
  variant test1-static-grids "$W/c.json" 'del p["factors"], p["sides"], p["counterbalance"]; p["conditions"] = "t.csv"; p["practice"]["count"] = 0'
  $BC run "$W/c.json" --participant C1 --db "$W/s.sqlite" --observer sim > /dev/null
  printf 'edge,left,right,label_stim\n1,measured,estimated,007\n3,estimated,measured,7\n' > "$W/t.csv"
  set +e
  $BC run "$W/c.json" --participant C2 --db "$W/s.sqlite" --observer sim > /dev/null 2> "$W/err"
  code=$?
  set -e
  [ $code = 3 ] && grep -q 'records protocol version 1 with another text (/recorded_conditions/t.csv: ' "$W/err" \
    || fail "an edited table under the same version: exit $code, $(cat "$W/err")"
  $BC export --db "$W/s.sqlite" --out "$W/tables" > /dev/null
  $PY - "$W/tables/trials.csv" <<'PYEOF' || fail "label cells in trials.csv"
import csv, sys
rows = [r for r in csv.DictReader(open(sys.argv[1])) if r["practice"] == "0"]
got = sorted((r["edge"], r["label_stim"]) for r in rows)
assert got == [("1", "007"), ("2", "7")], got
PYEOF
  echo "ok: an edited conditions table under version 1 refused naming /recorded_conditions/t.csv; 007 and 7 kept apart in trials.csv" ;;
again_group)
  # A between-subject participant's --again session stays in their group (issue 23's review): balanced assignment
  # used to give it the group with the fewest sessions, so one person saw both groups' conditions.
  G="$P/groups-and-info.json"
  info=(--info age=30 --info handedness=right --info vision=normal)
  for id in A1 A2 A3; do $BC run "$G" --participant $id --db "$W/s.sqlite" --observer sim "${info[@]}" > /dev/null; done
  group() { sql "$W/s.sqlite" "SELECT s.group_name FROM sessions s JOIN participants p ON p.id = s.participant_id
                               WHERE p.code = '$1' ORDER BY s.id"; }
  first=$(group A3)
  counts=$(sql "$W/s.sqlite" "SELECT group_name, count(*) FROM sessions GROUP BY group_name ORDER BY group_name")
  $BC run "$G" --participant A3 --db "$W/s.sqlite" --observer sim "${info[@]}" --again > /dev/null
  [ "$(group A3)" = "$first"$'\n'"$first" ] || fail "A3's sessions ran in groups $(group A3 | tr '\n' ' ') (counts before: $counts)"
  echo "ok: A3's --again session stayed in group $first (sessions per group before it: $(echo "$counts" | tr '\n' ' '))" ;;
balanced_counts)
  # Balanced assignment counts participants with a completed session or one being run now (issue 23's review: it
  # counted unfinished sessions, so a participant stopped before the end, or killed, tilted the groups). Hand-worked
  # with groups-and-info's order (estimated, then no_blur; the first of equals): A1 stopped after 2 trials and A2
  # aborted count for nothing, so A1, A2 and A3 all get estimated; A4 then no_blur (1 vs 0); A1 resumed and
  # completed keeps estimated (2 vs 1), A5 gets no_blur (2 vs 2 after it). A3 run again stays in estimated and is
  # still one participant, so A6 gets estimated (2 vs 2, the first of equals); counted as sessions it would be 3 vs 2
  # and A6 would get no_blur.
  G="$P/groups-and-info.json"
  info=(--info age=30 --info handedness=right --info vision=normal)
  r() { $BC run "$G" --db "$W/s.sqlite" --observer sim "${info[@]}" --participant "$@" > /dev/null; }
  group() { sql "$W/s.sqlite" "SELECT group_concat(g, ' ') FROM (SELECT s.group_name g FROM sessions s JOIN
                               participants p ON p.id = s.participant_id WHERE p.code = '$1' ORDER BY s.id)"; }
  r A1 --stop-after 2
  r A2 --stop-after 2
  $BC sessions --db "$W/s.sqlite" --abort 2 > /dev/null
  r A3
  r A4
  r A1 --resume
  r A5
  r A3 --again
  r A6
  got="A1=$(group A1) A2=$(group A2) A3=$(group A3) A4=$(group A4) A5=$(group A5) A6=$(group A6)"
  want="A1=estimated A2=estimated A3=estimated estimated A4=no_blur A5=no_blur A6=estimated"
  [ "$got" = "$want" ] || fail "groups: $got, expected $want"
  echo "ok: balanced groups count completed and live participants only: $got" ;;
merge_people)
  # Two stations each gave the id P1 to someone: merge refuses to join them (exit 3, both ways out named) until told
  # who they are; --rename works written before the inputs too (it used to take the inputs as renames).
  $BC run "$P/test1-static-grids.json" --participant P1 --db "$W/a.sqlite" --observer sim > /dev/null
  $BC run "$P/test1-static-grids.json" --participant P1 --db "$W/b.sqlite" --observer sim:lapse=0.2 > /dev/null
  set +e
  $BC merge "$W/a.sqlite" "$W/b.sqlite" --out "$W/all.sqlite" > /dev/null 2> "$W/err"
  code=$?
  set -e
  [ $code = 3 ] && grep -q "participant P1 of study test1-static-grids is also in an earlier input" "$W/err" \
    && grep -q -- "--same-person P1" "$W/err" && [ ! -e "$W/all.sqlite" ] || fail "joined: exit $code $(cat "$W/err")"
  $BC merge --rename "$W/b.sqlite:P1=P1b" "$W/a.sqlite" "$W/b.sqlite" --out "$W/all.sqlite" > /dev/null
  [ "$(sql "$W/all.sqlite" "SELECT group_concat(code, ' ') FROM (SELECT code FROM participants ORDER BY code)")" = "P1 P1b" ] \
    || fail "renamed: $(sql "$W/all.sqlite" "SELECT code FROM participants")"
  echo "ok: one id at two stations refused until renamed; renamed, two participants P1 and P1b" ;;
*) fail "unknown case $CASE" ;;
esac
