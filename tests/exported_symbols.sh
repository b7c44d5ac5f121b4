#!/usr/bin/env bash
# Checks that liboocsimp exports its public API and none of its internals: every
# defined dynamic symbol is of namespace oocsimp and names a function or a class that
# include/oocsimp/ marks OOCSIMP_API (export.hpp). A static archive (the default build)
# is first linked whole into a shared object with the exports map, as a shared build
# links the same objects.
#   tests/exported_symbols.sh LIBRARY INCLUDE_DIR EXPORTS_MAP WORK_DIR
set -euo pipefail
lib=$1
include=$2
map=$3
work=$4
mkdir -p "$work"
so=$lib
if [[ $lib == *.a ]]; then
  so=$work/liboocsimp_probe.so
  c++ -shared -o "$so" -Wl,--version-script="$map" -Wl,--whole-archive "$lib" -Wl,--no-whole-archive
fi

# The names the API marks: each class, and each function (the identifier before its
# parameter list).
{
  grep -h 'class OOCSIMP_API\|struct OOCSIMP_API' "$include"/*.hpp | sed 's/.*OOCSIMP_API \([A-Za-z_0-9]*\).*/\1/'
  grep -h '^OOCSIMP_API ' "$include"/*.hpp | sed -e 's/(.*//' -e 's/.*[^A-Za-z_0-9]//'
} | sort -u >"$work/api_names"

nm -D --defined-only -C "$so" | cut -d' ' -f3- >"$work/exported"
echo "exported_symbols: $(wc -l <"$work/exported") symbols exported, from $(wc -l <"$work/api_names") names" \
  "marked OOCSIMP_API"

bad=0
while IFS= read -r symbol; do
  name=$symbol
  for prefix in "typeinfo name for " "typeinfo for " "vtable for " "non-virtual thunk to "; do
    name=${name#"$prefix"}
  done
  if [[ $name != oocsimp::* ]]; then
    echo "exported_symbols: not of namespace oocsimp: $symbol"
    bad=1
    continue
  fi
  name=${name#oocsimp::}
  name=${name%%(*}
  name=${name%%::*}
  name=${name%%<*}
  name=${name%%\[*}  # an ABI tag, [abi:cxx11]
  if ! grep -qx "$name" "$work/api_names"; then
    echo "exported_symbols: not marked OOCSIMP_API in include/oocsimp/: $symbol"
    bad=1
  fi
done <"$work/exported"
if ! grep -q '^oocsimp::simplify_file(' "$work/exported"; then
  echo "exported_symbols: oocsimp::simplify_file is not exported"
  bad=1
fi
exit $bad
