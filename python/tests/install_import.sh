#!/usr/bin/env bash
# The install route: `cmake --install --component python` into a scratch prefix, then
# import vola from there alone and use it. Usage: install_import.sh BUILD_DIR PYTHON
set -euo pipefail
build=$1 python=$2
prefix=$(mktemp -d)
trap 'rm -rf "$prefix"' EXIT
cmake --install "$build" --component python --prefix "$prefix" >/dev/null
site=$prefix/$(sed -n 's/^VOLA_PYTHON_INSTALL_DIR:STRING=//p' "$build/CMakeCache.txt")
cd "$prefix"
PYTHONPATH=$site "$python" - "$site" <<'PY'
import sys
import numpy as np
import vola
assert vola.__file__.startswith(sys.argv[1]), vola.__file__
tree = vola.build(np.array([[0.5, 0.5, 0.5], [7.5, 0.5, 0.5]]), voxel_size=1.0, origin=(0.0, 0.0, 0.0))
assert tree.contains(np.array([[0, 0, 0], [7, 0, 0], [1, 0, 0]])).tolist() == [True, True, False]
for f in ("__init__.pyi", "_vola.pyi", "py.typed"):
    assert (__import__("pathlib").Path(vola.__file__).parent / f).exists(), f
print("installed vola imports and works:", vola.__file__)
PY
