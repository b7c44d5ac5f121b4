#!/usr/bin/env bash
# Configures (once) and builds oocsimp under build/ (or $OOCSIMP_BUILD_DIR); make only
# rebuilds what is stale. Extra arguments go to cmake's configure step. A configure
# that failed (a package missing) leaves a cache but no Makefile: it is run again.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${OOCSIMP_BUILD_DIR:-$root/build}"
mkdir -p "$build"
if [ ! -f "$build/CMakeCache.txt" ] || [ ! -f "$build/Makefile" ] || [ $# -gt 0 ]; then
  cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release "$@" >"$build/configure.log" 2>&1 ||
    { cat "$build/configure.log" >&2; exit 1; }
fi
if ! cmake --build "$build" -j "$(nproc)" >"$build/build.log" 2>&1; then
  cat "$build/build.log" >&2
  exit 1
fi
grep -E "warning:" "$build/build.log" >&2 || true
