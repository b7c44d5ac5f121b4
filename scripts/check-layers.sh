#!/usr/bin/env bash
# Checks that includes run one way: a file may include only files of its own folder or
# of a folder on a lower floor (docs/design.md, "Layers"). Prints each include that runs
# back up, or sideways between two folders of one floor, and exits 1 if there is any.
#   scripts/check-layers.sh
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
cd "$root"

# The floors, bottom first; folders on one line share a floor and may not include
# each other.
floors=(
  "include/oocsimp"
  "src/common"
  "src/runtime"
  "src/io"
  "src/spill"
  "src/grid"
  "src/cluster src/curvature"
  "src/stitch src/refine src/hierarchy"
  "src/methods"
  "src/parts"
  "src/report src/metrics src/synth src/render src/lod"
  "src/api"
  "tools"
)

declare -A floor_of
for i in "${!floors[@]}"; do
  for folder in ${floors[$i]}; do floor_of[$folder]=$i; done
done

folder_of() {  # the folder of a path, as the floors name it
  case "$1" in
    include/oocsimp/*) echo include/oocsimp ;;
    tools/*) echo tools ;;
    src/*/*) echo "$1" | cut -d/ -f1-2 ;;
    *) echo "" ;;
  esac
}

bad=0
while IFS= read -r file; do
  from=$(folder_of "$file")
  [ -n "$from" ] || { echo "check-layers: $file is in no folder of a floor" >&2; bad=1; continue; }
  [ -n "${floor_of[$from]+x}" ] || { echo "check-layers: $from has no floor" >&2; bad=1; continue; }
  while IFS= read -r inc; do
    if [ -f "src/$inc" ]; then target="src/$inc"
    elif [ -f "include/$inc" ]; then target="include/$inc"
    else continue  # a system or third-party header
    fi
    to=$(folder_of "$target")
    [ "$to" = "$from" ] && continue
    if [ "${floor_of[$to]}" -ge "${floor_of[$from]}" ]; then
      echo "$file includes $target: $from (floor $((floor_of[$from] + 1))) may not include $to (floor $((floor_of[$to] + 1)))"
      bad=1
    fi
  done < <(sed -n 's/^[[:space:]]*#[[:space:]]*include[[:space:]]*"\([^"]*\)".*/\1/p' "$file")
done < <(find include src tools -name '*.hpp' -o -name '*.cpp' -o -name '*.h' | sort)
[ "$bad" -eq 0 ] && echo "check-layers: every include runs down a floor"
exit "$bad"
