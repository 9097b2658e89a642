#!/usr/bin/env bash
# What an adversary tried against ar, track, init, calibrate and camera (issue 39), each refused before any work:
# exit 2 or 3, one line naming the option and the path, no hang (a FIFO input), and every file there byte-identical
# afterwards (sha256 of the whole folder before and after). Usage: outputs_guard_test.sh BLURCUE DIR
set -euo pipefail
BC=$1 W=$2/outputs-guard L=$2/outputs-guard-logs
rm -rf "$W" "$L" && mkdir -p "$W" "$L"
source "$(dirname "$0")/lib.sh"
cd "$W"

$BC synth-take --out take --frames 3 --supersample 1 --quiet
$BC track take/take.avi --camera take/camera.json --out track --quiet
cp take/take.avi same.avi
mkdir cp && cp take/frame-000*.png cp/
$PY -c "import sqlite3; c = sqlite3.connect('study.sqlite'); c.execute('CREATE TABLE answers (a)'); c.executemany('INSERT INTO answers VALUES (?)', [(i,) for i in range(148)]); c.commit()"
echo precious > afile
ln -s nowhere dangling
mkfifo fifo
mkdir strangers && echo notes > strangers/notes.txt
$PY - <<'PYEOF'
import json
json.dump({"objects": [{"kind": "ball", "x_mm": 50 + i % 50, "y_mm": 125} for i in range(65)]}, open("many.json", "w"))
PYEOF
snapshot() { find . -type f -print0 | sort -z | xargs -0 sha256sum; }
before=$(snapshot)

AR=(ar take/take.avi --track track --ball 50,125 --quiet)
cases=0
EXPECT_TIMEOUT=20  # expect: tests/lib.sh
# 2. An output that is an input.
expect 2 "--out same.avi: is also the input INPUT same.avi" ar same.avi --track track --ball 50,125 --out same.avi
expect 2 "--frames cp: holds the input INPUT cp/frame-0000.png" ar 'cp/frame-%04d.png' --track track --ball 50,125 --out x.avi --frames cp
# 3. Two outputs on one path; an output in an input folder; a record as a CSV, a camera.json or a calib.json.
expect 2 "--csv g.avi: is also --out g.avi" "${AR[@]}" --out g.avi --csv g.avi
expect 2 "--csv track/track.csv: lies inside the input folder --track track" "${AR[@]}" --out g.avi --csv track/track.csv
expect 2 "--out track/ar.avi: lies inside the input folder --track track" "${AR[@]}" --out track/ar.avi
expect 3 "--csv study.sqlite: is an SQLite record" "${AR[@]}" --out g.avi --csv study.sqlite
expect 3 "--out study.sqlite: is an SQLite record" camera take/frame-0000.png --out study.sqlite
expect 3 "--out study.sqlite: is an SQLite record" calibrate take/frame-0000.png --camera take/camera.json --out study.sqlite
expect 2 "--out take/camera.json: is also the input --camera" calibrate take/frame-0000.png --camera take/camera.json --out take/camera.json
# 5. A FIFO input: refused at once.
expect 3 "INPUT fifo: is a FIFO" track fifo --camera take/camera.json --out t2
expect 3 "INPUT fifo: is a FIFO" ar fifo --track track --ball 50,125 --out g.avi
# 8. Outputs of another kind: a file, a dangling symlink, a path under a file, a folder that takes no file.
expect 3 "--out afile: is a file, not a folder" track take/take.avi --camera take/camera.json --out afile
expect 3 "--out dangling: is a symlink to nothing" track take/take.avi --camera take/camera.json --out dangling
expect 3 "--out afile/t: lies under" track take/take.avi --camera take/camera.json --out afile/t
expect 3 "--out /proc/blurcue-test/t: cannot be written" track take/take.avi --camera take/camera.json --out /proc/blurcue-test/t
expect 3 "--out strangers: holds notes.txt, which this command did not write" track take/take.avi --camera take/camera.json --out strangers
expect 3 "--out afile/x.avi: lies under" "${AR[@]}" --out afile/x.avi
expect 3 "--frames afile: is a file, not a folder" "${AR[@]}" --out g.avi --frames afile
expect 3 "--csv fifo: is a FIFO" "${AR[@]}" --out fifo.avi --csv fifo
# 9. Limits: objects per run, up front.
balls=(); for i in $(seq 1 65); do balls+=(--ball "$((40 + i)),125"); done
expect 2 "65 --ball and --card options: at most 64 objects a run" ar take/take.avi --track track --out g.avi "${balls[@]}"
expect 3 "many.json: /objects: holds 65 objects: at most 64 a run" ar take/take.avi --track track --out g.avi --objects many.json
# 6. init: a photo that is no image, an example whose board-free photo is missing; neither leaves a folder.
expect 3 "--photo /etc/passwd: not a readable image" init study --photo /etc/passwd --camera take/camera.json
expect 2 "--photo: test3-no-board shows the scene without the board" init study --from test3-no-board --photo take/frame-0000.png --camera take/camera.json
expect 3 "--photo fifo: is a FIFO" init study --photo fifo --camera take/camera.json

[ "$(snapshot)" = "$before" ] || fail "a refused command changed a file: $(diff <(echo "$before") <(snapshot) | head -5)"
left=$(ls -A | grep -Ev '^(take|track|same\.avi|cp|study\.sqlite|afile|dangling|fifo|strangers|many\.json)$' || true)
[ -z "$left" ] || fail "a refused command left: $left"
# Failures after the checks write nothing: ar stopped at frame 2 (a frame that is not the take's) leaves no video,
# CSV or frames; init on a photo with no board (calibrate: exit 4) leaves no study.
$PY -c "from PIL import Image; Image.open('take/frame-0000.png').point(lambda v: 128).save('grey.png')"
mkdir mixed && cp take/frame-000[01].png mixed/ && cp grey.png mixed/frame-0002.png
code=0
$BC ar 'mixed/frame-%04d.png' --track track --ball 50,125 --out stopped/ar.avi --frames stopped/frames --quiet \
  2> "$L/err.log" || code=$?
[ $code = 3 ] || fail "ar on a take with another frame 2: exit $code: $(cat "$L/err.log")"
grep -q "frame 2" "$L/err.log" || fail "ar on a take with another frame 2: $(cat "$L/err.log")"
[ -z "$(ls -A stopped 2>/dev/null)" ] || fail "ar stopped at frame 2 left: $(ls -A stopped)"
code=0
$BC init grey-study --photo grey.png --camera take/camera.json > "$L/init.log" 2>&1 || code=$?
[ $code = 4 ] || fail "init on a photo with no board: exit $code: $(cat "$L/init.log")"
[ -z "$(ls -A | grep grey-study)" ] || fail "a failed init left $(ls -A | grep grey-study)"

# The photo study the adversary could not make (scene-no-board.png was never made): the default example with a
# photo of one's own now validates, its board-free line dropped.
$BC init photo-study --photo take/frame-0000.png --camera take/camera.json > "$L/init.log" 2>&1 ||
  fail "init with --photo: $(tail -3 "$L/init.log")"
grep -q board_free photo-study/protocol.json && fail "the photo study names a board-free photo it does not have"
echo "ok: $cases refusals, each exit 2 or 3 in one line naming the option and the path, none hung; every file" \
     "byte-identical afterwards and nothing new beside them; init --photo with the default example made a study"
