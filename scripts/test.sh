#!/usr/bin/env bash
# Install what is missing, build, and run the whole test suite under ctest.
#   scripts/test.sh             Release build in build/
#   scripts/test.sh --sanitize  AddressSanitizer + UBSan build in build-sanitize/, with
#                               clang (the Release build is gcc's: CI compiles with both)
# With OOCSIMP_WERROR=1 in the environment (CI) a compiler warning fails the build
# (-DOOCSIMP_WERROR=ON); with OOCSIMP_WERROR=0 the build dir is set back to warnings.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
# Given as a configure argument, so scripts/build.sh configures again with it even
# where the build dir has a cache.
configure=()
case "${OOCSIMP_WERROR:-}" in
  1) configure+=(-DOOCSIMP_WERROR=ON) ;;
  0) configure+=(-DOOCSIMP_WERROR=OFF) ;;
  "") ;;
  *) echo "scripts/test.sh: OOCSIMP_WERROR must be 1 or 0, not '$OOCSIMP_WERROR'" >&2; exit 2 ;;
esac
"$root/scripts/setup-deps.sh"
if [ "${1:-}" = "--sanitize" ]; then
  export OOCSIMP_BUILD_DIR="$root/build-sanitize"
  # -O1 -g1: the optimisation and debug level AddressSanitizer's documentation
  # suggests (line tables are enough for its reports); the build takes about half
  # the time of -O2 -g, which keeps .ci/run within its 30 minutes.
  "$root/scripts/build.sh" -DOOCSIMP_SANITIZE=ON -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_C_COMPILER=clang \
    "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g1 -DNDEBUG" "-DCMAKE_C_FLAGS_RELWITHDEBINFO=-O1 -g1 -DNDEBUG" \
    ${configure[@]+"${configure[@]}"}
  export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1
else
  export OOCSIMP_BUILD_DIR="$root/build"
  "$root/scripts/build.sh" ${configure[@]+"${configure[@]}"}
fi
cd "$OOCSIMP_BUILD_DIR"
ctest --output-on-failure -j "$(nproc)"
