#!/usr/bin/env bash
# The packaging route a Python user takes, with Debian's tools and no network:
# `pip install . --no-build-isolation` into a fresh venv, and
# `python3 -m build --wheel --no-isolation`; both reuse the CMake build tree
# (VOLA_CMAKE_BUILD_DIR), so only the packaging is under test here. The installed package
# must work from its own folder alone: the extension, the stubs and the plugins it loads.
# Usage: pip_install.sh SOURCE_DIR BUILD_DIR PYTHON
set -euo pipefail
source_dir=$1 build=$2 python=$3
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }
export VOLA_CMAKE_BUILD_DIR=$build PIP_NO_INDEX=1 PIP_DISABLE_PIP_VERSION_CHECK=1
unset PYTHONPATH VOLA_PLUGIN_DIR

"$python" -m venv --system-site-packages "$work/venv"  # numpy from Debian's site-packages
"$work/venv/bin/pip" install --no-build-isolation --no-deps "$source_dir" > "$work/pip.log" 2>&1 ||
  fail "pip install: $(tail -20 "$work/pip.log")"
cd "$work"
"$work/venv/bin/python" - "$work/venv" <<'PY' || fail "the pip-installed package"
import pathlib, sys
import numpy as np
import vola
here = pathlib.Path(vola.__file__).parent
assert str(here).startswith(sys.argv[1]), here  # the venv's copy, not the build tree's
for f in ("__init__.pyi", "_vola.pyi", "py.typed", "libvola_gdal.so", "libvola_proj.so", "libvola_assimp.so"):
    assert (here / f).exists(), f
tree = vola.build(np.array([[0.5, 0.5, 0.5], [7.5, 0.5, 0.5]]), voxel_size=1.0, origin=(0.0, 0.0, 0.0))
assert tree.contains(np.array([[0, 0, 0], [7, 0, 0], [1, 0, 0]])).tolist() == [True, True, False]
# The PROJ plugin from the package folder: the header's lat/lon of a point in UTM 33N.
pathlib.Path("utm.xyz").write_text("500000.5 5000000.5 0.5\n")
lat, lon = vola.convert("utm.xyz", voxel_size=1.0, assign_crs="EPSG:32633").lat_lon
assert abs(lat - 45.1) < 0.1 and abs(lon - 15.0) < 0.01, (lat, lon)
# The mesh reader (an Assimp plugin) reads an STL.
stl = pathlib.Path("tetra.stl")
faces = [((0, 0, 0), (1, 0, 0), (0, 1, 0)), ((0, 0, 0), (0, 1, 0), (0, 0, 1)),
         ((0, 0, 0), (0, 0, 1), (1, 0, 0)), ((1, 0, 0), (0, 1, 0), (0, 0, 1))]
stl.write_text("solid t\n" + "".join("facet normal 0 0 0\nouter loop\n" + "".join(
    f"vertex {x} {y} {z}\n" for x, y, z in f) + "endloop\nendfacet\n" for f in faces) + "endsolid t\n")
assert vola.convert(stl, depth=2).voxel_count > 0
print("pip-installed vola works:", vola.__file__)
PY

"$python" -m build --version > /dev/null 2>&1 || fail "python3 -m build is missing (apt-get install python3-build)"
(cd "$source_dir" && "$python" -m build --wheel --no-isolation --outdir "$work/dist" .) > "$work/build.log" 2>&1 ||
  fail "python3 -m build --wheel: $(tail -20 "$work/build.log")"
wheel=$(ls "$work"/dist/vola-*.whl)
"$python" -m zipfile -l "$wheel" > "$work/wheel.txt"
for f in vola/__init__.py vola/_vola.pyi vola/py.typed vola/libvola_gdal.so vola-.*dist-info/METADATA; do
  grep -Eq "^$f" "$work/wheel.txt" || fail "the wheel lacks $f"
done
grep -Eq "^vola/_vola\.cpython-.*\.so" "$work/wheel.txt" || fail "the wheel lacks the extension"
echo "pip_install: OK ($(basename "$wheel"))"
