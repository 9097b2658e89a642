#!/usr/bin/env bash
# Installed and moved: `cmake --install` into a temporary prefix, the prefix moved elsewhere (relocatable), and the
# installed binary run from another folder finds its shaders, stimuli and analysis beside itself (blurcue info says
# "installed"), and makes a scene, a render, a validated protocol, a simulated session and a report.
# usage: install_test.sh BUILD_DIR WORK_DIR
set -euo pipefail
BUILD=$1 W=$2
source "$(dirname "$0")/lib.sh"
install_moved "$BUILD"
$BC info > info.txt || fail "info: $(cat info.txt)"
grep -q "^data: *$W/moved/share/blurcue (installed)" info.txt || fail "not found beside the binary: $(cat info.txt)"
grep -q "^media: *$W/moved/lib/blurcue/libblurcue_media.so" info.txt || fail "media plugin not beside the binary: $(cat info.txt)"
# Every relative link of the installed protocols' README (and the installed docs') leads to an installed file.
$PY - "$W/moved/share/blurcue" <<'PYEOF' || fail "installed documentation links"
import os, re, sys
root = sys.argv[1]
pages = [os.path.join(root, "protocols", "README.md")] + [os.path.join(root, "docs", f)
                                                          for f in os.listdir(os.path.join(root, "docs")) if f.endswith(".md")]
broken = []
for page in pages:
    for target in re.findall(r"\]\(([^)#]+)(?:#[^)]*)?\)", open(page, encoding="utf-8").read()):
        if re.match(r"[a-z]+:", target):
            continue
        if target.startswith(("../src/", "../tests/", "../scripts/", "../analysis/", "../cmake/", "../.ci/")):
            continue  # the source tree's files, not installed: these pages are read in a clone as well
        if not os.path.exists(os.path.normpath(os.path.join(os.path.dirname(page), target))):
            broken.append(f"{os.path.relpath(page, root)} -> {target}")
assert os.path.exists(os.path.join(root, "protocols", "README.md")), "no protocols/README.md"
assert not broken, "; ".join(broken[:5])
PYEOF
$BC synth-scene --out scene --seed 5 > /dev/null
$BC calibrate scene/scene.png --camera scene/camera.json --out calib.json > /dev/null
$BC render --calib calib.json --background scene/scene.png --object ball --at-edge 9 --blur estimated \
    --out ball.png > /dev/null || fail "render"
[ -s ball.png ] || fail "no render"
sed 's|"\.\./results/demo/|"'"$PWD"'/|g' "$W/moved/share/blurcue/protocols/test1-static-grids.json" > p.json
$BC validate p.json > /dev/null || fail "validate: $($BC validate p.json 2>&1 | tail -2)"
$BC run p.json --participant P1 --db s.sqlite --observer sim > /dev/null 2>&1 || fail "run"
MPLCONFIGDIR=$W/mpl $BC report --db s.sqlite --out report --bench nowhere > /dev/null 2> report.err \
    || fail "report: $(tail -2 report.err)"
[ -s report/index.html ] && [ -s report/test1-per-edge.png ] || fail "no report"
echo "ok: installed to a prefix, moved, and run from elsewhere: info, scene, render, validate, session and report"
