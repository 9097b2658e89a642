# Helpers the shell tests share (sourced): fail MESSAGE; sql DB QUERY printing rows as a|b|c through Debian's
# python3 (no sqlite3 command-line tool needed); start_xvfb, an X server of the test's own in $W.
PY=/usr/bin/python3
fail() { echo "FAIL: $*" >&2; exit 1; }
sql() { $PY - "$1" "$2" <<'PYEOF'
import sqlite3, sys
con = sqlite3.connect(sys.argv[1])
for row in con.execute(sys.argv[2]):
    print("|".join("" if v is None else str(v) for v in row))
PYEOF
}
# An X server of its own on a display it picks itself (-displayfd: no clash with another test's server); up to 20 s
# to start on a loaded machine. Sets DISPLAY; the server ends with the test.
start_xvfb() {
  Xvfb -displayfd 3 -screen 0 1280x1024x24 -nolisten tcp 3> "$W/display" > "$W/xvfb.log" 2>&1 &
  xvfb=$!
  trap 'kill $xvfb 2>/dev/null || true' EXIT
  for _ in $(seq 1 400); do [ -s "$W/display" ] && break; sleep 0.05; done
  [ -s "$W/display" ] || fail "Xvfb did not start in 20 s: $(cat "$W/xvfb.log")"
  export DISPLAY=":$(head -1 "$W/display")"
}
# blurcue installed into a temporary prefix that is then moved (relocatable), run from an empty folder of its own:
# install_moved BUILD_DIR  (with W set) - W is made afresh, blurcue is installed to W/prefix and moved to W/moved,
# BC is the moved binary, the shell is in the empty W/elsewhere, and no variable points blurcue at a source tree.
install_moved() {
  rm -rf "$W" && mkdir -p "$W/elsewhere"
  # One install at a time from a build folder: cmake --install writes BUILD/install_manifest.txt, which three tests
  # installing at once under ctest -j2 would write together.
  flock "$1/.install-lock" cmake --install "$1" --prefix "$W/prefix" > "$W/install.log" ||
    fail "install: $(tail -3 "$W/install.log")"
  mv "$W/prefix" "$W/moved"
  BC=$W/moved/bin/blurcue
  cd "$W/elsewhere"
  unset BLURCUE_DATA_DIR BLURCUE_SHADER_DIR
}

# expect CODE TEXT ARGS...: $BC ARGS exits CODE within ${EXPECT_TIMEOUT:-20} s with one line on stderr (in $L/err.log)
# holding TEXT; counts the case in $cases (outputs_guard_test.sh, outputs_own_test.sh).
expect() {
  local code=$1 text=$2 got=0 limit=${EXPECT_TIMEOUT:-20}
  shift 2
  timeout "$limit" $BC "$@" > "$L/out.log" 2> "$L/err.log" < /dev/null || got=$?
  [ $got != 124 ] || fail "$*: still running after $limit s"
  [ $got = "$code" ] || fail "$*: exit $got, expected $code: $(head -5 "$L/err.log")"
  [ "$(wc -l < "$L/err.log")" = 1 ] || fail "$*: not one line: $(head -5 "$L/err.log")"
  grep -qF -- "$text" "$L/err.log" || fail "$*: the message does not say '$text': $(cat "$L/err.log")"
  cases=$((cases + 1))
}
