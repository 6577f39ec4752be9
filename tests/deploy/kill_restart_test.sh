#!/usr/bin/env bash
# Robustness of the deployed system: start every process of deploy/processes.txt under supervisord,
# kill -9 each one in turn, and check that supervisord restarts it (a new pid reports on the bus),
# that the others keep reporting, and that the arm driver is never left executing a motion.
#   kill_restart_test.sh SOURCE_DIR BUILD_DIR
set -euo pipefail
SRC="$1"; BUILD="$2"
TMP=$(mktemp -d)
export BOOKGRASP_BUILD_DIR="$BUILD"
export BOOKGRASP_RUN_DIR="$TMP/run"
export BOOKGRASP_LCM_URL="udpm://239.255.76.67:$((7700 + $$ % 90))?ttl=0&recv_buf_size=4194304"
FRONT="$SRC/deploy/bookgrasp"
MON="$BUILD/services/monitor/bookgrasp_monitor"
CONF="$TMP/run/supervisord.conf"
cleanup() { "$FRONT" stop >/dev/null 2>&1 || true; rm -rf "$TMP"; }
trap cleanup EXIT
fail() { echo "FAIL: $*"; tail -5 "$TMP/run/"*.log 2>/dev/null; exit 1; }

names=$(grep -v '^\s*#' "$SRC/deploy/processes.txt" | sed '/^\s*$/d' | grep -vw standby | awk '{print $1}')
all=$(echo $names | tr ' ' ',')
"$FRONT" start >/dev/null
"$MON" --lcm-url "$BOOKGRASP_LCM_URL" --expect "$all" --timeout 90 >/dev/null || fail "not every service came up"
for name in $names; do
  old=$(supervisorctl -c "$CONF" pid "$name")
  kill -9 "$old"
  new=$old
  for _ in $(seq 300); do
    new=$(supervisorctl -c "$CONF" pid "$name")
    [ "$new" -gt 0 ] && [ "$new" != "$old" ] && break
    sleep 0.1
  done
  [ "$new" != "$old" ] || fail "$name was not restarted after kill -9"
  # Every service, the restarted one included, reports again.
  "$MON" --lcm-url "$BOOKGRASP_LCM_URL" --expect "$all" --timeout 90 > "$TMP/table.txt" || fail "after killing $name: $(cat "$TMP/table.txt")"
  grep -E "^$name +" "$TMP/table.txt" | grep -q " $new " || fail "$name: the new pid $new is not the one reporting"
  if grep -qE "^arm_driver .*EXECUTING" "$TMP/table.txt"; then fail "arm driver executing after killing $name"; fi
  # Nobody rejects input because a neighbour restarted (e.g. a restarted simulation's clock starts over).
  rejecting=$(awk 'NR > 1 && $1 != "all" && $8 ~ /^[0-9]+$/ && $8 > 0 {print $1 " (" $8 ")"}' "$TMP/table.txt")
  [ -z "$rejecting" ] || fail "after killing $name these services reject input: $rejecting"
  echo "killed $name (pid $old): restarted as pid $new, all $(echo $names | wc -w) services reporting"
done
echo "PASS"
