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
