#!/usr/bin/env bash
# End-to-end tests of `blurcue run` on real SQLite files - the record: whole sessions, resume, kill -9, locks, merge, concurrent stations.
# Usage: session_test.sh CASE BLURCUE DIR. DIR holds protocols/ (tests/copy_protocols.cmake) and the scene
# they show. Each case prints what it checked and exits non-zero on the first failure.
set -euo pipefail
CASE=$1 BC=$2 DIR=$3
source "$(dirname "$0")/session_lib.sh"

case $CASE in
complete)
  # A whole session by the simulated observer: every trial answered once, every edge once per participant, and
  # by_participant sides exact: odd numbers see measured on the left, even ones on the right.
  for id in P1 P2; do $BC run "$P/test1-static-grids.json" --participant $id --db "$W/s.sqlite" --observer sim; done
  integrity "$W/s.sqlite"
  [ "$(sql "$W/s.sqlite" "SELECT count(*) FROM responses")" = 26 ] || fail "26 answers expected"
  [ "$(sql "$W/s.sqlite" "SELECT group_concat(status) FROM sessions")" = "completed,completed" ] || fail "status"
  edges=$(sql "$W/s.sqlite" "SELECT group_concat(e) FROM (SELECT json_extract(factors, '$.edge') e FROM trials t
          JOIN sessions s ON s.id = t.session_id JOIN participants p ON p.id = s.participant_id
          WHERE p.code = 'P1' AND json_extract(factors, '$.practice') = 0 ORDER BY e)")
  [ "$edges" = "1,2,3,4,5,6,7,8,9,10,11" ] || fail "edges of P1: $edges"
  sides=$(sql "$W/s.sqlite" "SELECT p.code, t.left_shown, count(*) FROM trials t JOIN sessions s ON s.id = t.session_id
          JOIN participants p ON p.id = s.participant_id GROUP BY p.code, t.left_shown ORDER BY p.code")
  [ "$sides" = $'P1|"measured"|13\nP2|"estimated"|13' ] || fail "sides: $sides"
  [ "$(sql "$W/s.sqlite" "SELECT min(n) > 0 FROM (SELECT count(f.id) n FROM trials t LEFT JOIN frames f ON f.trial_id = t.id GROUP BY t.id)")" = 1 ] \
    || fail "every trial records its frames"
  $BC export --db "$W/s.sqlite" --out "$W/export"
  head -1 "$W/export/trials.csv" | grep -q "block_name,task,practice,swapped,cell,blur_plan,brightness,contrast,edge,elevation_left_deg,elevation_right_deg,exposure_ms,floor_sigma_left_px,floor_sigma_left_screen_px,floor_sigma_right_px,floor_sigma_right_screen_px,kernel,motion_left_x_screen_px,motion_left_y_screen_px,motion_right_x_screen_px,motion_right_y_screen_px,r_left_arcmin,r_left_px,r_left_screen_px,r_right_arcmin,r_right_px,r_right_screen_px,r_scene_arcmin,r_scene_px,r_scene_screen_px,r_span_screen_px,screen_px_per_photo_px,size_left_deg,size_right_deg,u_left_mm,u_right_mm,white_balance_b,white_balance_g,white_balance_r,left_source,left_fixed,right_source,right_fixed,status,chosen_side" \
    || fail "export header: $(head -1 "$W/export/trials.csv")"
  # Every radius in three units: the screen px follow the fit of the photo into the protocol's display (its size read
  # from the PNG header here), the arcmin follow the display profile the session recorded.
  $PY - "$W/export/trials.csv" "$W/s.sqlite" "$P/test1-static-grids.json" <<'PYEOF' || fail "radii in screen px and arcmin"
import csv, json, math, sqlite3, struct, sys
rows = [r for r in csv.DictReader(open(sys.argv[1]))]
profile = json.loads(sqlite3.connect(sys.argv[2]).execute("SELECT display_profile FROM sessions LIMIT 1").fetchone()[0])
protocol = json.load(open(sys.argv[3]))
import os
photo = os.path.join(os.path.dirname(sys.argv[3]), protocol["scene"]["background"])
w, h = struct.unpack(">II", open(photo, "rb").read()[16:24])
dw, dh = protocol.get("display", {}).get("width_px", 1280), protocol.get("display", {}).get("height_px", 720)
s = math.floor(w * min(dw / w, dh / h)) / w
pitch, d = profile["width_mm"] / profile["width_px"], profile["distance_mm"]
assert profile["name"].startswith("default"), profile
for r in rows:
    assert abs(float(r["screen_px_per_photo_px"]) - s) < 1e-6, (r["screen_px_per_photo_px"], s)
    for side in ("left", "right", "scene"):
        px = float(r[f"r_{side}_px"])
        assert abs(float(r[f"r_{side}_screen_px"]) - px * s) < 2e-4, r
        arcmin = 2 * math.degrees(math.atan(px * s * pitch / 2 / d)) * 60
        assert abs(float(r[f"r_{side}_arcmin"]) - arcmin) < 2e-4, (r, arcmin)
print(f"{len(rows)} trials: {w}x{h} photo at {s:.4f} screen px per photo px, {profile['name']}")
PYEOF
  # The per-study summary counts every answer once.
  $PY - "$W/export/summary-test1-static-grids.csv" <<'PYEOF' || fail "summary"
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
assert [r["participant"] for r in rows] == ["P1", "P2"], rows
for r in rows:
    assert r["planned"] == r["answered"] == "11", r
    assert sum(int(v) for k, v in r.items() if k.startswith("n_")) == 11, r
PYEOF
  # A participant who completed the study is refused a second session unless --again says so.
  if $BC run "$P/test1-static-grids.json" --participant P1 --db "$W/s.sqlite" --observer sim 2> "$W/err"; then
    fail "a second session of a completed participant started"
  fi
  grep -q "participant P1 already completed test1-static-grids (session 1)" "$W/err" || fail "message: $(cat "$W/err")"
  $BC run "$P/test1-static-grids.json" --participant P1 --db "$W/s.sqlite" --observer sim --again | grep -q completed
  echo "ok: 2 participants x 13 trials, edges and sides as designed, frames recorded, exported and summarised" ;;
merge)
  # Two lab stations run different participants of two studies; the merged record holds both, and a session
  # cannot be merged twice.
  $BC run "$P/test1-static-grids.json" --participant A1 --db "$W/a.sqlite" --observer sim > /dev/null
  $BC run "$P/test2-moving-balls.json" --participant A1 --db "$W/a.sqlite" --observer sim --stop-after 5 > /dev/null
  $BC run "$P/test1-static-grids.json" --participant B1 --db "$W/b.sqlite" --observer sim > /dev/null
  $BC merge "$W/a.sqlite" "$W/b.sqlite" --out "$W/all.sqlite"
  integrity "$W/all.sqlite"
  got=$(sql "$W/all.sqlite" "SELECT st.name, p.code, s.status, count(r.id) FROM sessions s
        JOIN participants p ON p.id = s.participant_id JOIN studies st ON st.id = p.study_id
        JOIN trials t ON t.session_id = s.id LEFT JOIN responses r ON r.trial_id = t.id
        GROUP BY s.id ORDER BY st.name, p.code")
  [ "$got" = $'test1-static-grids|A1|completed|13\ntest1-static-grids|B1|completed|13\ntest2-moving-balls|A1|running|5' ] \
    || fail "merged: $got"
  if $BC merge "$W/all.sqlite" "$W/a.sqlite" --out "$W/again.sqlite" 2> "$W/err"; then fail "a session merged twice"; fi
  [ ! -e "$W/again.sqlite" ] || fail "a failed merge left its output"
  echo "ok: two stations merged: $(echo "$got" | tr '\n' ' ')" ;;
merge_live_writer)
  # A session a live run is still writing is refused, exit 3, one line naming the file, the session and the run's
  # pid, and what to do; nothing is written. (It used to be copied as running: both copies could then be resumed,
  # and the two finished copies never merged again.)
  $BC run "$P/test1-static-grids.json" --participant B1 --db "$W/b.sqlite" --observer sim > /dev/null 2>&1
  $BC run "$P/test2-moving-balls.json" --participant L1 --db "$W/a.sqlite" --observer sim --sim-fps 8 > /dev/null 2>&1 &
  pid=$!
  wait_for_answers "$W/a.sqlite" 1
  set +e
  $BC merge "$W/b.sqlite" "$W/a.sqlite" --out "$W/all.sqlite" > "$W/out" 2> "$W/err"
  code=$?
  set -e
  # Being written: the one session `sessions` lists as running, its live writer named.
  $BC sessions --db "$W/a.sqlite" > "$W/sessions"
  kill -0 $pid 2>/dev/null || fail "the run ended before the merge was tried: $(cat "$W/err")"
  grep -Eq "test2-moving-balls +1 +L1 +1 +- +simulated +running +[0-9]+/74 .*lock: pid $pid on host .*\(alive\)" "$W/sessions" \
    || fail "sessions of a session being written: $(cat "$W/sessions")"
  grep -q "^1 sessions, 1 unfinished (1 of them running now)$" "$W/sessions" || fail "sessions: $(cat "$W/sessions")"
  kill -9 $pid; wait $pid 2>/dev/null || true
  [ $code = 3 ] || fail "merge of a session being written: exit $code: $(cat "$W/err")"
  [ "$(wc -l < "$W/err")" = 1 ] || fail "more than one line: $(cat "$W/err")"
  grep -Eq "$W/a.sqlite: session 1 \(study test2-moving-balls, participant L1, [0-9]+ of 74 trials answered\) is being written by pid $pid on host $(hostname), heartbeat [0-9]+ s ago \(alive\); merge it once that session has ended \(to give it up instead: stop that run, then blurcue sessions --db $W/a.sqlite --abort 1\)" "$W/err" \
    || fail "message: $(cat "$W/err")"
  [ -z "$(ls -A "$W" | grep all.sqlite)" ] || fail "a refused merge left $(ls -A "$W" | grep all.sqlite)"
  echo "ok: a session being written is refused: $(cat "$W/err")" ;;
merge_killed_session)
  # A session whose run was killed (-9) has no live writer: merge copies it as running, and says so in one line
  # naming the file and the session, and that it is to be resumed in one record only; resumed there, it completes.
  $BC run "$P/test1-static-grids.json" --participant B1 --db "$W/b.sqlite" --observer sim > /dev/null 2>&1
  $BC run "$P/test2-moving-balls.json" --participant K1 --db "$W/a.sqlite" --observer sim --seed 9 --sim-fps 8 \
    > /dev/null 2>&1 &
  pid=$!
  wait_for_answers "$W/a.sqlite" 4
  kill -9 $pid; wait $pid 2>/dev/null || true
  answered=$(sql "$W/a.sqlite" "SELECT count(*) FROM responses")
  $BC merge "$W/b.sqlite" "$W/a.sqlite" --out "$W/all.sqlite" > "$W/out" 2> "$W/err" || fail "merge: $(cat "$W/err")"
  [ "$(cat "$W/err")" = "merge: $W/a.sqlite: session 1 (study test2-moving-balls, participant K1, $answered of 74 trials answered) is unfinished, with no live writer: copied as running; resume it in one record only (this one, then merge again into a new file, or the merged one), never both: the two copies could not be merged again" ] \
    || fail "merge said: $(cat "$W/err")"
  integrity "$W/all.sqlite"
  got=$(sql "$W/all.sqlite" "SELECT p.code, s.status, s.lock_token IS NULL, (SELECT count(*) FROM trials t JOIN responses r
        ON r.trial_id = t.id WHERE t.session_id = s.id) FROM sessions s JOIN participants p ON p.id = s.participant_id
        ORDER BY p.code")
  [ "$got" = $'B1|completed|1|13\nK1|running|1|'"$answered" ] || fail "merged: $got"
  $BC run "$P/test2-moving-balls.json" --participant K1 --db "$W/all.sqlite" --observer sim --seed 9 --sim-fps 8 --resume \
    | grep -q "74 of 74 trials answered" || fail "the merged copy did not resume"
  echo "ok: a killed session ($answered of 74) merged as running with one line saying so, resumed in the merged record" ;;
same_seed)
  # The same protocol, participant and seed give the same trials and (simulated) answers; another seed does not.
  for db in a b; do $BC run "$P/test2-moving-balls.json" --participant S1 --db "$W/$db.sqlite" --observer sim --seed 11; done
  $BC run "$P/test2-moving-balls.json" --participant S1 --db "$W/c.sqlite" --observer sim --seed 12
  [ "$(fingerprint "$W/a.sqlite" S1)" = "$(fingerprint "$W/b.sqlite" S1)" ] || fail "same seed, different sessions"
  [ "$(fingerprint "$W/a.sqlite" S1)" != "$(fingerprint "$W/c.sqlite" S1)" ] || fail "another seed, same session"
  [ "$(fingerprint "$W/a.sqlite" S1 | wc -l)" = 74 ] || fail "74 trials expected"
  echo "ok: same seed, same 74 trials and answers; seed 12 differs" ;;
resume)
  # Stopped after 20 answers and resumed equals uninterrupted, for the depth-matching adjustment too.
  for proto in test2-moving-balls pre-research-depth-matching; do
    $BC run "$P/$proto.json" --participant R2 --db "$W/whole.sqlite" --observer sim --seed 5
    $BC run "$P/$proto.json" --participant R2 --db "$W/parts.sqlite" --observer sim --seed 5 --stop-after 20 \
      | grep -q "not finished" || fail "$proto: stop-after did not leave the session open"
    # Left by its run, no writer: listed as unfinished, not as running, with no lock.
    listed=$($BC sessions --db "$W/parts.sqlite" | grep -E " $proto +1 +R2 " || true)
    echo "$listed" | grep -Eq " +simulated +unfinished +20/[0-9]+ " && [[ "$listed" != *lock:* ]] \
      || fail "$proto: sessions after --stop-after: $listed"
    if $BC run "$P/$proto.json" --participant R2 --db "$W/parts.sqlite" --observer sim --seed 5 2>"$W/err"; then
      fail "$proto: a second session started while one is running"
    fi
    grep -q "has an unfinished session" "$W/err" || fail "$proto: message: $(cat "$W/err")"
    $BC run "$P/$proto.json" --participant R2 --db "$W/parts.sqlite" --observer sim --seed 5 --resume | grep -q completed
    [ "$(fingerprint "$W/whole.sqlite" R2)" = "$(fingerprint "$W/parts.sqlite" R2)" ] || fail "$proto: resumed differs"
  done
  integrity "$W/parts.sqlite"
  # The record lists both participants' sessions as completed, every trial answered.
  $BC sessions --db "$W/parts.sqlite" > "$W/sessions"
  grep -Eq "pre-research-depth-matching +1 +R2 +1 +- +simulated +completed +28/28" "$W/sessions" || fail "sessions: $(cat "$W/sessions")"
  grep -Eq "test2-moving-balls +1 +R2 +1 +- +simulated +completed +74/74" "$W/sessions" || fail "sessions: $(cat "$W/sessions")"
  echo "ok: stopped at 20 and resumed = uninterrupted (test 2, depth matching)" ;;
kill9)
  # kill -9 in the middle of a session, then --resume: nothing lost, nothing twice, same as uninterrupted.
  $BC run "$P/test2-moving-balls.json" --participant K1 --db "$W/whole.sqlite" --observer sim --seed 9 --sim-fps 8
  $BC run "$P/test2-moving-balls.json" --participant K1 --db "$W/killed.sqlite" --observer sim --seed 9 --sim-fps 8 \
    > "$W/out" 2>&1 &
  pid=$!
  wait_for_answers "$W/killed.sqlite" 8
  kill -9 $pid; wait $pid 2>/dev/null || true
  # Killed: the session is listed as interrupted (resumable; the record keeps it running) and its lock names the
  # dead writer.
  $BC sessions --db "$W/killed.sqlite" | grep -Eq "test2-moving-balls +1 +K1 +1 +- +simulated +interrupted +[0-9]+/74 .*lock: pid $pid on .*gone" \
    || fail "sessions after kill: $($BC sessions --db "$W/killed.sqlite")"
  answered=$(sql "$W/killed.sqlite" "SELECT count(*) FROM responses")
  [ "$answered" -ge 8 ] && [ "$answered" -lt 74 ] || fail "killed after $answered answers, expected mid-session"
  integrity "$W/killed.sqlite"
  $BC run "$P/test2-moving-balls.json" --participant K1 --db "$W/killed.sqlite" --observer sim --seed 9 --sim-fps 8 --resume \
    | grep -q "74 of 74 trials answered" || fail "resume did not complete"
  [ "$(fingerprint "$W/whole.sqlite" K1)" = "$(fingerprint "$W/killed.sqlite" K1)" ] || fail "killed+resumed differs"
  integrity "$W/killed.sqlite"
  echo "ok: killed -9 after $answered answers, resumed: identical to the uninterrupted session" ;;
second_writer)
  # While one process runs a session, a second one resuming it is refused with a clear message (exit 3).
  $BC run "$P/test2-moving-balls.json" --participant L1 --db "$W/s.sqlite" --observer sim --sim-fps 8 > /dev/null 2>&1 &
  pid=$!
  wait_for_answers "$W/s.sqlite" 1
  set +e
  $BC run "$P/test2-moving-balls.json" --participant L1 --db "$W/s.sqlite" --observer sim --resume 2> "$W/err"
  code=$?
  set -e
  kill $pid 2>/dev/null; wait $pid 2>/dev/null || true
  [ $code = 3 ] || fail "second writer exit $code: $(cat "$W/err")"
  grep -q "is being written by pid" "$W/err" || fail "message: $(cat "$W/err")"
  integrity "$W/s.sqlite"
  echo "ok: second writer refused: $(cat "$W/err")" ;;
recover)
  # Through the whole pipeline - trials, the observer's key presses, the record, export and the analysis - the
  # depth-matching fit recovers the cut-off law the simulated observers were given: c = 20 d^-0.5.
  for id in D1 D2 D3; do
    $BC run "$P/pre-research-depth-matching.json" --participant $id --db "$W/s.sqlite" \
      --observer sim:cutoff1m=20,slope=-0.5,sdlog=0.05,tol=0.05 > /dev/null
  done
  MPLCONFIGDIR=$W/mpl $BC report --db "$W/s.sqlite" --out "$W/report" --bench "$W/no-bench" --boot 20 2> "$W/err" \
    || fail "report: $(cat "$W/err")"
  # The thesis's power law, pooled over the observers (OLS with SEs clustered by participant): log c = a + b log d.
  $PY - "$W/report/depth-matching.csv" <<'PYEOF' > "$W/fit" || fail "fit: $(cat "$W/fit")"
import csv, math, sys
rows = [r for r in csv.DictReader(open(sys.argv[1])) if r["model"] == "power law: lm(log_c ~ log_d), cluster-robust"]
a = float(next(r["estimate"] for r in rows if r["term"].startswith("a ")))
b = float(next(r["estimate"] for r in rows if r["term"].startswith("b ")))
print(f"recovered c = {math.exp(a):.2f} d^{b:.3f}")
sys.exit(0 if abs(b + 0.5) < 0.08 and abs(math.exp(a) / 20 - 1) < 0.12 else 1)
PYEOF
  grep -q "bench" "$W/err" || fail "the missing bench folder is not named: $(cat "$W/err")"
  # Every answer is where its recorded steps end: the start level, then each step (adjustments.csv, one row per step),
  # the last one accepted.
  $PY - "$W/report/tables/trials.csv" "$W/report/tables/adjustments.csv" <<'PYEOF' || fail "adjustment paths"
import csv, sys
rows = [r for r in csv.DictReader(open(sys.argv[1])) if r["status"] == "answered"]
assert len(rows) == 3 * 28, len(rows)
paths = {}
for s in csv.DictReader(open(sys.argv[2])):
    paths.setdefault((s["session_id"], s["trial_index"]), []).append(s)
stepped = 0
for r in rows:
    steps = sorted(paths.get((r["session_id"], r["trial_index"]), []), key=lambda s: int(s["step"]))
    assert [int(s["step"]) for s in steps] == list(range(1, len(steps) + 1)), steps
    assert all(float(b["t_ms"]) >= float(a["t_ms"]) for a, b in zip(steps, steps[1:])), r
    last = float(steps[-1]["level"]) if steps else float(r["start_level"])
    assert abs(float(r["adjusted_level"]) - last) < 1e-9, (r["adjusted_level"], last)
    assert not steps or float(r["rt_ms"]) >= float(steps[-1]["t_ms"]), r
    stepped += bool(steps)
assert stepped > len(rows) // 2, stepped
PYEOF
  echo "ok: depth matching through run, record, export and report recovers c = 20 d^-0.5" ;;
resume_guards)
  # --resume with nothing to resume says what it found, exits 3 and starts nothing (issue 9).
  T1=$P/test1-static-grids.json
  if $BC run "$T1" --participant G1 --db "$W/none.sqlite" --observer sim --resume 2> "$W/err"; then fail "resumed a missing record"; fi
  grep -q "none.sqlite: --resume: no such record" "$W/err" || fail "missing record: $(cat "$W/err")"
  [ ! -e "$W/none.sqlite" ] || fail "--resume created the record it did not find"
  $BC run "$T1" --participant G1 --db "$W/r.sqlite" --observer sim > /dev/null 2>&1
  set +e; $BC run "$T1" --participant G1 --db "$W/r.sqlite" --observer sim --resume 2> "$W/err"; code=$?; set -e
  [ $code = 3 ] || fail "--resume of a completed participant: exit $code"
  grep -q "has no unfinished session to continue (1 completed (last: session 1)); leave out --resume to start a new session, with --again" "$W/err" \
    || fail "completed participant: $(cat "$W/err")"
  [ "$(sql "$W/r.sqlite" "SELECT count(*) FROM sessions")" = 1 ] || fail "a session was started"
  # An empty file is a new record; --resume on it finds nothing and leaves it empty.
  : > "$W/empty.sqlite"
  set +e; $BC run "$T1" --participant G1 --db "$W/empty.sqlite" --observer sim --resume 2> "$W/err"; code=$?; set -e
  [ $code = 3 ] && grep -q "no sessions at all" "$W/err" || fail "empty record: exit $code $(cat "$W/err")"
  # Another program's SQLite file: refused, byte for byte untouched, no WAL beside it.
  $PY -c "import sqlite3; c = sqlite3.connect('$W/customers.sqlite'); c.execute('CREATE TABLE customers (id, name)'); c.commit()"
  before=$(sha256sum < "$W/customers.sqlite")
  set +e; $BC run "$T1" --participant G1 --db "$W/customers.sqlite" --observer sim 2> "$W/err"; code=$?; set -e
  [ $code = 3 ] && grep -q "customers.sqlite: not a blurcue record: it holds 1 tables (customers)" "$W/err" \
    || fail "foreign database: exit $code $(cat "$W/err")"
  [ "$(sha256sum < "$W/customers.sqlite")" = "$before" ] && [ ! -e "$W/customers.sqlite-wal" ] || fail "foreign file touched"
  for cmd in sessions export; do
    set +e; $BC $cmd --db "$W/customers.sqlite" $([ $cmd = export ] && echo --out "$W/x") 2> "$W/err"; code=$?; set -e
    [ $code = 3 ] && grep -q "not a blurcue record" "$W/err" || fail "$cmd of a foreign file: exit $code $(cat "$W/err")"
  done
  # A truncated record: exit 3 naming the file, for the runner and the readers alike.
  cp "$W/r.sqlite" "$W/cut.sqlite"
  size=$(stat -c %s "$W/cut.sqlite"); truncate -s $((size / 2)) "$W/cut.sqlite"
  # A garbled one: 4 KiB of noise in the middle of the file.
  cp "$W/r.sqlite" "$W/noise.sqlite"
  $PY -c "import os; f = open('$W/noise.sqlite', 'r+b'); f.seek(os.path.getsize('$W/noise.sqlite') // 2); f.write(os.urandom(4096))"
  for db in cut noise; do
    for args in "run $T1 --participant G2 --db $W/$db.sqlite --observer sim" "sessions --db $W/$db.sqlite" \
                "export --db $W/$db.sqlite --out $W/$db-tables"; do
      set +e; $BC $args 2> "$W/err"; code=$?; set -e
      [ $code = 3 ] && grep -q "$db.sqlite: the record is damaged" "$W/err" && [ "$(wc -l < "$W/err")" = 1 ] \
        || fail "damaged record ($db), $args: exit $code $(cat "$W/err")"
    done
  done
  # Two stations starting on one new file at the same moment: both proceed, every time.
  for round in 1 2 3 4 5 6; do
    $BC run "$T1" --participant A$round --db "$W/twin-$round.sqlite" --observer sim > /dev/null 2> "$W/twin-a" & a=$!
    $BC run "$T1" --participant B$round --db "$W/twin-$round.sqlite" --observer sim > /dev/null 2> "$W/twin-b" & b=$!
    wait $a || fail "round $round, first station: $(cat "$W/twin-a")"
    wait $b || fail "round $round, second station: $(cat "$W/twin-b")"
  done
  # A value echoed in an error stays one line and cannot drive the terminal: a newline, an escape, a broken byte.
  for bad in $'--seed=3\n' $'--participant=P\x1b[2J1' $'--observer=sim:weber=3\n' $'--sim-fps=\xff' $'--info=a\n=1'; do
    set +e; $BC run "$T1" --participant P1 --db "$W/echo.sqlite" --observer sim "$bad" > /dev/null 2> "$W/err"; code=$?
    set -e
    [ $code = 2 ] && [ "$(wc -l < "$W/err")" = 1 ] && ! grep -q $'\x1b' "$W/err" && [ ! -e "$W/echo.sqlite" ] \
      || fail "$(printf %q "$bad"): exit $code, $(wc -l < "$W/err") lines: $(cat -v "$W/err")"
  done
  echo "ok: --resume with nothing to resume, foreign, empty, truncated records and twin first starts; one-line errors" ;;
stranded)
  # A protocol reformatted by an editor (CRLF, a trailing newline, indentation) still resumes its session; a real
  # change is refused naming what changed and the command that closes the session, which keeps its answers.
  $BC run "$P/test1-static-grids.json" --participant S1 --db "$W/s.sqlite" --observer sim --stop-after 4 > /dev/null 2>&1
  $PY - "$P/test1-static-grids.json" "$P/test1-crlf.json" <<'PYEOF'
import json, sys
text = json.dumps(json.load(open(sys.argv[1])), indent=4)
open(sys.argv[2], "w", newline="").write(text.replace("\n", "\r\n") + "\r\n\r\n")
PYEOF
  $BC run "$P/test1-crlf.json" --participant S1 --db "$W/s.sqlite" --observer sim --stop-after 2 --resume \
    | grep -q "6 of 13 trials answered" || fail "a reformatted protocol did not resume"
  sed 's/"inter_trial_ms": 500/"inter_trial_ms": 800/' "$P/test1-static-grids.json" > "$P/test1-changed.json"
  set +e; $BC run "$P/test1-changed.json" --participant S1 --db "$W/s.sqlite" --observer sim --resume 2> "$W/err"; code=$?; set -e
  [ $code = 3 ] || fail "a changed protocol resumed: exit $code"
  grep -q "session 1 was started with another version of the protocol (/timing/inter_trial_ms 500 -> 800)" "$W/err" \
    || fail "changed protocol: $(cat "$W/err")"
  grep -q "blurcue sessions --db $W/s.sqlite --abort 1 (its answers are kept)" "$W/err" || fail "no way out: $(cat "$W/err")"
  $BC sessions --db "$W/s.sqlite" --abort 1 | grep -q "session 1 closed as aborted; its answers are kept" || fail "abort"
  $BC sessions --db "$W/s.sqlite" | grep -Eq "test1-static-grids +1 +S1 +1 +- +simulated +aborted +6/13" || fail "sessions: $($BC sessions --db "$W/s.sqlite")"
  set +e; $BC sessions --db "$W/s.sqlite" --abort 1 2> "$W/err"; code=$?; set -e
  [ $code = 3 ] && grep -q "session 1 is aborted; only a running session can be aborted" "$W/err" || fail "abort twice: $(cat "$W/err")"
  # Run anew, the changed text is another version of the study's protocol: its "version" is raised.
  sed 's/"version": 1,/"version": 2,/' "$P/test1-changed.json" > "$P/test1-changed-v2.json"
  $BC run "$P/test1-changed-v2.json" --participant S1 --db "$W/s.sqlite" --observer sim | grep -q "session 2, .* 13 of 13" \
    || fail "no new session after the abort"
  integrity "$W/s.sqlite"
  echo "ok: CRLF-reformatted protocol resumes; a changed one names the change; --abort closes it, answers kept" ;;
stale_lock)
  # A crashed writer's pid reused by a live program (pid 1 here) with an old heartbeat is a stale lock; a fresh
  # heartbeat is a live one, until the experimenter breaks it.
  $BC run "$P/test1-static-grids.json" --participant L1 --db "$W/l.sqlite" --observer sim --stop-after 3 > /dev/null 2>&1
  plant() { $PY -c "import sqlite3; c = sqlite3.connect('$W/l.sqlite'); c.execute(\"UPDATE sessions SET lock_host = '$(hostname)', lock_pid = 1, lock_token = 'x', lock_heartbeat_ms = CAST(strftime('%s', 'now') AS INTEGER) * 1000 - $1 * 1000\"); c.commit()"; }
  plant 5
  set +e; $BC run "$P/test1-static-grids.json" --participant L1 --db "$W/l.sqlite" --observer sim --resume 2> "$W/err"; code=$?; set -e
  [ $code = 3 ] && grep -q "is being written by pid 1 on host $(hostname), heartbeat [0-9]* s ago (alive)" "$W/err" \
    || fail "live lock: exit $code $(cat "$W/err")"
  $BC sessions --db "$W/l.sqlite" --break-lock 1 | grep -q "broke the lock of pid 1 on host" || fail "break-lock"
  plant 120
  $BC sessions --db "$W/l.sqlite" | grep -q "lock: pid 1 on host .*(silent for over 60 s: a stale lock" \
    || fail "sessions: $($BC sessions --db "$W/l.sqlite")"
  $BC run "$P/test1-static-grids.json" --participant L1 --db "$W/l.sqlite" --observer sim --resume \
    | grep -q "13 of 13 trials answered" || fail "the stale lock was not taken over"
  echo "ok: a reused pid with an old heartbeat is stale; a fresh one is live until --break-lock" ;;
readonly)
  # An archived record in a read-only folder opens for sessions, export and report (as an unprivileged user, for
  # whom permissions hold; root ignores them).
  mkdir -p "$W/arch"
  $BC run "$P/test1-static-grids.json" --participant A1 --db "$W/arch/study.sqlite" --observer sim > /dev/null 2>&1
  [ ! -e "$W/arch/study.sqlite-wal" ] || fail "the writer left a WAL behind"
  chmod 444 "$W/arch/study.sqlite"; chmod 555 "$W/arch"
  mkdir -p "$W/out"; chmod 777 "$W/out"
  as_nobody() { setpriv --reuid=65534 --regid=65534 --clear-groups env HOME="$W/out" MPLCONFIGDIR="$W/out/mpl" "$@"; }
  as_nobody $BC sessions --db "$W/arch/study.sqlite" | grep -Eq "test1-static-grids +1 +A1 +1 +- +simulated +completed +13/13" \
    || fail "sessions of a read-only record: $(as_nobody $BC sessions --db "$W/arch/study.sqlite" 2>&1)"
  as_nobody $BC export --db "$W/arch/study.sqlite" --out "$W/out/tables" > /dev/null 2> "$W/err" || fail "export: $(cat "$W/err")"
  [ "$(wc -l < "$W/out/tables/trials.csv")" = 14 ] || fail "export of a read-only record: $(wc -l < "$W/out/tables/trials.csv") lines"
  as_nobody $BC report --db "$W/arch/study.sqlite" --out "$W/out/report" --bench "$W/no-bench" --boot 20 > /dev/null 2> "$W/err" \
    || fail "report of a read-only record: $(tail -3 "$W/err")"
  [ -s "$W/out/report/index.html" ] || fail "no index.html"
  # A writer is refused with one line: the folder is read-only.
  set +e; as_nobody $BC run "$P/test1-static-grids.json" --participant A2 --db "$W/arch/study.sqlite" --observer sim 2> "$W/err"; code=$?; set -e
  [ $code = 3 ] && [ "$(wc -l < "$W/err")" = 1 ] && grep -q "study.sqlite: " "$W/err" || fail "writer on a read-only record: exit $code $(cat "$W/err")"
  chmod 755 "$W/arch"; chmod 644 "$W/arch/study.sqlite"
  echo "ok: a read-only archived record lists, exports and reports; a writer is refused in one line" ;;
resume_observer)
  # The session row names one observer: resuming with another is refused (exit 3, one line naming both) and adds
  # nothing; the same observer spelled another way (the same canonical form) resumes.
  T1=$P/test1-static-grids.json
  $BC run "$T1" --participant O1 --db "$W/o.sqlite" --observer sim:lapse=1 --stop-after 1 > /dev/null 2>&1
  set +e
  $BC run "$T1" --participant O1 --db "$W/o.sqlite" --observer sim:weber=0.5 --resume > /dev/null 2> "$W/err"; code=$?
  set -e
  [ $code = 3 ] && [ "$(wc -l < "$W/err")" = 1 ] &&
    grep -q "session 1 was started with --observer sim:model=arcmin,[^ ]*,lapse=1,[^ ]*, got --observer sim:model=arcmin,[^ ]*weber=0.5,[^ ]*lapse=0.04,[^ ]*; resume it with the observer it started with" "$W/err" \
    || fail "another observer on resume: exit $code $(cat "$W/err")"
  [ "$(sql "$W/o.sqlite" "SELECT count(*) FROM responses")" = 1 ] || fail "another observer answered"
  $BC run "$T1" --participant O1 --db "$W/o.sqlite" --observer sim:model=arcmin,lapse=1.0 --resume | grep -q completed \
    || fail "an equivalent observer spec did not resume"
  [ "$(sql "$W/o.sqlite" "SELECT count(*), count(DISTINCT observer_params) FROM sessions")" = "1|1" ] || fail "sessions"
  echo "ok: another observer on resume refused naming both; an equivalent spec resumes" ;;
resume_display)
  # A session resumed on another display profile is refused naming both profiles and what differs (not "another
  # calibration or blurcue version?"); the same profile named by another path resumes.
  T1=$P/test1-static-grids.json
  LAB=$(cd "$(dirname "$0")/data" && pwd)/lab-monitor.json
  $BC run "$T1" --participant D1 --db "$W/d.sqlite" --observer sim --stop-after 2 > /dev/null 2>&1
  set +e
  $BC run "$T1" --participant D1 --db "$W/d.sqlite" --observer sim --resume --display "$LAB" > /dev/null 2> "$W/err"
  code=$?
  set -e
  [ $code = 3 ] && [ "$(wc -l < "$W/err")" = 1 ] &&
    grep -qF 'session 1 was started with display profile "default (24-inch 16:9 at 60 cm)", got "lab 1" (/distance_mm 600.0 -> 570.0, ' "$W/err" &&
    grep -qF "resume it with the --display (or the protocol's display.profile) it started with" "$W/err" \
    || fail "another display on resume: exit $code $(cat "$W/err")"
  [ "$(sql "$W/d.sqlite" "SELECT count(*) FROM responses")" = 2 ] || fail "answers were added on another display"
  $BC run "$T1" --participant D2 --db "$W/d.sqlite" --observer sim --stop-after 2 --display "$LAB" > /dev/null 2>&1
  (cd "$(dirname "$LAB")" && $BC run "$T1" --participant D2 --db "$W/d.sqlite" --observer sim --resume \
     --display ./lab-monitor.json) | grep -q completed || fail "the same profile by another path did not resume"
  echo "ok: another display profile on resume refused naming what differs; the same one by another path resumes" ;;
groups_concurrent)
  # Four stations starting participants at the same moment on one new record: the balanced groups count each other's
  # sessions (the count and the session's insert are one transaction), so two get each group, and each session's
  # trials are its group's blocks. Run one after another they alternate (groups_info); started together they all got
  # the first group before.
  G="$P/groups-and-info.json"
  info=(--info age=30 --info handedness=right --info vision=normal)
  for round in 1 2 3; do
    pids=()
    for id in B1 B2 B3 B4; do
      $BC run "$G" --participant $id --db "$W/c-$round.sqlite" --observer sim "${info[@]}" > /dev/null 2> "$W/$id.err" &
      pids+=($!)
    done
    for i in 0 1 2 3; do wait ${pids[$i]} || fail "round $round, station $((i + 1)): $(grep -v '^trial' "$W/B$((i + 1)).err")"; done
    integrity "$W/c-$round.sqlite"
    got=$(sql "$W/c-$round.sqlite" "SELECT group_name, count(*) FROM sessions GROUP BY group_name ORDER BY group_name")
    [ "$got" = $'estimated|2\nno_blur|2' ] || fail "round $round: groups $(echo "$got" | tr '\n' ' ')"
    wrong=$(sql "$W/c-$round.sqlite" "SELECT count(*) FROM trials t JOIN sessions s ON s.id = t.session_id
            WHERE (s.group_name = 'estimated') != (t.block_name = 'measured-vs-estimated')")
    [ "$wrong" = 0 ] || fail "round $round: $wrong trials of another group's block"
  done
  echo "ok: 3 rounds of 4 stations started at once: 2 sessions per group each time, each with its group's trials" ;;
resume_exact)
  # A resumed simulated session is bit-identical to an uninterrupted one: every answer's response time and every
  # frame's flip time to the last digit (sql prints floats round-trip), not only to the 3 decimals of fingerprint.
  # Before, the simulated clock ran on from the session's start and ~22 of test 2's 74 response times differed in
  # their last digits.
  exact() {
    sql "$1" "SELECT t.trial_index, r.choice, r.rt_ms, r.adjustment, r.level FROM trials t
              JOIN responses r ON r.trial_id = t.id ORDER BY t.trial_index"
    sql "$1" "SELECT t.trial_index, f.frame_index, f.flip_time_s, f.dropped FROM trials t
              JOIN frames f ON f.trial_id = t.id ORDER BY t.trial_index, f.frame_index"
  }
  for proto in test2-moving-balls pre-research-depth-matching; do
    $BC run "$P/$proto.json" --participant K1 --db "$W/$proto-whole.sqlite" --observer sim > /dev/null 2>&1
    $BC run "$P/$proto.json" --participant K1 --db "$W/$proto-parts.sqlite" --observer sim --stop-after 5 > /dev/null 2>&1
    $BC run "$P/$proto.json" --participant K1 --db "$W/$proto-parts.sqlite" --observer sim --resume 2> /dev/null |
      grep -q completed || fail "$proto: resume did not complete"
    exact "$W/$proto-whole.sqlite" > "$W/$proto-whole.txt"
    exact "$W/$proto-parts.sqlite" > "$W/$proto-parts.txt"
    [ -s "$W/$proto-whole.txt" ] || fail "$proto: nothing recorded"
    diff "$W/$proto-whole.txt" "$W/$proto-parts.txt" > "$W/$proto.diff" ||
      fail "$proto: resumed differs from uninterrupted in $(grep -c '^<' "$W/$proto.diff") rows, e.g. $(grep -m2 '^[<>]' "$W/$proto.diff" | tr '\n' ' ')"
  done
  echo "ok: stopped after 5 and resumed = uninterrupted to the last digit of every response and flip time (test 2, depth matching)" ;;
schema1)
  # A record an early build wrote (schema 1: no display profile, no typed columns, a trial's variables as that build's
  # TrialVariables kept them - the levels as given, a pattern's speed_cm_s only inside the pattern object, then
  # practice, block_name, swapped and the three radii) exports every variable it holds and reports (issue 24: export
  # left speed_cm_s out and report exited 10 for every study). It is made from a record of today's run (test 2's
  # task 1, the balls rolled at 2 frames a second) by writing its rows into schema 1's tables, as that build did.
  $PY - "$P/test2-moving-balls.json" "$W/t2.json" <<'PYEOF'
import json, sys
t = json.load(open(sys.argv[1]))
t["blocks"] = t["blocks"][:1]
t.pop("practice", None)
json.dump(t, open(sys.argv[2], "w"))
PYEOF
  sed -i "s|\"\.\./|\"$P/../|g" "$W/t2.json"
  $BC run "$W/t2.json" --participant P1 --db "$W/new.sqlite" --observer sim --sim-fps 2 > "$W/out" 2>&1 ||
    fail "run: $(tail -1 "$W/out")"
  $PY - "$W/new.sqlite" "$W/old.sqlite" <<'PYEOF'
import json, sqlite3, sys
new, old = sqlite3.connect(sys.argv[1]), sqlite3.connect(sys.argv[2])
# Schema 1 as the early build created it (src/store/schema.cc at 0fc9814^, STRICT as SQLite >= 3.37 made it).
S = " STRICT"
old.executescript(f"""
CREATE TABLE studies (id INTEGER PRIMARY KEY, name TEXT NOT NULL UNIQUE, created TEXT NOT NULL){S};
CREATE TABLE protocol_versions (id INTEGER PRIMARY KEY, study_id INTEGER NOT NULL REFERENCES studies(id),
  json TEXT NOT NULL, hash TEXT NOT NULL, created TEXT NOT NULL, UNIQUE (study_id, hash)){S};
CREATE TABLE participants (id INTEGER PRIMARY KEY, study_id INTEGER NOT NULL REFERENCES studies(id),
  code TEXT NOT NULL, created TEXT NOT NULL, UNIQUE (study_id, code)){S};
CREATE TABLE sessions (id INTEGER PRIMARY KEY, participant_id INTEGER NOT NULL REFERENCES participants(id),
  protocol_version_id INTEGER NOT NULL REFERENCES protocol_versions(id), seed INTEGER NOT NULL,
  software_version TEXT NOT NULL, host TEXT NOT NULL, display TEXT NOT NULL, started TEXT NOT NULL, ended TEXT,
  status TEXT NOT NULL CHECK (status IN ('running', 'completed', 'aborted')), lock_host TEXT, lock_pid INTEGER,
  lock_token TEXT, lock_heartbeat_ms INTEGER){S};
CREATE INDEX sessions_participant ON sessions (participant_id);
CREATE TABLE trials (id INTEGER PRIMARY KEY, session_id INTEGER NOT NULL REFERENCES sessions(id),
  trial_index INTEGER NOT NULL, block INTEGER NOT NULL, factors TEXT NOT NULL, left_shown TEXT NOT NULL,
  right_shown TEXT NOT NULL, UNIQUE (session_id, trial_index)){S};
CREATE TABLE responses (id INTEGER PRIMARY KEY, trial_id INTEGER NOT NULL UNIQUE REFERENCES trials(id),
  choice TEXT NOT NULL, rt_ms REAL, adjustment TEXT NOT NULL, answered_at TEXT NOT NULL){S};
CREATE TABLE frames (id INTEGER PRIMARY KEY, trial_id INTEGER NOT NULL REFERENCES trials(id),
  frame_index INTEGER NOT NULL, flip_time_s REAL NOT NULL, dropped INTEGER NOT NULL CHECK (dropped IN (0, 1)),
  UNIQUE (trial_id, frame_index)){S};
PRAGMA user_version = 1;
""")
def copy(table, columns, transform=None):
    for row in new.execute(f"SELECT {', '.join(columns)} FROM {table} ORDER BY id"):
        row = list(row)
        if transform: row = transform(row)
        old.execute(f"INSERT INTO {table} ({', '.join(columns)}) VALUES ({', '.join('?' * len(columns))})", row)
copy("studies", ["id", "name", "created"])
# The protocol's text as run; the early build hashed the file's bytes (migration 2 makes the hash canonical).
copy("protocol_versions", ["id", "study_id", "json", "hash", "created"], lambda r: r[:3] + ["0123456789abcdef", r[4]])
copy("participants", ["id", "study_id", "code", "created"])
# The early build wrote the simulated observer into the display text ("...; observer sim:..."), in its spelling.
copy("sessions", ["id", "participant_id", "protocol_version_id", "seed", "software_version", "host", "display",
                  "started", "ended", "status"],
     lambda r: r[:6] + [r[6].split("; observer ")[0] + "; observer sim:jnd=0.6,bias=0"] + r[7:])
kept = ("practice", "block_name", "swapped", "r_left_px", "r_right_px", "r_scene_px")
protocol = json.loads(new.execute("SELECT json FROM protocol_versions").fetchone()[0])
levels = set(protocol["blocks"][0]["factors"])
def old_factors(r):
    f = json.loads(r[4])
    r[4] = json.dumps({k: v for k, v in f.items() if k in levels or k in kept}, separators=(",", ":"))
    return r
copy("trials", ["id", "session_id", "trial_index", "block", "factors", "left_shown", "right_shown"], old_factors)
copy("responses", ["id", "trial_id", "choice", "rt_ms", "adjustment", "answered_at"])
copy("frames", ["id", "trial_id", "frame_index", "flip_time_s", "dropped"])
old.commit()
first = json.loads(old.execute("SELECT factors FROM trials").fetchone()[0])
assert "speed_cm_s" not in first and "speed_cm_s" in first["pattern"], first
PYEOF
  $BC export --db "$W/old.sqlite" --out "$W/old-tables" > "$W/out" 2>&1 || fail "export of the old record: $(tail -1 "$W/out")"
  $BC export --db "$W/new.sqlite" --out "$W/new-tables" > "$W/out" 2>&1 || fail "export of the new record: $(tail -1 "$W/out")"
  # Every variable the old record holds is a column, with the value today's run recorded for it.
  $PY - "$W/old-tables/trials.csv" "$W/new-tables/trials.csv" <<'PYEOF' || fail "the old record's export"
import csv, sys
old, new = (list(csv.DictReader(open(p))) for p in sys.argv[1:])
assert len(old) == len(new) == 12, (len(old), len(new))
for column in ("pattern", "speed_cm_s", "practice", "block_name", "swapped", "r_left_px", "r_right_px", "chosen_side"):
    assert column in old[0], f"no column {column} in the old record's export: {sorted(old[0])}"
for o, n in zip(old, new):
    for column in ("trial_index", "pattern", "speed_cm_s", "r_left_px", "r_right_px", "chosen_side"):
        assert o.get(column) == n.get(column), (column, o.get(column), n.get(column))
assert sorted({o["speed_cm_s"] for o in old}) == ["1.8", "3"], {o["speed_cm_s"] for o in old}
PYEOF
  code=0
  MPLCONFIGDIR=$W/mpl $BC report --db "$W/old.sqlite" --out "$W/report" --bench "$W/no-bench" --boot 20 > "$W/out" 2>&1 ||
    code=$?
  [ "$code" = 0 ] || fail "report on the old record: exit $code: $(tail -3 "$W/out")"
  grep -q "speed" "$W/report/index.html" || fail "the old record's report says nothing of speed"
  echo "ok: a schema-1 record exports speed_cm_s (12 rows equal to today's record's) and reports (exit 0)" ;;
*) fail "unknown case $CASE" ;;
esac
