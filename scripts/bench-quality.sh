#!/usr/bin/env bash
# Quality and time at a triangle target: oocsimp against the in-core
# quadric edge collapses, every run in one invocation, errors from `oocsimp measure`.
#
#   scripts/bench-quality.sh                    generated 2M sphere and 2M parts, target 100000
#   scripts/bench-quality.sh scan.ply ...       files of your own instead of generated ones
#   SIZE=20000000 SHAPES=sphere TARGET=580000 RUNS="openmesh simplify" scripts/bench-quality.sh
#
# Environment: SHAPES (default "sphere parts") and SIZE (default 2000000) name the
# generated inputs, cached under build/bench/ as bench.sh does; TARGET the output
# triangles (default 100000); SAMPLES the points `oocsimp measure` samples on each
# surface (default 1000000); THREADS oocsimp's threads (default 2; the peers run on
# one); OPENMESH_ARGS options for the OpenMesh run (--normal-flip DEGREES adds
# ModNormalFlippingT, --lock-boundary keeps every boundary vertex); RUNS which rows
# run, in this order, default all of:
#   openmesh   OpenMesh's Decimater with ModQuadricT, decimate_to_faces(0, TARGET)
#   open3d     Open3D's simplify_quadric_decimation(TARGET) (scripts/open3d_decimate.py,
#              Debian python3-open3d under /usr/bin/python3); its anon_MiB is sampled
#              right after the collapse, not a peak
#   simplify   meshopt_simplify, target_error FLT_MAX so the count is the only stop
#   sloppy     meshopt_simplifySloppy
#   floating   oocsimp simplify --ratio TARGET/input (an estimate: the count is not TARGET)
#   uniform    the same with --method uniform
#   qem        oocsimp simplify --target-tris TARGET, the default: quadric edge collapse,
#              out of core in tiles on an input of 2^20 faces or more
#   target-floating  --method floating --target-tris TARGET: floating cells, then the
#              collapse (multiphase)
#   target-uniform   the same with --method uniform as phase 1
# A peer whose program is not built is skipped with a note.
#
# Rows: wall seconds file to file, input Mtri/s, output triangles, peak anonymous and
# total RSS, then RMS and Hausdorff distances (symmetric, as fractions of the input's
# bounding-box diagonal), the output's boundary and non-manifold edges
# (scripts/mesh_topology.py), and the ratios of this invocation: RMS over OpenMesh's,
# and seconds over meshopt_simplify's. Each peer's load / simplify / write seconds follow.
set -euo pipefail
source "$(dirname "$0")/bench-setup.sh"
openmesh_bin="${OPENMESH_BENCH_BIN:-$root/build/openmesh_decimate_bench}"
meshopt_bin="${MESHOPT_BENCH_BIN:-$root/build/meshopt_bench}"
target="${TARGET:-100000}"
samples="${SAMPLES:-1000000}"
threads="${THREADS:-2}"
size="${SIZE:-2000000}"
runs=(${RUNS:-openmesh open3d simplify sloppy floating uniform qem target-floating target-uniform})
out="$dir/quality"
mkdir -p "$out"

inputs=("$@")
if [ ${#inputs[@]} -eq 0 ]; then
  for shape in ${SHAPES:-sphere parts}; do
    mesh="$dir/$shape-$size.ply"
    [ -f "$mesh" ] || "$bin" generate --tris "$size" --shape "$shape" --seed 1 --quiet -o "$mesh"
    inputs+=("$mesh")
  done
fi

simplify_help=$("$bin" simplify --help 2>&1 || true)
has_target=0
grep -q -- '--target-tris' <<<"$simplify_help" && has_target=1
has_qem=0
[ $has_target = 1 ] && grep -q 'qem' <<<"$simplify_help" && has_qem=1

now() { date +%s.%N; }
calc() { awk "BEGIN { print $1 }"; }
ratio() {  # ratio A B -> A/B as "0.93x", with three decimals below 0.1
  awk -v a="$1" -v b="$2" 'BEGIN { r = a / b; printf(r < 0.1 ? "%.3fx" : "%.2fx", r) }'
}
field() {  # field "LINE" KEY -> the word after KEY in a peer's key-value line
  awk -v k="$2" '{for (i = 1; i < NF; i++) if ($i == k) print $(i + 1)}' <<<"$1"
}
measured() {  # measured MEASURE.json -> "rms/diag hausdorff/diag" of the symmetric distance
  grep '"symmetric"' "$1" |
    sed -E 's/.*"of_diagonal": \{"hausdorff": ([^,]*), "mean": [^,]*, "rms": ([^}]*)\}.*/\2 \1/'
}
b_triangles() { grep -o '"b": {"triangles": [0-9]*' "$1" | awk '{print $NF}'; }
a_triangles() { grep -o '"a": {"triangles": [0-9]*' "$1" | awk '{print $NF}'; }

head_fmt='%-16s %9s %8s %9s %9s %9s %11s %11s %11s %10s %10s\n'
row_fmt='%-16s %9.3f %8.2f %9s %9s %9s %11.3e %11.3e %11s %10s %10s\n'

for mesh in "${inputs[@]}"; do
  cat "$mesh" >/dev/null  # a warm page cache for every run
  echo "input $mesh, target $target triangles, measure --samples $samples, oocsimp --threads $threads${OPENMESH_ARGS:+, OpenMesh $OPENMESH_ARGS}"
  [ $has_target = 0 ] && echo "  (oocsimp simplify has no --target-tris yet: rows qem and target-* skipped)"
  [ $has_target = 1 ] && [ $has_qem = 0 ] && echo "  (oocsimp simplify has no --method qem yet: row qem skipped)"
  faces=$("$bin" info "$mesh" | awk '$1 == "faces" {print $2}')  # as stored: the ratio's estimate
  declare -A secs=() tris=() anon=() rss=() rms=() haus=() topo=() phases=()
  done_runs=()
  for r in "${runs[@]}"; do
    result="$out/$r.ply"
    echo "  $r ..." >&2
    case "$r" in
      openmesh | open3d | simplify | sloppy)
        if [ "$r" = openmesh ]; then
          prog="$openmesh_bin"
          args=("$mesh" "$result" "$target" ${OPENMESH_ARGS:-})
        elif [ "$r" = open3d ]; then
          prog=/usr/bin/python3
          args=("$root/scripts/open3d_decimate.py" "$mesh" "$result" "$target")
          if ! "$prog" -c "import open3d" 2>/dev/null; then
            echo "  $r: skipped, python3-open3d is not installed"
            continue
          fi
        else
          prog="$meshopt_bin"
          args=("$r" "$mesh" "$result" "$target")
        fi
        if [ ! -x "$prog" ]; then
          echo "  $r: skipped, $prog is not built"
          continue
        fi
        t0=$(now)
        line=$("$prog" "${args[@]}")
        t1=$(now)
        tris[$r]=$(field "$line" triangles)
        anon[$r]=$(field "$line" peak_anon_mib)
        rss[$r]=$(field "$line" peak_rss_mib)
        phases[$r]="load $(field "$line" load) simplify $(field "$line" simplify) write $(field "$line" write)"
        case "$r" in simplify | sloppy) phases[$r]+=", meshoptimizer's result_error $(field "$line" result_error)" ;; esac
        [ "$r" = openmesh ] &&
          phases[$r]+=", $(field "$line" collapses) collapses, $(field "$line" rejected_faces) input faces rejected"
        ;;
      floating | uniform | qem | target-floating | target-uniform)
        case "$r" in
          floating | uniform)
            args=(--method "$r" --ratio "$(calc "$target / $faces")")
            ;;
          target-floating)
            [ $has_target = 1 ] || continue
            args=(--method floating --target-tris "$target")
            ;;
          target-uniform)
            [ $has_target = 1 ] || continue
            args=(--method uniform --target-tris "$target")
            ;;
          qem)
            [ $has_qem = 1 ] || continue
            args=(--target-tris "$target")
            ;;
        esac
        t0=$(now)
        "$bin" simplify "$mesh" -o "$result" "${args[@]}" --threads "$threads" --quiet --stats "$out/stats.json"
        t1=$(now)
        tris[$r]=$(output_triangles "$out/stats.json")
        anon[$r]=$(printf %.1f "$(calc "$(json_field "$out/stats.json" peak_anon_bytes) / 1048576")")
        rss[$r]=$(printf %.1f "$(calc "$(json_field "$out/stats.json" peak_rss_bytes) / 1048576")")
        ;;
      *)
        echo "unknown run '$r' in RUNS" >&2
        exit 2
        ;;
    esac
    secs[$r]=$(calc "$t1 - $t0")
    "$bin" measure "$mesh" "$result" --samples "$samples" --json --quiet >"$out/measure.json"
    read -r rms[$r] haus[$r] <<<"$(measured "$out/measure.json")"
    topo[$r]=$(python3 "$root/scripts/mesh_topology.py" "$result" |
      sed -E 's/.* ([0-9]+) boundary .* ([0-9]+) non-manifold .*/\1\/\2/')
    in_tris=$(a_triangles "$out/measure.json")  # the triangles every method reads
    measured_tris=$(b_triangles "$out/measure.json")
    [ "$measured_tris" = "${tris[$r]}" ] ||
      echo "  $r: the program reported ${tris[$r]} triangles, measure read $measured_tris"
    done_runs+=("$r")
  done

  printf "$head_fmt" method seconds Mtri/s out_tris anon_MiB rss_MiB rms/diag haus/diag open/nm rms/openm t/simplify
  for r in "${done_runs[@]}"; do
    rms_ratio=-
    [ -n "${rms[openmesh]:-}" ] && rms_ratio=$(ratio "${rms[$r]}" "${rms[openmesh]}")
    time_ratio=-
    [ -n "${secs[simplify]:-}" ] && time_ratio=$(ratio "${secs[$r]}" "${secs[simplify]}")
    printf "$row_fmt" "$r" "${secs[$r]}" "$(calc "$in_tris / ${secs[$r]} / 1000000")" "${tris[$r]}" "${anon[$r]}" \
      "${rss[$r]}" "${rms[$r]}" "${haus[$r]}" "${topo[$r]}" "$rms_ratio" "$time_ratio"
  done
  for r in "${done_runs[@]}"; do
    [ -n "${phases[$r]:-}" ] && echo "  $r seconds: ${phases[$r]}"
  done
  echo
  unset secs tris anon rss rms haus topo phases
done
[ -n "${KEEP:-}" ] || rm -rf "$out"
