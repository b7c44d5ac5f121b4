#!/usr/bin/env bash
# The scale ladder: speed (input Mtri/s) and peak anonymous memory of whole runs, file
# to file, against the input's size from 1M to 1B triangles, as a table and a log-log
# plot (scripts/plot-scale.py).
#
#   scripts/bench-scale.sh                           the whole ladder: 1M to 1B (the 1B
#                                                    input is a 19 GB file; hours; not for CI)
#   SIZES="1M 4M" scripts/bench-scale.sh             the small rungs (a few minutes)
#   SIZES="256M 1B" DIR=/big/disk APPEND=1 scripts/bench-scale.sh
#                                                    the large rungs, added to an earlier table
#
# Each rung generates the sphere and the parts mesh of that many triangles (once:
# cached as DIR/SHAPE-N.ply, seed 1, the names the other scripts use) and runs on each:
#   uniform, floating  oocsimp --method uniform|floating --ratio RATIO (or --grid GRID)
#   target             the default target path: oocsimp --target-ratio RATIO (qem)
#   sloppy, simplify   meshopt_bench sloppy|simplify to RATIO x the input's triangles
#                      (meshopt_simplifySloppy, meshopt_simplify; in core, one thread)
# oocsimp runs with --threads THREADS and --mem MEM, or --mem BIG_MEM from the rung
# BIG_FROM up. Every run is one process, timed from start to exit with the page cache
# warm (the input is read once before its runs when it fits in half of MemAvailable;
# larger inputs come from disk, as out-of-core runs do).
#
# Why --ratio and not a fixed grid: a fixed --grid 256 writes about the same 450k
# triangles at every rung, half of the 1M input and 0.05% of the 1B one, so the small
# rungs hardly simplify and the methods' outputs differ in size. With --ratio 0.01
# every method writes about 1% of its input, as the target path and meshopt do, and a
# flat Mtri/s means a cost linear in the input, output included. GRID=256 gives the
# ladder at a fixed output instead. (At 1B, --ratio 0.01 means about 5M uniform cells:
# a run that cannot hold them within --mem refuses, and its row says so.)
#
# Environment:
#   SIZES      rungs, in triangles with K, M or B (G) suffixes (default "1M 4M 16M 64M 256M 1B")
#   SHAPES     generated shapes (default "sphere parts")
#   RUNS       runs per input (default "uniform floating target sloppy simplify")
#   RATIO      the output's share of the input (default 0.01)
#   GRID       a --grid for uniform and floating instead of --ratio RATIO (default none)
#   MEM        oocsimp's --mem below BIG_FROM (default 256M)
#   BIG_MEM    oocsimp's --mem from BIG_FROM up (default 1G); BIG_FROM default 256M
#   THREADS    oocsimp's threads (default 2)
#   DIR        where the inputs are generated and cached (default build/bench)
#   OUT        the table, plot, stats and logs (default build/bench/scale)
#   APPEND     1: keep the rows of OUT/scale.tsv from earlier invocations (those of the
#              rungs, shapes and runs run now are replaced); default: a new table
#   TMPDIR     oocsimp's --tmp (default /tmp)
#   SPILL_FACTOR   free space asked of TMPDIR, times the input file (default 1.5:
#              floating's zstd spill of the 1M sphere is 1.3x its PLY)
#   SLOPPY_FACTOR, SIMPLIFY_FACTOR  meshopt's memory need, times the input file
#              (default 3 and 7; measured 2.4x and 6.5x at 1M): a meshopt run goes only
#              when it fits in MemAvailable, else its row says "skipped"
#   MESHOPT_BENCH_BIN, OOCSIMP_BIN  the programs (default build/meshopt_bench, build/oocsimp)
#   BENCH_NO_BUILD=1   use the programs as built (scripts/bench-setup.sh)
#   PYTHON     a Python with matplotlib for the plot (default: python3 or
#              /usr/bin/python3 when either has it; else python3-matplotlib from Debian)
#
# A rung and shape is skipped, with rows that say so, when the disk cannot hold the
# input (about 20 bytes a triangle, when not cached) and the spill.
#
# Output: OUT/scale.tsv (rung, shape, method, input tris, output tris, seconds, Mtri/s,
# peak anon MiB, --mem, note), printed as an aligned table, then for each shape and
# method the spread of Mtri/s from 16M up (linear cost keeps it within 15%) and the
# oocsimp runs whose peak went over --mem, and OUT/scale.png. Mtri/s is the input's
# triangles over the wall seconds. Peak anonymous memory is RssAnon sampled every
# 20 ms by the program itself: oocsimp's --stats memory.peak_anon_bytes, and
# meshopt_bench's peak_anon_mib (runtime/memory_usage.hpp, the same sampler).
set -euo pipefail
source "$(dirname "$0")/bench-setup.sh"
meshopt_bin="${MESHOPT_BENCH_BIN:-$root/build/meshopt_bench}"
dir="${DIR:-$dir}"
out="${OUT:-$root/build/bench/scale}"
tmp="${TMPDIR:-/tmp}"
ratio_arg="${RATIO:-0.01}"
threads="${THREADS:-2}"
mem_small="${MEM:-256M}"
mem_big="${BIG_MEM:-1G}"
spill_factor="${SPILL_FACTOR:-1.5}"
sloppy_factor="${SLOPPY_FACTOR:-3}"
simplify_factor="${SIMPLIFY_FACTOR:-7}"
read -ra runs <<<"${RUNS:-uniform floating target sloppy simplify}"
read -ra shapes <<<"${SHAPES:-sphere parts}"
read -ra sizes <<<"${SIZES:-1M 4M 16M 64M 256M 1B}"
mkdir -p "$dir" "$out/stats" "$out/logs"

# tris_of 16M -> 16000000 (K, M, B or G; plain numbers as they are)
tris_of() {
  [[ "$1" =~ ^([0-9]+)([KkMmBbGg]?)$ ]] || { echo "bench-scale.sh: bad size '$1' (e.g. 16M, 1B)" >&2; exit 2; }
  local n=${BASH_REMATCH[1]}
  case "${BASH_REMATCH[2]}" in
    K | k) echo $((n * 1000)) ;;
    M | m) echo $((n * 1000000)) ;;
    B | b | G | g) echo $((n * 1000000000)) ;;
    *) echo "$n" ;;
  esac
}
for r in "${runs[@]}"; do
  case "$r" in uniform | floating | target | sloppy | simplify) ;; *)
    echo "bench-scale.sh: unknown run '$r' (uniform floating target sloppy simplify)" >&2
    exit 2
    ;;
  esac
done
big_from=$(tris_of "${BIG_FROM:-256M}")
free_bytes() { df -B1 --output=avail "$1" | tail -1 | tr -d ' '; }
same_fs() { [ "$(df --output=target "$1" | tail -1)" = "$(df --output=target "$2" | tail -1)" ]; }
gb() { awk -v b="$1" 'BEGIN { printf("%.1f GB", b / 1e9) }'; }
seconds() { awk -v a="$1" -v b="$2" 'BEGIN { printf("%.3f", b - a) }'; }
mem_available() { awk '/^MemAvailable:/ { printf("%.0f\n", $2 * 1024) }' /proc/meminfo; }

# The plot's Python: one with matplotlib, or Debian's after installing it.
has_mpl() { command -v "$1" >/dev/null 2>&1 && "$1" -c 'import matplotlib' 2>/dev/null; }
python="${PYTHON:-}"
if [ -z "$python" ]; then
  for p in python3 /usr/bin/python3; do has_mpl "$p" && { python=$p; break; }; done
fi
if [ -z "$python" ]; then
  echo "bench-scale.sh: installing python3-matplotlib" >&2
  sudo=""
  [ "$(id -u)" -ne 0 ] && sudo="sudo"
  export DEBIAN_FRONTEND=noninteractive
  $sudo apt-get update -qq >/dev/null
  $sudo apt-get install -y -qq --no-install-recommends python3-matplotlib >/dev/null
  python=/usr/bin/python3
fi

tsv="$out/scale.tsv"
header=$'rung\tshape\tmethod\tinput_tris\toutput_tris\tseconds\tMtri_s\tpeak_anon_MiB\tmem\tnote'
if [ -n "${APPEND:-}" ] && [ -f "$tsv" ]; then
  # Drop the earlier rows of what runs now.
  awk -F'\t' -v sizes="${sizes[*]}" -v shapes="${shapes[*]}" -v runs="${runs[*]}" '
    BEGIN { split(sizes, a, " "); for (i in a) s[a[i]]; split(shapes, a, " "); for (i in a) h[a[i]]
            split(runs, a, " "); for (i in a) r[a[i]] }
    NR == 1 || !(($1 in s) && ($2 in h) && ($3 in r))' "$tsv" >"$tsv.tmp"
  mv "$tsv.tmp" "$tsv"
else
  echo "$header" >"$tsv"
fi
row() { # row RUNG SHAPE METHOD IN OUT SECONDS ANON_MIB MEM NOTE
  local mtri=-
  [ "$6" != - ] && mtri=$(awk -v n="$4" -v s="$6" 'BEGIN { printf("%.3f", n / s / 1e6) }')
  printf '%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\n' "$1" "$2" "$3" "$4" "$5" "$6" "$mtri" "$7" "$8" "$9" >>"$tsv"
  printf '  %-9s %-7s %-9s %11s %10s %9s %8s %9s %5s  %s\n' "$1" "$2" "$3" "$4" "$5" "$6" "$mtri" "$7" "$8" "$9"
}

# field KEY -> the value after KEY in meshopt_bench's line
field() { awk -v k="$1" '{ for (i = 1; i < NF; i++) if ($i == k) print $(i + 1) }' <<<"$line"; }

result="$out/result.ply"
trap 'rm -f "$result"' EXIT
echo "scale ladder: ${sizes[*]}; ${shapes[*]}; ${runs[*]}; output ${GRID:+--grid $GRID for clustering, }ratio $ratio_arg;" \
  "oocsimp --threads $threads --mem $mem_small (--mem $mem_big from $big_from triangles); inputs in $dir, --tmp $tmp"
printf '  %-9s %-7s %-9s %11s %10s %9s %8s %9s %5s  %s\n' rung shape method in_tris out_tris seconds Mtri/s anon_MiB mem note
for rung in "${sizes[@]}"; do
  n=$(tris_of "$rung")
  mem=$mem_small
  [ "$n" -ge "$big_from" ] && mem=$mem_big
  for shape in "${shapes[@]}"; do
    mesh="$dir/$shape-$n.ply"
    est=$((20 * n))  # the generated PLY: 19.0 (sphere) to 19.2 (parts) bytes a triangle
    need_dir=0
    [ -f "$mesh" ] || need_dir=$est
    need_tmp=$(awk -v e="$est" -v f="$spill_factor" 'BEGIN { printf("%.0f", e * f) }')
    if same_fs "$dir" "$tmp"; then
      need=$((need_dir + need_tmp)) free=$(free_bytes "$dir")
      where="$dir and $tmp"
    else
      need=$need_dir free=$(free_bytes "$dir") where=$dir
      if [ "$need_tmp" -gt "$(free_bytes "$tmp")" ]; then need=$need_tmp free=$(free_bytes "$tmp") where=$tmp; fi
    fi
    if [ "$need" -gt "$free" ]; then
      for r in "${runs[@]}"; do
        row "$rung" "$shape" "$r" - - - - - \
          "skipped: the input and spill need about $(gb "$need") on $where, $(gb "$free") free (DIR, TMPDIR, SPILL_FACTOR)"
      done
      continue
    fi
    if [ ! -f "$mesh" ]; then
      echo "  generating $mesh ..." >&2
      "$bin" generate --tris "$n" --shape "$shape" --seed 1 --quiet -o "${mesh%.ply}.partial.ply"
      mv "${mesh%.ply}.partial.ply" "$mesh"  # no half-written input is cached
    fi
    size=$(stat -c %s "$mesh")
    in_tris=$("$bin" info "$mesh" --json --quiet | grep -o '"faces": [0-9]*' | awk '{print $2}')
    target=$(awk -v n="$in_tris" -v r="$ratio_arg" 'BEGIN { printf("%.0f", n * r) }')
    [ "$size" -lt $(($(mem_available) / 2)) ] && cat "$mesh" >/dev/null
    for r in "${runs[@]}"; do
      log="$out/logs/$rung-$shape-$r.log"
      case "$r" in
        uniform | floating | target)
          args=(--method "$r" --ratio "$ratio_arg")
          [ -n "${GRID:-}" ] && args=(--method "$r" --grid "$GRID")
          [ "$r" = target ] && args=(--target-ratio "$ratio_arg")
          st="$out/stats/$rung-$shape-$r.json"
          rm -f "$st"
          t0=$(now)
          "$bin" simplify "$mesh" -o "$result" "${args[@]}" --threads "$threads" --mem "$mem" --tmp "$tmp" \
            --quiet --stats "$st" 2>"$log" && rc=0 || rc=$?
          t1=$(now)
          if [ "$rc" -ne 0 ]; then
            row "$rung" "$shape" "$r" "$in_tris" - - - "$mem" "exit $rc: $(head -c 300 "$log" | head -1 | tr '\t' ' ')"
            continue
          fi
          anon=$(json_field "$st" peak_anon_bytes)
          mem_bytes=$(json_field "$st" mem_bytes)
          note=""
          [ "$anon" -gt "$mem_bytes" ] && note="over --mem"
          row "$rung" "$shape" "$r" "$in_tris" "$(output_triangles "$st")" "$(seconds "$t0" "$t1")" \
            "$(awk -v b="$anon" 'BEGIN { printf("%.1f", b / 1048576) }')" "$mem" "$note"
          ;;
        sloppy | simplify)
          factor=$sloppy_factor
          [ "$r" = simplify ] && factor=$simplify_factor
          need=$(awk -v s="$size" -v f="$factor" 'BEGIN { printf("%.0f", s * f) }')
          avail=$(mem_available)
          if [ ! -x "$meshopt_bin" ]; then
            row "$rung" "$shape" "$r" "$in_tris" - - - - "skipped: $meshopt_bin is not built"
            continue
          elif [ "$need" -gt "$avail" ]; then
            row "$rung" "$shape" "$r" "$in_tris" - - - - \
              "skipped: needs about $(gb "$need") in core, $(gb "$avail") available"
            continue
          fi
          t0=$(now)
          line=$("$meshopt_bin" "$r" "$mesh" "$result" "$target" 2>"$log") && rc=0 || rc=$?
          t1=$(now)
          if [ "$rc" -ne 0 ]; then
            row "$rung" "$shape" "$r" "$in_tris" - - - - "exit $rc: $(head -c 300 "$log" | head -1 | tr '\t' ' ')"
            continue
          fi
          echo "$line" >>"$log"
          row "$rung" "$shape" "$r" "$in_tris" "$(field triangles)" "$(seconds "$t0" "$t1")" "$(field peak_anon_mib)" - ""
          ;;
      esac
    done
  done
done

echo
echo "table $tsv (all rows, by shape, method and size):"
{
  head -1 "$tsv"
  tail -n +2 "$tsv" | sort -t$'\t' -k2,2 -k3,3 -k4,4n
} | column -t -s$'\t'

echo
# Linear cost: the spread of Mtri/s from the 16M rung up, per shape and method (by the
# rung's size: a generated parts mesh holds a few triangles fewer than its rung).
tail -n +2 "$tsv" | awk -F'\t' '
  function rung_tris(r, n, s) {
    n = r + 0; s = toupper(substr(r, length(r)))
    return s == "K" ? n * 1e3 : s == "M" ? n * 1e6 : (s == "B" || s == "G") ? n * 1e9 : n
  }
  $7 != "-" && rung_tris($1) >= 16000000 {
    k = $2 " " $3; n[k]++
    if (!(k in lo) || $7 < lo[k]) lo[k] = $7
    if (!(k in hi) || $7 > hi[k]) hi[k] = $7
  }
  END {
    for (k in n) {
      s = 1 - lo[k] / hi[k]
      printf("  Mtri/s from 16M up, %-17s %d rungs, %.2f to %.2f: spread %.0f%% %s\n", k, n[k], lo[k], hi[k], 100 * s,
             n[k] < 2 ? "(one rung)" : (s <= 0.15 ? "(within 15%)" : "(NOT within 15%)"))
      any = 1
    }
    if (!any) print "  Mtri/s from 16M up: no rung of 16M or more in the table"
  }' | sort
over=$(awk -F'\t' '$10 == "over --mem" { print "  " $1 " " $2 " " $3 ": " $8 " MiB over --mem " $9 }' "$tsv")
if [ -n "$over" ]; then
  echo "peak anonymous memory over --mem:"
  echo "$over"
else
  echo "  peak anonymous memory under --mem on every oocsimp run in the table"
fi

percent=$(awk -v r="$ratio_arg" 'BEGIN { printf("%g%%", 100 * r) }')
what="outputs about $percent of the input"
[ -n "${GRID:-}" ] && what="clustering at --grid $GRID, targets $percent of the input"
"$python" "$root/scripts/plot-scale.py" "$tsv" "$out/scale.png" \
  "oocsimp scale ladder: generated $(sed "s/ /, /g" <<<"${shapes[*]}"), $what; oocsimp --threads $threads"
echo "plot $out/scale.png"
