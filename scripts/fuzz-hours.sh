#!/usr/bin/env bash
# Sums the fuzzing ledger tests/fuzz/hours.tsv (one row per run of a target, appended
# by scripts/fuzz.sh --ledger) per target and prints it as a Markdown table: runs,
# CPU hours, executions, findings.
#
#   scripts/fuzz-hours.sh            # prints the table
#   scripts/fuzz-hours.sh --update   # also writes it into docs/building.md, between
#                                    # the fuzz-hours markers
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
ledger="$root/tests/fuzz/hours.tsv"
doc="$root/docs/building.md"
targets="fuzz_ply_reader fuzz_obj_reader fuzz_stl_reader fuzz_off_reader fuzz_glb_reader fuzz_gzip_input
  fuzz_hierarchy_file fuzz_simplify fuzz_hierarchy_build"

table() {
  # Columns of the ledger: date commit target wall_seconds cpu_seconds executions findings.
  awk -F'\t' -v targets="$targets" '
    NR == 1 { next }
    { runs[$3]++; cpu[$3] += $5; execs[$3] += $6; if ($7 != "-" && $7 != "") found[$3] = found[$3] (found[$3] == "" ? "" : ", ") $7
      if (first == "" || $1 < first) first = $1; if ($1 > last) last = $1 }
    END {
      print "| target | runs | CPU hours | executions | findings |"
      print "|---|---:|---:|---:|---|"
      n = split(targets, t, /[ \n]+/)
      for (i = 1; i <= n; i++) {
        if (t[i] == "") continue
        k = t[i]; total_cpu += cpu[k]; total_execs += execs[k]; total_runs += runs[k]
        printf "| `%s` | %d | %.2f | %d | %s |\n", k, runs[k], cpu[k] / 3600, execs[k], (found[k] == "" ? "none" : found[k])
      }
      printf "| all | %d | %.2f | %d | |\n", total_runs, total_cpu / 3600, total_execs
      if (first != "") printf "\nRuns from %s to %s (UTC).\n", substr(first, 1, 10), substr(last, 1, 10)
    }' "$ledger"
}

[ -f "$ledger" ] || { echo "fuzz-hours.sh: no ledger $ledger" >&2; exit 1; }
case "${1:-}" in
  "") table ;;
  --update)
    mkdir -p "$root/build-fuzz"
    exec 9>"$root/build-fuzz/.hours.lock"
    flock 9
    tmp="$(mktemp)"
    table >"$tmp"
    grep -q '^<!-- fuzz-hours begin' "$doc" || { echo "fuzz-hours.sh: no fuzz-hours markers in $doc" >&2; exit 1; }
    awk -v tablefile="$tmp" '
      /^<!-- fuzz-hours begin/ { print; while ((getline line < tablefile) > 0) print line; skip = 1; next }
      /^<!-- fuzz-hours end/ { skip = 0 }
      !skip { print }' "$doc" >"$doc.new"
    mv "$doc.new" "$doc"
    rm -f "$tmp"
    ;;
  *) echo "usage: scripts/fuzz-hours.sh [--update]" >&2; exit 2 ;;
esac
