#!/usr/bin/env bash
# The main job: install what is missing, build if stale, then `oocsimp simplify ARGS`.
# With no arguments, generates a 2M-triangle sphere under build/ and simplifies it.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
"$root/scripts/setup-deps.sh"
"$root/scripts/build.sh"
bin="$root/build/oocsimp"
if [ $# -eq 0 ]; then
  # Shell completion and the man page, from the program's help, and how to install them.
  "$root/scripts/completions.sh" "$bin" "$root/build/share" >&2 || true
  mesh="$root/build/sphere-2M.ply"
  [ -f "$mesh" ] || "$bin" generate --tris 2000000 --shape sphere --seed 1 -o "$mesh"
  exec "$bin" simplify "$mesh" -o "$root/build/sphere-2M-simplified.ply" --grid 256 --stats "$root/build/sphere-2M-stats.json"
fi
exec "$bin" simplify "$@"
