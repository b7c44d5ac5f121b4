#!/usr/bin/env bash
# Installs from Debian only the build dependencies that are missing. Idempotent and
# quiet when everything is there. clang (with its sanitizer runtimes) builds the
# sanitizer suite of scripts/test.sh --sanitize, so CI compiles with both compilers.
# python3-setuptools, -pip, -venv and -wheel: `pip install --no-build-isolation .` of
# the Python module (docs/python.md) and its test.
set -euo pipefail

packages=(cmake g++ clang libclang-rt-14-dev make pkg-config libtbb-dev libopenmesh-dev libzstd-dev zlib1g-dev libcli11-dev catch2 libmeshoptimizer-dev libxxhash-dev libpng-dev libjpeg62-turbo-dev nlohmann-json3-dev libopenmpi-dev openmpi-bin slurm-wlm munge pybind11-dev python3-dev python3-numpy python3-setuptools python3-pip python3-venv python3-wheel)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && exit 0

echo "setup-deps: installing ${missing[*]}" >&2
sudo=""
[ "$(id -u)" -ne 0 ] && sudo="sudo"
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -qq >/dev/null
$sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
