#!/usr/bin/env bash
# Minimises what a target's runs grew (build-fuzz/corpus/TARGET, after scripts/fuzz.sh)
# with libFuzzer's -merge=1 into a fresh folder, leaving out what the seeds fuzz.sh
# writes already cover, and keeps the files of at most MAX_BYTES (default 4096) in
# tests/fuzz/corpus/TARGET, which fuzz.sh copies into the seed corpus. Prints the
# count and bytes kept; commit them only where they are small (a few hundred KB).
#
#   nice -n 19 scripts/fuzz-keep.sh TARGET [MAX_BYTES]
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
[ $# -ge 1 ] || { echo "usage: scripts/fuzz-keep.sh TARGET [MAX_BYTES]" >&2; exit 2; }
t="$1"
max="${2:-4096}"
build="$root/build-fuzz"
src="$build/corpus/$t"
[ -x "$build/$t" ] && [ -d "$src" ] || { echo "fuzz-keep.sh: run scripts/fuzz.sh for $t first" >&2; exit 1; }
work="$build/keep/$t"
rm -rf "$work"
mkdir -p "$work/new" "$work/tmp"
# The seeds fuzz.sh writes have readable names; what libFuzzer adds (and what is kept
# here) is named by its SHA-1. The seeds go in first, so the merge adds only what they
# do not cover, and come out again.
find "$src" -maxdepth 1 -regextype posix-extended -type f ! -regex '.*/[0-9a-f]{40}' -printf '%f\n' >"$work/seeds.txt"
while read -r f; do cp "$src/$f" "$work/new/"; done <"$work/seeds.txt"
extra=()
if [ "$t" = fuzz_simplify ] || [ "$t" = fuzz_hierarchy_build ]; then extra=(-max_len=65537); fi
ASAN_OPTIONS=detect_leaks=1 TMPDIR="$work/tmp" "$build/$t" -merge=1 -timeout=10 -rss_limit_mb=2048 "${extra[@]}" \
  "$work/new" "$src" >"$work/merge.log" 2>&1 || { echo "fuzz-keep.sh: the merge failed, see $work/merge.log" >&2; exit 1; }
while read -r f; do rm -f "$work/new/$f"; done <"$work/seeds.txt"
find "$work/new" -type f -size +"$max"c -delete
rm -rf "$root/tests/fuzz/corpus/$t"
mkdir -p "$root/tests/fuzz/corpus/$t"
cp "$work/new"/. "$root/tests/fuzz/corpus/$t/" -R
echo "$t: kept $(find "$root/tests/fuzz/corpus/$t" -type f | wc -l) files," \
  "$(find "$root/tests/fuzz/corpus/$t" -type f -printf '%s\n' | awk '{ s += $1 } END { print s + 0 }') bytes"
