#!/usr/bin/env bash
# Speed of the edge collapse to a target against meshopt_simplify, whole processes
# file to file, every run alternated in one invocation so that the machine's drift
# falls on both: the median wall and CPU seconds of each, and their ratios.
#
#   scripts/bench-collapse.sh                   the scans to 5000, the 2M sphere, parts
#                                               and terrain to 100000
#   scripts/bench-collapse.sh scan.ply ...      files of your own, to SCAN_TARGET
#   SIZE=20000000 SHAPES=sphere TARGET=580000 RUNS=3 THREADS="1 2" scripts/bench-collapse.sh
#   BASE_BIN=/path/to/older/oocsimp scripts/bench-collapse.sh   an older build alongside
#
# Environment: RUNS alternations per input (default 5); THREADS oocsimp's thread
# counts (default 2; meshopt_simplify runs on one); SHAPES and SIZE the generated
# inputs (default "sphere parts terrain", 2000000), cached under build/bench/;
# TARGET their output triangles (default 100000); SCAN_TARGET that of the scans and of
# files given (default 5000); MEM a --mem for oocsimp; BASE_BIN an older oocsimp run
# beside the current one, with the same options.
#
# Rows: median wall seconds, median CPU seconds (user + system), peak RSS, and the
# ratios of the medians over meshopt_simplify's (wall, CPU).
set -euo pipefail
source "$(dirname "$0")/bench-setup.sh"
meshopt_bin="${MESHOPT_BENCH_BIN:-$root/build/meshopt_bench}"
runs="${RUNS:-5}"
size="${SIZE:-2000000}"
target="${TARGET:-100000}"
scan_target="${SCAN_TARGET:-5000}"
threads=(${THREADS:-2})
mem_args=()
[ -n "${MEM:-}" ] && mem_args=(--mem "$MEM")
[ -x "$meshopt_bin" ] || { echo "bench-collapse.sh: $meshopt_bin is not built (libmeshoptimizer-dev)" >&2; exit 1; }

inputs=() targets=()
if [ $# -gt 0 ]; then
  for f in "$@"; do inputs+=("$f") targets+=("$scan_target"); done
else
  if [ -z "${SHAPES+x}" ]; then
    for f in $("$root/scripts/fetch-scans.sh"); do inputs+=("$f") targets+=("$scan_target"); done
  fi
  for shape in ${SHAPES:-sphere parts terrain}; do
    mesh="$dir/$shape-$size.ply"
    [ -f "$mesh" ] || "$bin" generate --tris "$size" --shape "$shape" --seed 1 --quiet -o "$mesh"
    inputs+=("$mesh") targets+=("$target")
  done
fi

out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
# timed NAME CMD...: one run; appends "wall cpu rss_mib" to $out/NAME.
timed() {
  local name=$1
  shift
  python3 - "$@" >>"$out/$name" <<'PY'
import resource, subprocess, sys, time
t0 = time.perf_counter()
subprocess.run(sys.argv[1:], check=True, stdout=subprocess.DEVNULL)
wall = time.perf_counter() - t0
u = resource.getrusage(resource.RUSAGE_CHILDREN)
print("%.4f %.4f %.1f" % (wall, u.ru_utime + u.ru_stime, u.ru_maxrss / 1024))
PY
}
median() {  # median FILE COLUMN
  sort -g -k"$2,$2" "$1" | awk -v c="$2" '{v[NR] = $c} END {print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2}'
}
row() {  # row NAME LABEL
  local w c r
  w=$(median "$out/$1" 1)
  c=$(median "$out/$1" 2)
  r=$(median "$out/$1" 3)
  printf '  %-22s %9.3f %9.3f %9.1f %9s %9s\n' "$2" "$w" "$c" "$r" \
    "$(ratio "$w" "$(median "$out/meshopt" 1)")" "$(ratio "$c" "$(median "$out/meshopt" 2)")"
}

for i in "${!inputs[@]}"; do
  mesh=${inputs[$i]} tris=${targets[$i]}
  cat "$mesh" >/dev/null  # a warm page cache for every run
  rm -f "$out"/[a-z]*
  echo "input $mesh to $tris triangles, $runs runs alternated${MEM:+, oocsimp --mem $MEM}"
  for ((k = 0; k < runs; k++)); do
    timed meshopt "$meshopt_bin" simplify "$mesh" "$out/m.ply" "$tris"
    for t in "${threads[@]}"; do
      timed "oocsimp-t$t" "$bin" simplify "$mesh" -o "$out/o.ply" --target-tris "$tris" --threads "$t" --quiet \
        ${mem_args[@]+"${mem_args[@]}"}
      [ -n "${BASE_BIN:-}" ] && timed "base-t$t" "$BASE_BIN" simplify "$mesh" -o "$out/b.ply" --target-tris "$tris" \
        --threads "$t" --quiet ${mem_args[@]+"${mem_args[@]}"}
    done
  done
  printf '  %-22s %9s %9s %9s %9s %9s\n' run wall_s cpu_s rss_MiB wall/mopt cpu/mopt
  row meshopt "meshopt_simplify"
  for t in "${threads[@]}"; do
    row "oocsimp-t$t" "oocsimp --threads $t"
    [ -n "${BASE_BIN:-}" ] && row "base-t$t" "base --threads $t"
  done
done
