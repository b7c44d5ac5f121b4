#!/usr/bin/env bash
# Velho's 4-k hierarchy (`oocsimp hierarchy`, `extract`) against oocsimp's QEM and
# meshopt_simplify at the same counts, every run in one invocation.
#
#   scripts/bench-hierarchy.sh                        generated sphere, terrain and parts of 200k triangles
#   scripts/bench-hierarchy.sh $(scripts/fetch-scans.sh)     the bunny and the armadillo
#   SIZE=1000000 SHAPES=sphere scripts/bench-hierarchy.sh
#
# For each input: the build's wall time beside `simplify --method qem` to the coarsest
# level's count (and their ratio), the file's size over the input's, each level's
# triangles and its ratio to the level before, then for every other level down to
# MIN_TRIS (default 500): the RMS and Hausdorff distances (symmetric, as fractions of
# the input's bounding-box diagonal, `oocsimp measure`) of the level, of QEM and of
# meshopt_simplify at its count, and the ratios; and the seconds extracting the finest,
# a middle and the coarsest level take, file to file.
# Environment: SHAPES, SIZE (generated inputs, cached under build/bench/), SAMPLES
# (points `oocsimp measure` samples, default 1000000), THREADS (oocsimp's, default 2),
# MIN_TRIS, FLAGS (more `oocsimp hierarchy` options, e.g. FLAGS=--sequential),
# PLACEMENT (`extract --placement`: quadric, the default, or kept).
set -euo pipefail
source "$(dirname "$0")/bench-setup.sh"
meshopt_bin="${MESHOPT_BENCH_BIN:-$root/build/meshopt_bench}"
samples="${SAMPLES:-1000000}"
threads="${THREADS:-2}"
size="${SIZE:-200000}"
min_tris="${MIN_TRIS:-500}"
placement="${PLACEMENT:-quadric}"
out="$dir/hierarchy-bench"
mkdir -p "$out"

inputs=("$@")
if [ ${#inputs[@]} -eq 0 ]; then
  for shape in ${SHAPES:-sphere terrain parts}; do
    mesh="$dir/$shape-$size.ply"
    [ -f "$mesh" ] || "$bin" generate --tris "$size" --shape "$shape" --seed 1 --quiet -o "$mesh"
    inputs+=("$mesh")
  done
fi

rms_of() {  # rms_of MESH RESULT -> "rms hausdorff"
  "$bin" measure "$1" "$2" --samples "$samples" --json --quiet >"$out/measure.json"
  measured "$out/measure.json"
}

for mesh in "${inputs[@]}"; do
  cat "$mesh" >/dev/null
  h="$out/h.4k"
  echo "input $mesh, hierarchy --threads $threads ${FLAGS:-}, extract --placement $placement, measure --samples $samples"
  t0=$(now)
  # shellcheck disable=SC2086
  "$bin" hierarchy "$mesh" -o "$h" --threads "$threads" --quiet ${FLAGS:-} >"$out/build.txt"
  t1=$(now)
  "$bin" info "$h" >"$out/info.txt"
  levels=$(awk '/^level/ {on = 1; next} on {n++} END {print n}' "$out/info.txt")
  coarsest=$(tail -1 "$out/info.txt" | awk '{print $2}')
  t2=$(now)
  "$bin" simplify "$mesh" -o "$out/qem.ply" --method qem --target-tris "$coarsest" --threads "$threads" --quiet
  t3=$(now)
  build=$(calc "$t1 - $t0")
  qem=$(calc "$t3 - $t2")
  in_bytes=$(stat -c %s "$mesh")
  h_bytes=$(stat -c %s "$h")
  printf 'build %.3f s, qem to the coarsest (%s triangles) %.3f s: %s; %s; file %s of the input (%d levels)\n' \
    "$build" "$coarsest" "$qem" "$(ratio "$build" "$qem")" "$(grep peak "$out/build.txt" | sed 's/.*; //')" \
    "$(ratio "$h_bytes" "$in_bytes")" "$levels"
  echo "$(grep '^records' "$out/info.txt")"
  echo "levels (triangles/ratio): $(awk '/^level/ {on = 1; next} on {printf "%s/%s ", $2, $4}' "$out/info.txt")"
  printf '%5s %9s %11s %11s %11s %11s %11s %9s %9s %9s\n' level tris rms_4k rms_qem rms_meshopt haus_4k haus_qem \
    rms/qem rms/mopt haus/qem
  for ((j = 1; j < levels; j += 2)); do
    tris=$(awk -v j="$j" '/^level/ {on = 1; next} on && $1 == j {print $2}' "$out/info.txt")
    [ "$tris" -ge "$min_tris" ] || break
    "$bin" extract "$h" -o "$out/level.ply" --level "$j" --placement "$placement"
    "$bin" simplify "$mesh" -o "$out/qem.ply" --method qem --target-tris "$tris" --threads "$threads" --quiet
    read -r r4 h4 <<<"$(rms_of "$mesh" "$out/level.ply")"
    read -r rq hq <<<"$(rms_of "$mesh" "$out/qem.ply")"
    rm_="-" rmr="-"
    if [ -x "$meshopt_bin" ]; then
      "$meshopt_bin" simplify "$mesh" "$out/mopt.ply" "$tris" >/dev/null
      read -r rm_ _ <<<"$(rms_of "$mesh" "$out/mopt.ply")"
      rmr=$(ratio "$r4" "$rm_")
      rm_=$(printf '%.3e' "$rm_")
    fi
    printf '%5s %9s %11.3e %11.3e %11s %11.3e %11.3e %9s %9s %9s\n' "$j" "$tris" "$r4" "$rq" "$rm_" "$h4" "$hq" \
      "$(ratio "$r4" "$rq")" "$rmr" "$(ratio "$h4" "$hq")"
  done
  for j in 0 $((levels / 2)) $((levels - 1)); do
    t0=$(now)
    "$bin" extract "$h" -o "$out/level.ply" --level "$j" --placement "$placement"
    t1=$(now)
    printf 'extract --level %s: %.3f s\n' "$j" "$(calc "$t1 - $t0")"
  done
  echo
done
[ -n "${KEEP:-}" ] || rm -rf "$out"
