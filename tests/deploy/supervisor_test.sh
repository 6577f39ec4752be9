#!/usr/bin/env bash
# The deploy front door with a real supervisord: start a process, see it alive on the bus, kill it,
# see supervisord restart it (new pid in SERVICE_STATUS), stop everything cleanly.
#   supervisor_test.sh SOURCE_DIR BUILD_DIR
set -euo pipefail
SRC="$1"; BUILD="$2"
TMP=$(mktemp -d)
PORT=$((7100 + $$ % 500))
export BOOKGRASP_BUILD_DIR="$BUILD"
export BOOKGRASP_RUN_DIR="$TMP/run"
export BOOKGRASP_LCM_URL="udpm://239.255.76.67:$PORT?ttl=0&recv_buf_size=4194304"
export BOOKGRASP_PROCESSES="$TMP/processes.txt"
echo "test_echo tests/common/bookgrasp_test_echo tests/common/echo.yaml" > "$BOOKGRASP_PROCESSES"
FRONT="$SRC/deploy/bookgrasp"
MON="$BUILD/services/monitor/bookgrasp_monitor"
cleanup() { "$FRONT" stop >/dev/null 2>&1 || true; rm -rf "$TMP"; }
trap cleanup EXIT
fail() { echo "FAIL: $*"; cat "$TMP/run/"*.log 2>/dev/null | tail -20; exit 1; }

"$FRONT" start
"$MON" --lcm-url "$BOOKGRASP_LCM_URL" --expect test_echo --timeout 20 || fail "echo never reported alive"
pid1=$(supervisorctl -c "$TMP/run/supervisord.conf" pid test_echo)
[ "$pid1" -gt 0 ] || fail "no pid"
kill -9 "$pid1"
for _ in $(seq 100); do
  pid2=$(supervisorctl -c "$TMP/run/supervisord.conf" pid test_echo)
  [ "$pid2" -gt 0 ] && [ "$pid2" != "$pid1" ] && break
  sleep 0.1
done
[ "$pid2" != "$pid1" ] || fail "supervisord did not restart the killed process"
out=$("$MON" --lcm-url "$BOOKGRASP_LCM_URL" --once --seconds 2)
echo "$out"
grep -q "test_echo" <<< "$out" || fail "restarted process not on the bus"
"$FRONT" stop
kill -0 "$pid2" 2>/dev/null && fail "process still running after stop"
echo "PASS: started, restarted after kill -9 (pid $pid1 -> $pid2), stopped"
