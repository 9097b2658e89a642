# The shared part of the session tests (session_test.sh, session_design_test.sh, session_display_test.sh): sourced
# after CASE, BC and DIR are set; sets P (the protocols) and W (this case's folder, made empty) and the helpers.
P=$DIR/protocols
W=$DIR/session-$CASE
rm -rf "$W" && mkdir -p "$W"
source "$(dirname "$0")/lib.sh"
# Everything a session decided (not when it was answered): trials, choices, response times, steps, frames.
fingerprint() {
  sql "$1" "SELECT t.trial_index, t.block, t.factors, t.left_shown, t.right_shown, r.choice, printf('%.3f', r.rt_ms),
            r.adjustment, (SELECT count(*) FROM frames f WHERE f.trial_id = t.id)
            FROM trials t JOIN sessions s ON s.id = t.session_id JOIN participants p ON p.id = s.participant_id
            LEFT JOIN responses r ON r.trial_id = t.id WHERE p.code = '$2' ORDER BY t.trial_index"
}
# Waits (up to 30 s) until the record at $1 holds at least $2 answers.
wait_for_answers() {
  for _ in $(seq 1 600); do
    n=$(sql "$1" "SELECT count(*) FROM responses" 2>/dev/null || echo 0)
    [ "${n:-0}" -ge "$2" ] && return 0
    sleep 0.05
  done
}
# Window tests: waits (up to 20 s) until the window's title ends with $1 (the runner names the screen or the trial
# on show), then presses key $2 or clicks button $3 there. A key that ends the run may close the window between
# xdotool's key-down and key-up: `last=1 at ...` lets that key's window vanish (the record is checked after).
at() {
  local wid
  wid=$(timeout 20 xdotool search --sync --name "$1\$" | head -1) || fail "no window titled ...$1"
  sleep 0.15
  if [ -n "${3:-}" ]; then
    xdotool mousemove --window "$wid" 200 200 click "$3" 2>> "$W/xdotool.log" || fail "click $3 at '$1': $(tail -1 "$W/err") $(run_status)"
  else
    xdotool key --window "$wid" "$2" 2>> "$W/xdotool.log" || [ -n "${last:-}" ] ||
      fail "key $2 at '$1': $(tail -1 "$W/err") $(run_status)"
  fi
}
# How the run in the background ended, when a window test finds its window gone.
run_status() { if [ -n "${run:-}" ] && ! kill -0 "$run" 2>/dev/null; then wait "$run"; echo "(run exited with $?)"; fi; }
integrity() { [ "$(sql "$1" 'PRAGMA integrity_check')" = ok ] || fail "integrity_check of $1"; }

