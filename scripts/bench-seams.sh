#!/usr/bin/env bash
# Texture seams through the edge collapse: a textured sphere (scripts/textured_sphere.py:
# six charts, twelve seams, three charts at each cube corner) simplified to each
# target with its texture coordinates (the seams kept closed and unblended) and
# without them (--attributes none: no seam at all), in the same invocation. Prints the
# symmetric RMS and Hausdorff distance over the diagonal of each, their ratio (the cost
# of keeping the seams), the seam points left (2396 in the input at N 200), and the
# times.
#
#   scripts/bench-seams.sh [N [TARGET...]]    (default N 200: 480000 triangles; targets 20000 5000 1000)
set -euo pipefail
source "$(dirname "$0")/bench-setup.sh"
n="${1:-200}"
shift || true
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(20000 5000 1000)
mesh="$dir/textured-sphere-$n.obj"
[ -f "$mesh" ] || python3 "$root/scripts/textured_sphere.py" "$n" "$mesh"
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
"$bin" info "$mesh" | grep -E "^faces|seams"
printf "%8s %10s | %10s %10s %7s %8s | %10s %10s %7s | %9s\n" target triangles rms/diag haus/diag time seam_pts \
  plain_rms plain_haus time rms_ratio
for t in "${targets[@]}"; do
  row=()
  for mode in uv plain; do
    flags=()
    [ "$mode" = plain ] && flags=(--attributes none)
    start=$(now)
    "$bin" simplify "$mesh" -o "$out/$mode.obj" --target-tris "$t" --quiet --stats "$out/$mode.json" "${flags[@]}"
    seconds=$(calc "$(now) - $start")
    "$bin" measure "$mesh" "$out/$mode.obj" --json --quiet >"$out/$mode-measure.json"
    read -r rms haus < <(measured "$out/$mode-measure.json")
    row+=("$(output_triangles "$out/$mode.json")" "$rms" "$haus" "$(printf %.2f "$seconds")")
    # Seam points: positions that two or more vertices share (OBJ writes one v per vertex).
    [ "$mode" = uv ] && row+=("$(grep '^v ' "$out/uv.obj" | sort | uniq -d | wc -l)")
  done
  printf "%8s %10s | %10.3e %10.3e %7s %8s | %10.3e %10.3e %7s | %9s\n" "$t" "${row[0]}" "${row[1]}" "${row[2]}" \
    "${row[3]}" "${row[4]}" "${row[6]}" "${row[7]}" "${row[8]}" "$(ratio "${row[1]}" "${row[6]}")"
done
