#!/usr/bin/env bash
# `pip install --no-build-isolation .` of this source tree into a throwaway venv: the
# module imports from there (not from build/python) and gives the CLI's bytes.
# OOCSIMP_CMAKE_BUILD_DIR points setup.py at the suite's own build folder, so nothing
# is compiled twice. Exits 77 (skipped) where venv or pip is missing.
#   tests/pip_install.sh PYTHON SOURCE_DIR BUILD_DIR OOCSIMP_CLI
set -euo pipefail
python=$1 source=$2 build=$3 cli=$4
skip() { echo "pip_install: skipped: $*"; exit 77; }

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
"$python" -m venv --system-site-packages "$tmp/venv" >"$tmp/venv.log" 2>&1 ||
  skip "$python -m venv failed (python3-venv missing?): $(tail -n 1 "$tmp/venv.log")"
venv_python=$tmp/venv/bin/python
"$venv_python" -m pip --version >/dev/null 2>&1 || skip "no pip in the venv (python3-pip missing?)"
"$venv_python" -c "import setuptools, wheel" 2>/dev/null ||
  skip "no setuptools or wheel for --no-build-isolation (python3-setuptools, python3-wheel missing?)"

# --no-index: nothing from the network; --ignore-installed: into the venv even where the
# system's Python already has an oocsimp.
OOCSIMP_CMAKE_BUILD_DIR=$build PYTHONPATH= "$venv_python" -m pip install --no-build-isolation --no-index \
  --no-deps --ignore-installed --no-cache-dir --quiet "$source"

"$cli" generate --quiet --shape parts --tris 20000 -o "$tmp/in.ply"
"$cli" simplify --quiet "$tmp/in.ply" -o "$tmp/cli.ply" --target-tris 1000
cd "$tmp"  # not the source tree, so nothing there can be imported by accident
PYTHONPATH= "$venv_python" - "$tmp" <<'PY'
import os, sys
import numpy as np
import oocsimp

tmp = sys.argv[1]
site = os.path.realpath(os.path.join(tmp, "venv"))
where = os.path.realpath(oocsimp.__file__)
assert where.startswith(site + os.sep), f"oocsimp imported from {where}, not from the venv {site}"
stats = oocsimp.simplify_file(os.path.join(tmp, "in.ply"), os.path.join(tmp, "py.ply"), target_tris=1000)
with open(os.path.join(tmp, "py.ply"), "rb") as a, open(os.path.join(tmp, "cli.ply"), "rb") as b:
    assert a.read() == b.read(), "the installed module's output differs from the CLI's"
assert stats["output"]["triangles"] == 1000, stats["output"]
# Arrays too: the unit square as a 20 x 20 grid of 800 triangles, down to 100, stays
# flat with its area of 1.
x, y = np.meshgrid(np.linspace(0.0, 1.0, 21), np.linspace(0.0, 1.0, 21))
v = np.stack([x.ravel(), y.ravel(), np.zeros(x.size)], axis=1)
i = np.arange(21 * 21).reshape(21, 21)
a, b, c, d = i[:-1, :-1].ravel(), i[1:, :-1].ravel(), i[:-1, 1:].ravel(), i[1:, 1:].ravel()
f = np.concatenate([np.stack([a, b, d], 1), np.stack([a, d, c], 1)]).astype(np.int32)
v2, f2 = oocsimp.simplify(v, f, target_tris=100)
assert f2.shape == (100, 3), f2.shape
assert np.abs(v2[:, 2]).max() == 0.0
p, q, r = v2[f2[:, 0]], v2[f2[:, 1]], v2[f2[:, 2]]
area = 0.5 * np.linalg.norm(np.cross(q - p, r - p), axis=1).sum()
assert abs(area - 1.0) < 1e-9, area
print(f"pip_install: oocsimp {oocsimp.__version__} installed into a venv and imported from {where}")
PY
