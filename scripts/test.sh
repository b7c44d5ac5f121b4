#!/usr/bin/env bash
# Install what is missing, build, and run the whole test suite under ctest.
#   scripts/test.sh             Release build in build/
#   scripts/test.sh --sanitize  AddressSanitizer + UBSan build in build-sanitize/
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
"$root/scripts/setup-deps.sh"
if [ "${1:-}" = "--sanitize" ]; then
  export OOCSIMP_BUILD_DIR="$root/build-sanitize"
  "$root/scripts/build.sh" -DOOCSIMP_SANITIZE=ON -DCMAKE_BUILD_TYPE=RelWithDebInfo
  export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1
else
  export OOCSIMP_BUILD_DIR="$root/build"
  "$root/scripts/build.sh"
fi
cd "$OOCSIMP_BUILD_DIR"
ctest --output-on-failure -j "$(nproc)"
