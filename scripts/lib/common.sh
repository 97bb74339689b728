# Shared by the scripts: where things are, and installing Debian packages when missing.
# shellcheck shell=bash
set -euo pipefail

VOLA_ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
export VOLA_ROOT
export VOLA_SHARED=${VOLA_SHARED:-$(cd "$VOLA_ROOT/.." && pwd)/shared}

# Packages every build needs (the core needs none; the CLI, tests and geo do).
VOLA_BUILD_PACKAGES=(cmake make g++ libcli11-dev libzstd-dev libproj-dev proj-data libgtest-dev libgmock-dev
  nlohmann-json3-dev python3 python3-numpy python3-scipy gzip libassimp-dev libdraco-dev libgdal-dev libpng-dev liblzf-dev libeigen3-dev libsndfile1-dev libfftw3-dev libmysofa-dev pkg-config
  libexpat1-dev)

# The Python module (pybind11, numpy) and its tests (pytest, matplotlib for the example).
VOLA_BUILD_PACKAGES+=(python3-dev pybind11-dev python3-pytest python3-matplotlib python3-pyproj)
# pip install . and python3 -m build --wheel (pyproject.toml), tested in a venv.
VOLA_BUILD_PACKAGES+=(python3-venv python3-pip python3-setuptools python3-wheel python3-build)

# vola view: cpp-httplib, chromium for its browser test, and node/npm to build the page
# (three.js, esbuild from the npm registry); a machine with its own node keeps it.
VOLA_BUILD_PACKAGES+=(libcpp-httplib-dev pkg-config chromium)
command -v npm > /dev/null || VOLA_BUILD_PACKAGES+=(nodejs npm)

# 3D CNN classification (vola_learn): libtorch (CPU); libzip for .npz (vola_io), found through pkg-config.
VOLA_BUILD_PACKAGES+=(libtorch-dev libzip-dev pkg-config)

# Occupancy maps in and out: OctoMap .bt/.ot through liboctomap (the octomap plugin; the
# map tests also compare with OctoMap cell by cell) and .vdb through OpenVDB (the openvdb
# plugin; libopenvdb-dev brings TBB and Blosc, but not the Boost.Iostreams headers that
# OpenVDB's headers and FindOpenVDB.cmake need).
VOLA_BUILD_PACKAGES+=(liboctomap-dev libopenvdb-dev libboost-iostreams-dev)

# vola export --raster's test reads the GeoTIFFs back with GDAL's Python bindings; the tile test
# opens the tile index with ogrinfo, as a GIS user would.
VOLA_BUILD_PACKAGES+=(python3-gdal gdal-bin)

# vola fuse: ORB features (OpenCV) for wide-baseline tracking and relocalisation.
VOLA_BUILD_PACKAGES+=(libopencv-dev)

# vola tile under mpirun: Open MPI (the tests run 3 ranks on one machine).
VOLA_BUILD_PACKAGES+=(libopenmpi-dev openmpi-bin)

# install_packages PKG...: apt-get installs the ones that are missing (as root), or
# says exactly what to install.
install_packages() {
  local missing=()
  for p in "$@"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  [ ${#missing[@]} -eq 0 ] && return 0
  if [ "$(id -u)" -ne 0 ]; then
    echo "vola: missing Debian packages: ${missing[*]}" >&2
    echo "      run as root, or: sudo apt-get install ${missing[*]}" >&2
    exit 1
  fi
  echo "vola: installing ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends "${missing[@]}"
}
