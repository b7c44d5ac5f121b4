#!/usr/bin/env bash
# Distributed runs (docs/cluster.md) against one process, on generated spheres cached
# under build/bench/:
#
#   scripts/bench-cluster.sh [SIZES...]      default sizes: 20000000 100000000
#   GRID=256 (default) METHOD=uniform (the method the parts take)
#   METHOD=qem RATIO=0.029 (default): the edge collapse to that share of the input,
#   whose first out-of-core pass the parts share
#   METHOD=floating: floating cells, whose ranks exchange tile borders under mpirun
#   (the parts of an array each grade and sweep every tile)
#   METHOD=curvature SHAPE=parts GRID=150 ... 2000000: curvature cells, whose parts
#   each estimate their share of the vertices' curvatures
#   METHOD=floating TARGET_RATIO=0.01: the clustering as phase 1 of a target (the
#   parts share phase 1; the merge collapses)
#   SHAPE=sphere (default): the generated shape
#
# Per size, all with 1 thread per process:
#   one      oocsimp simplify, one process;
#   part K=1 one part alone (the whole input read, every chunk summed);
#   parts 2  two parts at once (two processes, --part 0/2 and 1/2), then the merge;
#   mpirun 2 mpirun -n 2 (when the CLI is built with MPI), --bind-to none: Open MPI
#            binds each rank to one core, where a rank's reading thread then
#            competes with its work (26.4 s bound against 20.9 s unbound, 20M to 0.5%).
#            MPI_OPTIONS (default: --mca pml ob1 --mca btl self,vader) picks Open
#            MPI's shared-memory transport, all that ranks on one node need: with
#            its defaults, MPI_Init probes the network transports and a 2-rank run
#            of a 1000-triangle input took 0.40-0.53 s, against 0.17-0.22 s.
# Then the speed-up of 2 processes over one, the bytes of the part files (what the
# ranks exchange through the work folder), and the model of docs/cluster.md for K =
# 8, 64 and 256 on a 10 Gb/s network, from this invocation's figures:
#   T(K) = R + S/K + M + X/B     R: what every part repeats (T(part K=1) - S),
#                                S: the summing that splits (2 (T(part K=1) - T(2 parts))),
#                                M: the merge, X: the part files' bytes, B: 1.25 GB/s.
# Each output is checked against the one-process bytes. Then (not for qem or
# curvature) floating
# cells run once in one process for the bytes their tiles hand on (per sweep, per
# stitch) and the same model's prediction for ranks that exchange them.
set -euo pipefail
source "$(dirname "$0")/bench-setup.sh"
sizes=("$@")
[ ${#sizes[@]} -eq 0 ] && sizes=(20000000 100000000)
grid="${GRID:-256}"
method="${METHOD:-uniform}"
shape="${SHAPE:-sphere}"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
read -r -a mpi_options <<<"${MPI_OPTIONS---mca pml ob1 --mca btl self,vader}"
work="$dir/cluster-work"
if [ "$method" = qem ]; then
  common=(--method qem --target-ratio "${RATIO:-0.029}" --threads 1 --quiet)
elif [ -n "${TARGET_RATIO:-}" ]; then
  common=(--method "$method" --target-ratio "$TARGET_RATIO" --threads 1 --quiet)
else
  common=(--method "$method" --grid "$grid" --threads 1 --quiet)
fi

printf '%-10s %8s %9s %9s %9s %9s %9s %9s %10s\n' size one_s part1_s parts2_s merge_s 2proc_s mpirun2_s speedup part_MiB
for n in "${sizes[@]}"; do
  mesh="$dir/$shape-$n.ply"
  [ -f "$mesh" ] || "$bin" generate --tris "$n" --shape "$shape" --seed 1 --quiet -o "$mesh"
  cat "$mesh" >/dev/null
  t0=$(now)
  "$bin" simplify "$mesh" -o "$dir/one.ply" "${common[@]}"
  t1=$(now)
  rm -rf "$work" && mkdir -p "$work"
  "$bin" simplify "$mesh" -o "$dir/x.ply" "${common[@]}" --part 0/1 --work-dir "$work"
  t2=$(now)
  rm -rf "$work" && mkdir -p "$work"
  t3=$(now)
  "$bin" simplify "$mesh" -o "$dir/x.ply" "${common[@]}" --part 0/2 --work-dir "$work" &
  "$bin" simplify "$mesh" -o "$dir/x.ply" "${common[@]}" --part 1/2 --work-dir "$work"
  wait
  t4=$(now)
  "$bin" merge "$work" -o "$dir/merged.ply" --threads 1 --quiet
  t5=$(now)
  cmp -s "$dir/one.ply" "$dir/merged.ply" || { echo "bench-cluster: merged output differs from one process" >&2; exit 1; }
  part_bytes=$(du -cb "$work"/part-*.oocpart | tail -1 | cut -f1)
  mpi="-"
  if command -v mpirun >/dev/null; then
    t6=$(now)
    mpirun --oversubscribe --bind-to none "${mpi_options[@]}" -n 2 "$bin" simplify "$mesh" -o "$dir/mpi.ply" "${common[@]}" 2>"$dir/mpi.err"
    t7=$(now)
    if grep -q "built without MPI" "$dir/mpi.err"; then
      mpi="no MPI"
    else
      cmp -s "$dir/one.ply" "$dir/mpi.ply" || { echo "bench-cluster: mpirun output differs" >&2; exit 1; }
      mpi=$(printf '%.2f' "$(calc "$t7 - $t6")")
    fi
  fi
  one=$(calc "$t1 - $t0")
  part1=$(calc "$t2 - $t1")
  parts2=$(calc "$t4 - $t3")
  merge=$(calc "$t5 - $t4")
  two=$(calc "$parts2 + $merge")
  printf '%-10s %8.2f %9.2f %9.2f %9.2f %9.2f %9s %9s %10.1f\n' "$n" "$one" "$part1" "$parts2" "$merge" "$two" "$mpi" \
    "$(ratio "$one" "$two")" "$(calc "$part_bytes / 1048576")"
  awk -v one="$one" -v p1="$part1" -v p2="$parts2" -v m="$merge" -v x="$part_bytes" 'BEGIN {
    s = 2 * (p1 - p2); if (s < 0) s = 0; r = p1 - s; if (r < 0) r = 0; b = 1.25e9;
    printf("  model: R %.2f s, S %.2f s, M %.2f s, X %.1f MiB:", r, s, m, x / 1048576);
    split("8 64 256", ks, " ");
    for (i = 1; i <= 3; ++i) { k = ks[i]; t = r + s / k + m + x / b; printf(" K=%d %.2fx", k, one / t); }
    printf("\n");
  }'
  [ "$method" = qem ] || [ "$method" = curvature ] || [ -n "${TARGET_RATIO:-}" ] && continue
  # Floating cells' exchange measured in one process, and the model's prediction from
  # it for ranks that exchange borders (docs/cluster.md, "A model for floating cells").
  "$bin" simplify "$mesh" -o "$dir/one-floating.ply" --method floating --grid "$grid" --threads 1 --quiet \
    --stats "$dir/floating.json"
  python3 - "$dir/floating.json" "$n" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
t, x = s["seconds"], s["tiles"]["exchange"]
centre = x["border_centre_bytes"]
sweeps = [c["published"] * centre for c in s["tiles"]["sweeps"]]
stitch = x["stitch_corner_bytes"] + x["inside_triangle_bytes"] + x["cluster_share_bytes"]
total = x["border_bytes"] + sum(sweeps) + stitch
mib = lambda b: b / 1048576
print("  floating (one process, 1 thread): %.2f s; exchange: first greedy's borders %.1f MiB, %d sweeps %s MiB, "
      "stitch corners %.1f MiB + inside triangles %.1f MiB + cluster shares %.1f MiB" %
      (t["total"], mib(x["border_bytes"]), len(sweeps), "/".join("%.1f" % mib(b) for b in sweeps),
       mib(x["stitch_corner_bytes"]), mib(x["inside_triangle_bytes"]), mib(x["cluster_share_bytes"])))
r = t.get("bin", 0) + t.get("open", 0)
split = t.get("grade", 0) + t.get("cluster", 0) + t.get("rounds", 0)
m = t.get("stitch", 0) + t.get("assemble", 0) + t.get("write", 0)
print("  floating model: R %.2f s (bin), S %.2f s (grade, rounds, cluster), M %.2f s (stitch, assemble, write), "
      "X %.1f MiB:" % (r, split, m, mib(total)), end="")
for k in (8, 64, 256):
    print(" K=%d %.2fx" % (k, t["total"] / (r + split / k + m + total / 1.25e9)), end="")
print()
PY
done
rm -rf "$work"
