#!/usr/bin/env bash
# Approximation quality: floating cells against the uniform grid at the same cell size,
# measured with `oocsimp measure` (symmetric distance, as a fraction of the original's
# bounding-box diagonal), on generated meshes cached under build/bench/.
#
#   scripts/quality.sh                         sphere and parts, 2M triangles
#   SIZE=10000000 SAMPLES=1000000 scripts/quality.sh "sphere 0.0325" "parts 0.0125"
#
# Each argument is "SHAPE CELL"; both methods run at that --cell.
set -euo pipefail
source "$(dirname "$0")/bench-setup.sh"
size="${SIZE:-2000000}"
samples="${SAMPLES:-1000000}"
cases=("$@")
[ ${#cases[@]} -eq 0 ] && cases=("sphere 0.0325" "parts 0.0125")

printf '%-8s %-9s %8s %10s %11s %15s\n' shape method cell triangles rms/diag hausdorff/diag
for c in "${cases[@]}"; do
  read -r shape cell <<<"$c"
  mesh="$dir/$shape-$size.ply"
  [ -f "$mesh" ] || "$bin" generate --tris "$size" --shape "$shape" --seed 1 --quiet -o "$mesh"
  for method in uniform floating; do
    "$bin" simplify "$mesh" -o "$dir/q.ply" --method "$method" --cell "$cell" --quiet --stats "$dir/q.json"
    tris=$(output_triangles "$dir/q.json")
    "$bin" measure "$mesh" "$dir/q.ply" --samples "$samples" --json --quiet >"$dir/m.json"
    rel=$(grep '"symmetric"' "$dir/m.json" |
      sed -E 's/.*"of_diagonal": \{"hausdorff": ([^,]*), "mean": [^,]*, "rms": ([^}]*)\}.*/\2 \1/' |
      awk '{printf "%.3e %.3e", $1, $2}')
    printf '%-8s %-9s %8s %10s %11s %15s\n' "$shape" "$method" "$cell" "$tris" $rel
  done
done
rm -f "$dir/q.ply" "$dir/q.json" "$dir/m.json"
