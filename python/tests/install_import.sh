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
VOLA_PLUGIN_DIR=$site/vola PYTHONPATH=$site "$python" - "$site" <<'PY'
import sys
import numpy as np
import vola
assert vola.__file__.startswith(sys.argv[1]), vola.__file__
tree = vola.build(np.array([[0.5, 0.5, 0.5], [7.5, 0.5, 0.5]]), voxel_size=1.0, origin=(0.0, 0.0, 0.0))
assert tree.contains(np.array([[0, 0, 0], [7, 0, 0], [1, 0, 0]])).tolist() == [True, True, False]
here = __import__("pathlib").Path(vola.__file__).parent
for f in ("__init__.pyi", "_vola.pyi", "py.typed", "libvola_assimp.so", "libvola_gdal.so", "libvola_proj.so"):
    assert (here / f).exists(), f
# The mesh reader is a plugin: the installed one loads (VOLA_PLUGIN_DIR, set below, is
# searched first) and reads an STL written here.
stl = here.parent / "tetra.stl"
stl.write_text("solid t\n" + "".join(
    "facet normal 0 0 0\nouter loop\n" + "".join(f"vertex {x} {y} {z}\n" for x, y, z in f) + "endloop\nendfacet\n"
    for f in [((0, 0, 0), (1, 0, 0), (0, 1, 0)), ((0, 0, 0), (0, 1, 0), (0, 0, 1)),
              ((0, 0, 0), (0, 0, 1), (1, 0, 0)), ((1, 0, 0), (0, 1, 0), (0, 0, 1))]) + "endsolid t\n")
assert vola.convert(stl, depth=2).voxel_count > 0
print("installed vola imports and works:", vola.__file__)
PY
