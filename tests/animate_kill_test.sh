#!/usr/bin/env bash
# What a kill -9 of `animate --video` leaves: usage: animate_kill_test.sh BLURCUE CALIB PHOTO DIR
# The video is written beside its place (.NAME.partial-PID/NAME) and renamed once whole, so a killed run leaves the
# earlier video byte for byte (it used to write straight to --video: half a video under the final name), and the
# next run removes the killed one's partial folder.
set -euo pipefail
BC=$1 CALIB=$2 PHOTO=$3 W=$4
source "$(dirname "$0")/lib.sh"
rm -rf "$W" && mkdir -p "$W"
animate() { $BC animate --calib "$CALIB" --background "$PHOTO" --left measured --right none --fps 30 "$@"; }
animate --speed-cm-s 50 --video "$W/anim.avi" > /dev/null 2>&1 || fail "the first animate"
before=$(md5sum < "$W/anim.avi")
# About 600 frames: long enough to be killed midway.
$BC animate --calib "$CALIB" --background "$PHOTO" --left measured --right none --fps 30 --speed-cm-s 1.3 \
  --video "$W/anim.avi" > /dev/null 2>&1 &
pid=$!
# Until frames are being written (the partial video grows, or - the old way - anim.avi changes), up to 120 s.
for _ in $(seq 1 1200); do
  partial=$(find "$W" -path "*partial*" -name anim.avi -size +20k 2>/dev/null | head -1)
  [ -n "$partial" ] && break
  [ "$(md5sum < "$W/anim.avi")" != "$before" ] && break
  kill -0 $pid 2>/dev/null || fail "animate ended before it was killed"
  sleep 0.1
done
kill -9 $pid
wait $pid 2>/dev/null || true
[ "$(md5sum < "$W/anim.avi")" = "$before" ] ||
  fail "a killed animate changed anim.avi ($(stat -c %s "$W/anim.avi") bytes now): half a video under its name"
[ -n "$(ls -A "$W" | grep "^\.anim\.avi\.partial-$pid$")" ] || fail "no .anim.avi.partial-$pid left to clean: $(ls -A "$W")"
animate --speed-cm-s 50 --video "$W/anim.avi" > /dev/null 2>&1 || fail "animate after the kill"
left=$(ls -A "$W" | grep -v '^anim\.avi$' || true)
[ -z "$left" ] || fail "the next animate left: $left"
echo "ok: a killed animate --video left the earlier video unchanged; the next run removed .anim.avi.partial-$pid"
