#!/usr/bin/env bash
# Levels of detail from one run (simplify --lods) against the finest level alone, in
# the same invocation, so that the ratio holds whatever the machine's speed that day.
#
#   scripts/bench-lods.sh [TRIANGLES ...]       default 2000000 (generated spheres)
#   METHODS="floating uniform" GRID=256 LEVELS=3 FACTOR=2 RUNS=3 SHAPES=sphere
#   TARGET=40000 [METHODS=qem] [MEM=128M]     levels to a target, halved per level
#
# Per method and size: the median wall time of the finest level alone (`--grid GRID`,
# or `--target-tris TARGET`) and of `--lods LEVELS --lod-factor FACTOR` (each run
# after a warm-up), the ratio, input Mtri/s and peak RSS of the --lods run. The goal
# is LEVELS=3 in at most 1.6x the finest level's time. With TARGET the methods
# default to qem (the default with a target), and the coarser levels go on from the
# finest level's collapse.
set -euo pipefail
source "$(dirname "$0")/bench-setup.sh"
sizes=("$@")
[ ${#sizes[@]} -gt 0 ] || sizes=(2000000)
target=${TARGET:-}
if [ -n "$target" ]; then
  methods=${METHODS:-qem}
  sizing=(--target-tris "$target")
else
  methods=${METHODS:-"floating uniform"}
  sizing=(--grid "${GRID:-256}")
fi
[ -z "${MEM:-}" ] || sizing+=(--mem "$MEM")
levels=${LEVELS:-3}
factor=${FACTOR:-2}
runs=${RUNS:-3}
shapes=${SHAPES:-sphere}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

seconds() {  # seconds CMD... -> wall seconds and peak RSS in KiB of one run
  /usr/bin/time -f "%e %M" -o "$tmp/time" "$@" >/dev/null 2>&1
  cat "$tmp/time"
}
median() { sort -n | awk '{a[NR] = $1} END {print a[int((NR + 1) / 2)]}'; }

printf '%-8s %-9s %11s %10s %10s %7s %10s %9s\n' shape method triangles finest_s lods_s ratio lods_Mtri/s rss_MiB
for shape in $shapes; do
  for n in "${sizes[@]}"; do
    mesh="$dir/$shape-$n.ply"
    [ -f "$mesh" ] || "$bin" generate --shape "$shape" --tris "$n" --seed 1 --quiet -o "$mesh"
    tris=$("$bin" info "$mesh" | awk '/^faces/ {print $2}')
    for method in $methods; do
      one=(simplify "$mesh" -o "$tmp/one.ply" --method "$method" "${sizing[@]}" --quiet)
      many=(simplify "$mesh" -o "$tmp/lod.ply" --method "$method" "${sizing[@]}" --lods "$levels" --quiet)
      [ -n "$target" ] || many+=(--lod-factor "$factor")
      "$bin" "${one[@]}" # warm the page cache
      : >"$tmp/one.s"
      : >"$tmp/many.s"
      for _ in $(seq "$runs"); do
        seconds "$bin" "${one[@]}" | awk '{print $1}' >>"$tmp/one.s"
        seconds "$bin" "${many[@]}" >>"$tmp/many.s"
      done
      t1=$(median <"$tmp/one.s")
      tk=$(awk '{print $1}' "$tmp/many.s" | median)
      rss=$(awk '{print $2}' "$tmp/many.s" | sort -n | tail -1)
      awk -v s="$shape" -v m="$method" -v n="$tris" -v a="$t1" -v b="$tk" -v r="$rss" 'BEGIN {
        printf "%-8s %-9s %11d %10.2f %10.2f %7.2f %10.2f %9.1f\n", s, m, n, a, b, b / a, n / b / 1e6, r / 1024 }'
    done
  done
done
