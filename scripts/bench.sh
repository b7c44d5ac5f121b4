#!/usr/bin/env bash
# Throughput benchmark: oocsimp simplify (floating cells and the uniform grid) against
# meshoptimizer's meshopt_simplifySloppy, file to file, on generated meshes cached
# under build/bench/.
#
#   scripts/bench.sh [SIZES...]     default sizes: 1000000 10000000 50000000
#   SHAPES="sphere parts terrain" GRIDS="256 1024" THREADS="1 2" MEM=256M scripts/bench.sh
#   METHODS="floating uniform" (default both)
#
# For each shape, size and grid, each method runs with each thread count; sloppy then
# gets floating's output triangle count as its target (it searches its grid for it,
# its normal use). Each file is read once beforehand so every run starts from a warm
# page cache. Rows: wall seconds, input Mtri/s (input triangles / wall seconds), peak
# anonymous and total RSS, output triangles. Then the ratios, all from this one
# invocation (the machine's speed drifts from day to day, ratios much less):
#   speed vs sloppy  sloppy's seconds / ours (above 1: faster than sloppy);
#   float/uniform    floating's seconds / uniform's at the same thread count;
#   speed-up         the lowest thread count's seconds / each higher one's.
# And per floating run, the seconds of each phase from its --stats JSON.
set -euo pipefail
source "$(dirname "$0")/bench-setup.sh"
peer="${MESHOPT_BENCH_BIN:-$root/build/meshopt_bench}"
sizes=("$@")
[ ${#sizes[@]} -eq 0 ] && sizes=(1000000 10000000 50000000)
grids=(${GRIDS:-256 1024})
threads=(${THREADS:-1 2})
shapes=(${SHAPES:-sphere})
methods=(${METHODS:-floating uniform})
mem_opt=()
[ -n "${MEM:-}" ] && mem_opt=(--mem "$MEM")

now() { date +%s.%N; }
calc() { awk "BEGIN { print $1 }"; }
phases() {  # the "seconds" object of a stats JSON, without the braces
  grep -o '"seconds": {[^}]*}' "$1" | sed 's/"seconds": {//; s/}//; s/"//g'
}

echo "methods ${methods[*]}${mem_opt[1]:+, --mem ${mem_opt[1]}}"
row='%-8s %-10s %-5s %-12s %8s %8s %9s %9s %10s\n'
printf "$row" shape size grid run seconds Mtri/s anon_MiB rss_MiB out_tris
for shape in "${shapes[@]}"; do
  for n in "${sizes[@]}"; do
    mesh="$dir/$shape-$n.ply"
    [ -f "$mesh" ] || "$bin" generate --tris "$n" --shape "$shape" --seed 1 --quiet -o "$mesh"
    cat "$mesh" >/dev/null
    for g in "${grids[@]}"; do
      declare -A secs=() phase_lines=()
      tris=0
      target=0
      for m in "${methods[@]}"; do
        for t in "${threads[@]}"; do
          t0=$(now)
          "$bin" simplify "$mesh" -o "$dir/out.ply" --method "$m" "${mem_opt[@]}" --grid "$g" --threads "$t" \
            --quiet --stats "$dir/stats.json"
          t1=$(now)
          s=$(calc "$t1 - $t0")
          secs[$m-$t]=$s
          tris=$(json_field "$dir/stats.json" triangles | head -1)
          out_tris=$(output_triangles "$dir/stats.json")
          [ "$m" = floating ] && [ "$target" = 0 ] && target=$out_tris
          [ "$m" = floating ] && phase_lines[$t]=$(phases "$dir/stats.json")
          anon=$(json_field "$dir/stats.json" peak_anon_bytes)
          rss=$(json_field "$dir/stats.json" peak_rss_bytes)
          printf "$row" "$shape" "$n" "$g" "$m-t$t" "$(printf %.3f "$s")" \
            "$(printf %.2f "$(calc "$tris / $s / 1000000")")" "$(printf %.1f "$(calc "$anon / 1048576")")" \
            "$(printf %.1f "$(calc "$rss / 1048576")")" "$out_tris"
        done
      done
      [ "$target" = 0 ] && target=$out_tris
      ps=""
      if [ -x "$peer" ]; then
        t0=$(now)
        line=$("$peer" sloppy "$mesh" "$dir/sloppy.ply" "$target")
        t1=$(now)
        ps=$(calc "$t1 - $t0")
        prss=$(echo "$line" | awk '{for (i = 1; i < NF; i++) if ($i == "peak_rss_mib") print $(i + 1)}')
        ptris=$(echo "$line" | awk '{for (i = 1; i < NF; i++) if ($i == "triangles") print $(i + 1)}')
        printf "$row" "$shape" "$n" "$g" "sloppy" "$(printf %.3f "$ps")" \
          "$(printf %.2f "$(calc "$tris / $ps / 1000000")")" "-" "$prss" "$ptris"
      fi
      for m in "${methods[@]}"; do
        for t in "${threads[@]}"; do
          line="  $m-t$t:"
          [ -n "$ps" ] && line+=" speed vs sloppy $(printf %.2f "$(calc "$ps / ${secs[$m-$t]}")")x"
          [ "$m" = floating ] && [ -n "${secs[uniform-$t]:-}" ] &&
            line+=", float/uniform $(printf %.2f "$(calc "${secs[floating-$t]} / ${secs[uniform-$t]}")")x"
          [ "$t" != "${threads[0]}" ] &&
            line+=", speed-up from t${threads[0]} $(printf %.2f "$(calc "${secs[$m-${threads[0]}]} / ${secs[$m-$t]}")")x"
          echo "$line"
        done
      done
      for t in "${threads[@]}"; do
        [ -n "${phase_lines[$t]:-}" ] && echo "  floating-t$t phases (s): ${phase_lines[$t]}"
      done
      unset secs phase_lines
    done
  done
done
rm -f "$dir/out.ply" "$dir/sloppy.ply" "$dir/stats.json"
