#!/usr/bin/env bash
# Idempotent set-up of a Debian bookworm machine (as root): installs the missing Debian packages of
# deploy/packages.txt, puts the multicast route on loopback, raises the UDP receive buffers, then
# configures and builds the project (Release, all cores) into build/.
#   deploy/setup.sh [--no-build]
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD_DIR="${BOOKGRASP_BUILD_DIR:-$ROOT/build}"
log() { echo "[setup] $*"; }

sudo_if_needed() { if [ "$(id -u)" -eq 0 ]; then "$@"; else sudo "$@"; fi; }

# 1. Debian packages
mapfile -t WANTED < <(grep -v '^\s*#' "$ROOT/deploy/packages.txt" | tr ' ' '\n' | sed '/^\s*$/d')
MISSING=()
for p in "${WANTED[@]}"; do
  [[ "$(dpkg-query -W -f='${Status}' "$p" 2>/dev/null || true)" == *"install ok installed"* ]] || MISSING+=("$p")
done
if [ ${#MISSING[@]} -gt 0 ]; then
  log "installing ${#MISSING[@]} missing Debian packages: ${MISSING[*]}"
  export DEBIAN_FRONTEND=noninteractive
  sudo_if_needed apt-get update -q
  sudo_if_needed apt-get install -y -q --no-install-recommends "${MISSING[@]}"
else
  log "all ${#WANTED[@]} Debian packages present"
fi

# 2. LCM over UDP multicast on loopback (not persistent across boots: done every time)
sudo_if_needed ip link set lo multicast on
if [[ "$(ip route show 224.0.0.0/4)" != *"dev lo"* ]]; then
  sudo_if_needed ip route add 224.0.0.0/4 dev lo 2>/dev/null || log "warning: could not add the multicast route on lo"
fi
log "multicast route: $(ip route show 224.0.0.0/4 | head -1)"

# 3. UDP receive buffers large enough for images (LCM drops big messages otherwise)
for key in net.core.rmem_max net.core.rmem_default; do
  cur=$(sysctl -n "$key" 2>/dev/null || echo 0)
  if [ "$cur" -lt 8388608 ]; then
    sudo_if_needed sysctl -q -w "$key=8388608" >/dev/null 2>&1 || log "warning: cannot raise $key (now $cur)"
  fi
done
log "rmem_max=$(sysctl -n net.core.rmem_max) rmem_default=$(sysctl -n net.core.rmem_default)"

# 4. Configure and build
if [ "${1:-}" != "--no-build" ]; then
  log "configuring and building into $BUILD_DIR (Release, $(nproc) jobs)"
  cmake -S "$ROOT" -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=Release -DBOOKGRASP_ONLY= >"$BUILD_DIR.configure.log" 2>&1 \
    || { cat "$BUILD_DIR.configure.log"; exit 1; }
  # Progress every 10 %; the full log is kept beside the build tree.
  set +e
  cmake --build "$BUILD_DIR" -j"$(nproc)" 2>&1 | tee "$BUILD_DIR.build.log" |
    awk 'match($0, /^\[ *[0-9]+%\]/) { p = substr($0, RSTART + 1, RLENGTH - 3) + 0;
         if (p >= next_p) { printf "[setup] build %d%%\n", p; fflush(); next_p = p - p % 10 + 10 } }'
  build_rc=${PIPESTATUS[0]}
  set -e
  if [ "$build_rc" -ne 0 ]; then
    grep -E "error|Error" "$BUILD_DIR.build.log" | head -40
    log "build failed: see $BUILD_DIR.build.log"
    exit 1
  fi
  warnings=$(grep -c "warning:" "$BUILD_DIR.build.log" || true)
  log "build log: $BUILD_DIR.build.log ($warnings compiler warnings)"
  log "build done"
fi
