#!/usr/bin/env bash
# Curvature clustering against the other clusterings at equal output counts, every
# run in one invocation, errors from `oocsimp measure`.
#
#   scripts/bench-curvature.sh                     generated parts and terrain of 200k triangles
#   scripts/bench-curvature.sh $(scripts/fetch-scans.sh)    the bunny and the armadillo
#   SIZE=2000000 SHAPES=parts GRID=120 scripts/bench-curvature.sh
#
# For each input, `--method curvature --grid GRID` (default 60) gives N triangles (and
# the same with --rep vertex, the paper's representative); uniform and floating are then run at the grid whose
# count is nearest N (a bisection on --grid), meshopt_simplifySloppy is given N.
# Environment: SHAPES, SIZE (generated inputs, cached under build/bench/), GRID,
# SAMPLES (points `oocsimp measure` samples, default 1000000), THREADS (oocsimp's,
# default 2; sloppy runs on one), CURVATURE_ARGS (more options of the curvature runs,
# such as "--max-depth 1 --curvature-tolerance 0.25"), RUNS (which rows, default
# "curvature curvature-vertex uniform floating sloppy"; curvature first), OUT (the
# scratch folder, default build/bench/curvature-bench).
#
# Rows: wall seconds file to file, output triangles, RMS and Hausdorff distances
# (symmetric, as fractions of the input's bounding-box diagonal), the output's
# boundary and non-manifold edges (scripts/mesh_topology.py) next to the input's, and
# the ratios of this invocation: RMS over uniform's and over sloppy's, Hausdorff over
# uniform's.
set -euo pipefail
source "$(dirname "$0")/bench-setup.sh"
meshopt_bin="${MESHOPT_BENCH_BIN:-$root/build/meshopt_bench}"
grid="${GRID:-60}"
samples="${SAMPLES:-1000000}"
threads="${THREADS:-2}"
size="${SIZE:-200000}"
out="${OUT:-$dir/curvature-bench}"
mkdir -p "$out"

inputs=("$@")
if [ ${#inputs[@]} -eq 0 ]; then
  for shape in ${SHAPES:-parts terrain}; do
    mesh="$dir/$shape-$size.ply"
    [ -f "$mesh" ] || "$bin" generate --tris "$size" --shape "$shape" --seed 1 --quiet -o "$mesh"
    inputs+=("$mesh")
  done
fi

topology() { python3 "$root/scripts/mesh_topology.py" "$1" | sed -E 's/.* ([0-9]+) boundary .* ([0-9]+) non-manifold .*/\1\/\2/'; }

# clustered METHOD GRID RESULT -> the output triangles of --method METHOD --grid GRID
clustered() {
  "$bin" simplify "$mesh" -o "$3" --method "$1" --grid "$2" --threads "$threads" --quiet --stats "$out/stats.json"
  output_triangles "$out/stats.json"
}

# nearest_grid METHOD N -> the grid whose output count is nearest N (counts grow with the grid)
nearest_grid() {
  local lo=2 hi=4096 mid count best="" best_gap=""
  while [ $((hi - lo)) -gt 1 ]; do
    mid=$(((lo + hi) / 2))
    count=$(clustered "$1" "$mid" "$out/probe.ply")
    if [ "$count" -lt "$2" ]; then lo=$mid; else hi=$mid; fi
  done
  for g in $lo $hi; do
    count=$(clustered "$1" "$g" "$out/probe.ply")
    gap=$(awk -v a="$count" -v b="$2" 'BEGIN { d = a - b; print d < 0 ? -d : d }')
    if [ -z "$best" ] || [ "$gap" -lt "$best_gap" ]; then best=$g best_gap=$gap; fi
  done
  echo "$best"
}

for mesh in "${inputs[@]}"; do
  cat "$mesh" >/dev/null
  echo "input $mesh ($(topology "$mesh") boundary/non-manifold edges), curvature --grid $grid ${CURVATURE_ARGS:-}, measure --samples $samples, oocsimp --threads $threads"
  declare -A secs=() tris=() rms=() haus=() topo=() note=()
  runs=()
  for r in ${RUNS:-curvature curvature-vertex uniform floating sloppy}; do
    result="$out/$r.ply"
    echo "  $r ..." >&2
    case "$r" in
      curvature | curvature-vertex)
        # shellcheck disable=SC2206
        args=(--method curvature --grid "$grid" ${CURVATURE_ARGS:-})
        [ "$r" = curvature-vertex ] && args+=(--rep vertex)
        t0=$(now)
        "$bin" simplify "$mesh" -o "$result" "${args[@]}" --threads "$threads" --quiet --stats "$out/stats.json"
        t1=$(now)
        tris[$r]=$(output_triangles "$out/stats.json")
        ;;
      uniform | floating)
        g=$(nearest_grid "$r" "${tris[curvature]}")
        t0=$(now)
        tris[$r]=$(clustered "$r" "$g" "$result")
        t1=$(now)
        note[$r]="grid $g"
        ;;
      sloppy)
        if [ ! -x "$meshopt_bin" ]; then
          echo "  sloppy: skipped, $meshopt_bin is not built"
          continue
        fi
        t0=$(now)
        line=$("$meshopt_bin" sloppy "$mesh" "$result" "${tris[curvature]}")
        t1=$(now)
        tris[$r]=$(awk '{for (i = 1; i < NF; i++) if ($i == "triangles") print $(i + 1)}' <<<"$line")
        ;;
    esac
    secs[$r]=$(calc "$t1 - $t0")
    "$bin" measure "$mesh" "$result" --samples "$samples" --json --quiet >"$out/measure.json"
    read -r rms[$r] haus[$r] <<<"$(measured "$out/measure.json")"
    topo[$r]=$(topology "$result")
    runs+=("$r")
  done
  printf '%-18s %9s %9s %11s %11s %13s %10s %10s %10s  %s\n' method seconds out_tris rms/diag haus/diag \
    open/nm rms/unif rms/sloppy haus/unif note
  for r in "${runs[@]}"; do
    printf '%-18s %9.3f %9s %11.3e %11.3e %13s %10s %10s %10s  %s\n' "$r" "${secs[$r]}" "${tris[$r]}" "${rms[$r]}" \
      "${haus[$r]}" "${topo[$r]}" "$(ratio "${rms[$r]}" "${rms[uniform]}")" \
      "$([ -n "${rms[sloppy]:-}" ] && ratio "${rms[$r]}" "${rms[sloppy]}" || echo -)" \
      "$(ratio "${haus[$r]}" "${haus[uniform]}")" "${note[$r]:-}"
  done
  echo
  unset secs tris rms haus topo note
done
[ -n "${KEEP:-}" ] || rm -rf "$out"
