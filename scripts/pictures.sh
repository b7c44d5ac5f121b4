#!/usr/bin/env bash
# The README's pictures (docs/*.png): generated inputs and their simplifications, drawn
# by `oocsimp render` from the same view, so that the methods can be compared by eye.
#
#   scripts/pictures.sh            builds if needed, writes docs/*.png
#
# For each of the generated parts (CAD-like, sharp edges) and terrain meshes: the
# input, uniform and floating clustering at the same cell (--grid G), and the exact
# target (floating phase 1, then edge collapse) at the floating result's triangle count;
# then the branches model with and without thick edges.
# Every picture is 480x360 and stays under 200 KB.
set -euo pipefail
source "$(dirname "$0")/bench-setup.sh"
out="$root/docs"
mkdir -p "$out"
rm -f "$out"/parts-*.png "$out"/terrain-*.png  # names carry the grid and count
size=480x360

picture() {  # picture MESH NAME VIEW
  "$bin" render "$1" -o "$out/$2.png" --size "$size" --view "$3" --quiet
  echo "docs/$2.png  $("$bin" info "$1" | awk '/^faces/ {print $2}') triangles"
}

for spec in "parts 400000 20 40,30" "terrain 400000 32 -60,35"; do
  read -r shape tris grid view <<<"$spec"
  mesh="$dir/$shape-$tris.ply"
  [ -f "$mesh" ] || "$bin" generate --shape "$shape" --tris "$tris" --seed 1 --quiet -o "$mesh"
  picture "$mesh" "$shape-input" "$view"
  for method in uniform floating; do
    "$bin" simplify "$mesh" -o "$dir/$shape-$method.ply" --method "$method" --grid "$grid" --quiet
    picture "$dir/$shape-$method.ply" "$shape-$method-grid$grid" "$view"
  done
  count=$("$bin" info "$dir/$shape-floating.ply" | awk '/^faces/ {print $2}')
  "$bin" simplify "$mesh" -o "$dir/$shape-target.ply" --target-tris "$count" --quiet
  picture "$dir/$shape-target.ply" "$shape-target-$count" "$view"
done
# The branches model (a leafless tree of thin tubes, Low & Tan's Plate 3) at a cell of
# 5 branch radii: floating cells without thick edges, with them drawn one pixel wide,
# and drawn T/R pixels wide (Low & Tan 1997 §3.3).
rm -f "$out"/branches-*.png
mesh="$dir/branches-200000.ply"
[ -f "$mesh" ] || "$bin" generate --shape branches --tris 200000 --seed 1 --quiet -o "$mesh"
picture "$mesh" branches-input 30,10
"$bin" simplify "$mesh" -o "$dir/branches-plain.ply" --cell 0.025 --quiet
picture "$dir/branches-plain.ply" branches-floating 30,10
"$bin" simplify "$mesh" -o "$dir/branches-thick.ply" --cell 0.025 --thick-edges --quiet
picture "$dir/branches-thick.ply" branches-edges-thin 30,10
"$bin" render "$dir/branches-thick.ply" -o "$out/branches-edges-thick.png" --size "$size" --view 30,10 --thick-edges \
  --quiet
echo "docs/branches-edges-thick.png  $("$bin" info "$dir/branches-thick.ply" | awk '/^edges/ {print $2}') edges"
ls -la "$out"/*.png | awk '{ if ($5 > 200 * 1024) { print "pictures.sh: " $NF " is over 200 KB" > "/dev/stderr"; bad = 1 } } END { exit bad }'
