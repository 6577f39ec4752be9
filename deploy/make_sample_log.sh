#!/usr/bin/env bash
# Records a small sample log of the running system for the replay tests: every process of
# deploy/processes.txt, cameras publishing JPEG (so the log stays small), from the system's start
# until N seconds of wall time after all services report alive.
#   deploy/make_sample_log.sh OUT.lcm [SECONDS]
# logs/samples/system_jpeg.lcm: `deploy/make_sample_log.sh logs/samples/system_jpeg.lcm 20` on an idle machine
# (a loaded one drops frames and the replay tests then report them missing); the stereo camera at 4 Hz keeps the
# 20 s at ~25 MB (re-recorded 2026-12-02 on far_cart.yaml for the stereo-ranged markers; 20 s end inside the
# first stripe servo, so the arbiter is replayed on logs/samples/arbiter_seed5.lcm instead; re-recorded 2026-12-03 for
# the BwS selection changes of stop 17; re-recorded 2026-12-05 for BwS's top_growth_climbed_only, stop 30, and for
# GoD's smoothed gradients, stop 34, and for the front layer and the hole budget of stop 35; re-recorded 2026-12-07
# with 35 s for BSwH's colour check, stop 45: with 20 and 25 s the log ended early in the stripe servo, 79 and 48
# SERVO_STATUS, fewer than the visual servo's replay test needs); re-recorded 2026-12-07 (35 s, 38 MB) for BwS's
# front_plane (stop 46: 45 of the old sample's 74 P1s moved); re-recorded 2026-12-08 (35 s) for BwS's top_crease
# (stop 47).
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
OUT="$1"; SECONDS_TO_RECORD="${2:-3}"
TMP=$(mktemp -d)
export BOOKGRASP_RUN_DIR="$TMP/run"
export BOOKGRASP_LCM_URL="udpm://239.255.76.67:7611?ttl=0&recv_buf_size=4194304"
cleanup() { "$ROOT/deploy/bookgrasp" stop >/dev/null 2>&1 || true; rm -rf "$TMP"; }
trap cleanup EXIT
# The same processes (deploy/processes.txt), the cameras publishing JPEG (a --set override).
export BOOKGRASP_SET="${BOOKGRASP_SET:-} stereo_camera:image_encoding=jpeg hand_camera:image_encoding=jpeg stereo_camera:sim.frame_rate_hz=4"
names=$(grep -v '^\s*#' "$ROOT/deploy/processes.txt" | sed '/^\s*$/d' | grep -vw standby | awk '{print $1}' | paste -sd, -)
# The logger starts first, so the recording holds every input from the system's start: a replay then
# sees exactly what the live processes saw (no state from before the log).
rm -f "$OUT"
lcm-logger --lcm-url="$BOOKGRASP_LCM_URL" --quiet --force "$OUT" &
logger=$!
"$ROOT/deploy/bookgrasp" start
"$ROOT/build/services/monitor/bookgrasp_monitor" --lcm-url "$BOOKGRASP_LCM_URL" --expect "$names" --timeout 60 >/dev/null
sleep "$SECONDS_TO_RECORD"
"$ROOT/deploy/bookgrasp" stop >/dev/null
kill -INT "$logger"
wait "$logger" || true
[ -s "$OUT" ] || { echo "error: lcm-logger wrote nothing to $OUT" >&2; exit 1; }
echo "wrote $OUT ($(du -h "$OUT" | cut -f1))"
