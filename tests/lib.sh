# Helpers the shell tests share (sourced): fail MESSAGE, and sql DB QUERY printing rows as a|b|c through Debian's
# python3 (no sqlite3 command-line tool needed).
PY=/usr/bin/python3
fail() { echo "FAIL: $*" >&2; exit 1; }
sql() { $PY - "$1" "$2" <<'PYEOF'
import sqlite3, sys
con = sqlite3.connect(sys.argv[1])
for row in con.execute(sys.argv[2]):
    print("|".join("" if v is None else str(v) for v in row))
PYEOF
}
