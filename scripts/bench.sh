#!/usr/bin/env bash
# Throughput benchmark: oocsimp simplify against meshoptimizer's meshopt_simplifySloppy,
# file to file, on generated spheres cached under build/bench/.
#
#   scripts/bench.sh [SIZES...]     default sizes: 1000000 10000000 50000000
#   GRIDS="256 1024" THREADS="1 2" SHAPE=sphere METHOD=uniform MEM=256M scripts/bench.sh  (METHOD: floating by default)
#
# For each size and grid, oocsimp runs with each thread count; sloppy then gets our
# output triangle count as its target (it searches its grid for it, its normal use).
# Each file is read once beforehand so every run starts from a warm page cache.
# Columns: input Mtri/s (input triangles / wall seconds), peak anonymous and total
# RSS, output triangles, and our speed relative to sloppy (sloppy s / our s).
set -euo pipefail
source "$(dirname "$0")/bench-setup.sh"
peer="$root/build/meshopt_sloppy_bench"
sizes=("$@")
[ ${#sizes[@]} -eq 0 ] && sizes=(1000000 10000000 50000000)
grids=(${GRIDS:-256 1024})
threads=(${THREADS:-1 2})
shape="${SHAPE:-sphere}"
method="${METHOD:-floating}"
mem_opt=()
# --mem bounds the floating method's tiles; the uniform method refuses it (it has none).
[ -n "${MEM:-}" ] && [ "$method" = floating ] && mem_opt=(--mem "$MEM")

now() { date +%s.%N; }
calc() { awk "BEGIN { print $1 }"; }

echo "method $method${mem_opt[1]:+, --mem ${mem_opt[1]}}"
printf '%-10s %-5s %-8s %8s %8s %9s %9s %10s %8s %9s %8s\n' \
  size grid run seconds Mtri/s anon_MiB rss_MiB out_tris ratio peer_s peer_MiB
for n in "${sizes[@]}"; do
  mesh="$dir/$shape-$n.ply"
  [ -f "$mesh" ] || "$bin" generate --tris "$n" --shape "$shape" --seed 1 --quiet -o "$mesh"
  cat "$mesh" >/dev/null
  for g in "${grids[@]}"; do
    declare -A secs=()
    out_tris=0
    for t in "${threads[@]}"; do
      t0=$(now)
      "$bin" simplify "$mesh" -o "$dir/out.ply" --method "$method" "${mem_opt[@]}" --grid "$g" --threads "$t" --quiet \
        --stats "$dir/stats.json"
      t1=$(now)
      s=$(calc "$t1 - $t0")
      secs[$t]=$s
      tris=$(json_field "$dir/stats.json" triangles | head -1)
      out_tris=$(output_triangles "$dir/stats.json")
      anon=$(json_field "$dir/stats.json" peak_anon_bytes)
      rss=$(json_field "$dir/stats.json" peak_rss_bytes)
      printf '%-10s %-5s %-8s %8.3f %8.2f %9.1f %9.1f %10s %8s %9s %8s\n' "$n" "$g" "oocs-t$t" "$s" \
        "$(calc "$tris / $s / 1000000")" "$(calc "$anon / 1048576")" "$(calc "$rss / 1048576")" \
        "$out_tris" "" "" ""
    done
    if [ -x "$peer" ]; then
      t0=$(now)
      line=$("$peer" "$mesh" "$dir/sloppy.ply" "$out_tris")
      t1=$(now)
      ps=$(calc "$t1 - $t0")
      prss=$(echo "$line" | awk '{for (i = 1; i < NF; i++) if ($i == "peak_rss_mib") print $(i + 1)}')
      ptris=$(echo "$line" | awk '{for (i = 1; i < NF; i++) if ($i == "triangles") print $(i + 1)}')
      printf '%-10s %-5s %-8s %8.3f %8.2f %9s %9.1f %10s %8s %9s %8s\n' "$n" "$g" "sloppy" "$ps" \
        "$(calc "$tris / $ps / 1000000")" "-" "$prss" "$ptris" "" "" ""
      for t in "${threads[@]}"; do
        printf '%-10s %-5s %-8s %45s %8.2fx %9.3f %8.1f\n' "$n" "$g" "ratio-t$t" "" \
          "$(calc "$ps / ${secs[$t]}")" "$ps" "$prss"
      done
    fi
    unset secs
  done
done
rm -f "$dir/out.ply" "$dir/sloppy.ply" "$dir/stats.json"
