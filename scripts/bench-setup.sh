# Sourced by the benchmark scripts (bench.sh, quality.sh): installs what is missing and
# builds unless BENCH_NO_BUILD is set, and defines the paths and JSON helpers they share.
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
if [ -z "${BENCH_NO_BUILD:-}" ]; then
  "$root/scripts/setup-deps.sh"
  "$root/scripts/build.sh"
fi
bin="${OOCSIMP_BIN:-$root/build/oocsimp}"
dir="$root/build/bench"  # generated meshes are cached here
mkdir -p "$dir"

now() { date +%s.%N; }
calc() { awk "BEGIN { print $1 }"; }
ratio() { awk -v a="$1" -v b="$2" 'BEGIN { printf("%.2fx", a / b) }'; }
measured() {  # measured MEASURE.json -> "rms/diag hausdorff/diag" of the symmetric distance
  grep '"symmetric"' "$1" |
    sed -E 's/.*"of_diagonal": \{"hausdorff": ([^,]*), "mean": [^,]*, "rms": ([^}]*)\}.*/\2 \1/'
}
json_field() {  # json_field FILE KEY -> first number after "KEY":
  grep -o "\"$2\": [0-9.e+-]*" "$1" | head -1 | awk '{print $2}'
}
output_triangles() {  # output_triangles STATS.json -> the output triangle count
  grep -o '"output": {"vertices": [0-9]*, "triangles": [0-9]*' "$1" | awk '{print $NF}'
}
