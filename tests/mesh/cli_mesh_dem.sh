#!/usr/bin/env bash
# `vola convert` on meshes and DEMs, end to end.
#
#   cli_mesh_dem.sh VOLA_BINARY DATA_DIR
#
# Every mesh kind converts with `--quantize toolkit --depth 5` (and grid mode, and
# --solid); toolkit frames are the vertices' bbox; each GeoTIFF converts, with one
# voxel column per valid cell and the raster's EPSG code in the header.
# Exit status: 0 all good, 1 failures, 77 data folder missing (outside CI).
set -uo pipefail

if [[ $# -ne 2 ]]; then
  echo "usage: $0 VOLA_BINARY DATA_DIR" >&2
  exit 2
fi
vola=$1
data=$2
keep_going=1
source "$(dirname "$0")/../lib/cli_test.sh"
[[ -d $data/mesh && -d $data/dem ]] || skip "data folder $data is missing"

# info_field FILE KEY: one field of `vola info --json`.
info_field() {
  "$vola" info --json "$1" | python3 -c "import json, sys; v = json.load(sys.stdin)['$2']; print(' '.join(map(str, v)) if isinstance(v, list) else v)"
}

# distinct (x, y) columns of a .vol file
columns() {
  "$vola" voxels "$1" | awk '{print $1, $2}' | sort -u | wc -l
}

meshes=(
  "$data/mesh/stl/trimesh_fuji_ascii.stl"
  "$data/mesh/stl/trimesh_teapot_bin.stl"
  "$data/mesh/stl/trimesh_20mm-xyz-cube_bin_colorhdr.stl"
  "$data/mesh/obj/ajc_spot.obj"
  "$data/mesh/off/trimesh_ballA.off"
  "$data/modelnet/off/bathtub_0002.off"
)
for mesh in "${meshes[@]}"; do
  name=$(basename "$mesh")
  out=$tmp/$name.vol
  if ! "$vola" convert "$mesh" "$out" --quantize toolkit --depth 5 -q; then
    fail "$name: toolkit conversion failed"
    continue
  fi
  voxels=$(info_field "$out" voxels)
  [[ $voxels -gt 0 ]] || fail "$name: no voxels"
  [[ $(info_field "$out" depth) == 5 ]] || fail "$name: depth is not 5"
  # The header bbox is the vertices' bbox: its extent is what EXPECTED.txt says, to 1e-3.
  bbox=$(info_field "$out" bbox)
  expected=$(grep -m1 "^$name " "$data/EXPECTED.txt" | sed -n 's/.*bbox=\[\([^]]*\)\]\.\.\[\([^]]*\)\].*/\1, \2/p' | tr -d ',')
  if [[ -n $expected ]]; then
    python3 - "$bbox" "$expected" <<'PY' || fail "$name: header bbox $bbox, EXPECTED.txt $expected"
import sys
got = [float(v) for v in sys.argv[1].split()]
want = [float(v) for v in sys.argv[2].split()]
sys.exit(0 if all(abs(g - w) <= 1e-3 * max(1.0, abs(w)) for g, w in zip(got, want)) else 1)
PY
  fi
done

# Grid mode, and the solid fill of a closed mesh.
cube=$data/mesh/stl/trimesh_20mm-xyz-cube_bin_colorhdr.stl
"$vola" convert "$cube" "$tmp/cube_grid.vol" --voxel-size 0.5 -q || fail "cube: grid conversion failed"
[[ $(info_field "$tmp/cube_grid.vol" quantization) == grid ]] || fail "cube: not a grid frame"
"$vola" convert "$cube" "$tmp/cube_surface.vol" --quantize toolkit --depth 3 -q || fail "cube: depth 3 failed"
"$vola" convert "$cube" "$tmp/cube_solid.vol" --quantize toolkit --depth 3 --solid -q || fail "cube: --solid failed"
surface=$(info_field "$tmp/cube_surface.vol" voxels)
solid=$(info_field "$tmp/cube_solid.vol" voxels)
# The 20 mm cube fills its own toolkit frame but for the letters cut into its faces.
[[ $solid -gt $((surface * 4)) && $solid -le $((64 * 64 * 64)) ]] || fail "cube: solid $solid voxels, surface $surface"

# DEMs: one voxel column per valid cell (neither file has nodata cells: the library
# tests cover nodata), the EPSG code in the header, and a toolkit conversion.
dem_case() {
  local file=$1 size=$2 epsg=$3 cells=$4
  local extra=("${@:5}")
  local name
  name=$(basename "$file")
  "$vola" convert "$file" "$tmp/$name.surface.vol" --voxel-size "$size" --dem-surface-only -q "${extra[@]}" || {
    fail "$name: surface conversion failed"
    return
  }
  [[ $(columns "$tmp/$name.surface.vol") == "$cells" ]] || fail "$name: $(columns "$tmp/$name.surface.vol") columns, expected $cells"
  [[ $(info_field "$tmp/$name.surface.vol" voxels) == "$cells" ]] || fail "$name: surface-only is not one voxel per cell"
  [[ $(info_field "$tmp/$name.surface.vol" crs) == "$epsg" ]] || fail "$name: header EPSG is not $epsg"
  "$vola" convert "$file" "$tmp/$name.toolkit.vol" --quantize toolkit --depth 4 -q || fail "$name: toolkit conversion failed"
  [[ $(info_field "$tmp/$name.toolkit.vol" crs) == "$epsg" ]] || fail "$name: toolkit header EPSG is not $epsg"
}
dem_case "$data/dem/pdal_gdal_int16_epsg26711.tif" 60 26711 $((20 * 20))
dem_case "$data/dem/pysheds_dem_int16_tiled_epsg4326.tif" 0.000833333333333 4326 $((367 * 359)) --allow-geographic
# Without --allow-geographic, cells of degrees under heights of metres are refused, naming the way out.
"$vola" convert "$data/dem/pysheds_dem_int16_tiled_epsg4326.tif" "$tmp/degrees.vol" --voxel-size 0.000833333333333 \
  2> "$tmp/degrees.err" && fail "a DEM in degrees became grid voxels without --allow-geographic"
grep -q -- "geographic CRS.*reproject the raster first (gdalwarp.*--allow-geographic" "$tmp/degrees.err" || fail "degrees: $(cat "$tmp/degrees.err")"
[[ -e "$tmp/degrees.vol" ]] && fail "a refused conversion wrote its output"

# Full columns: as many columns as cells, and more voxels than cells.
pdal=$data/dem/pdal_gdal_int16_epsg26711.tif
"$vola" convert "$pdal" "$tmp/columns.vol" --voxel-size 60 -q || fail "pdal dem: column conversion failed"
[[ $(columns "$tmp/columns.vol") == 400 ]] || fail "pdal dem: columns"
[[ $(info_field "$tmp/columns.vol" voxels) -gt 400 ]] || fail "pdal dem: columns hold no more than the surface"
# A base below everything lengthens every column by the same number of voxels.
"$vola" convert "$pdal" "$tmp/deeper.vol" --voxel-size 60 --origin 440700 3750120 -600 --dem-base -600 -q ||
  fail "pdal dem: --dem-base failed"
[[ $(info_field "$tmp/deeper.vol" voxels) -gt $(info_field "$tmp/columns.vol" voxels) ]] || fail "pdal dem: --dem-base did not deepen"

# Options that do not fit the input are refused.
if "$vola" convert "$pdal" "$tmp/x.vol" --voxel-size 60 --solid -q 2>/dev/null; then fail "--solid on a DEM was accepted"; fi
if "$vola" convert "$cube" "$tmp/x.vol" --voxel-size 1 --dem-base 0 -q 2>/dev/null; then fail "--dem-base on a mesh was accepted"; fi
if "$vola" convert "$cube" "$tmp/x.vol" --voxel-size 1 --nbits 1 -q 2>/dev/null; then fail "--nbits on a mesh was accepted"; fi

# An ESRI ASCII grid (.asc, which is also a text-points extension) is told by its first
# word and read as a DEM: 3 x 2 cells of 10, one without data.
printf 'NCOLS 3\nNROWS 2\nxllcorner 100\nyllcorner 200\ncellsize 10\nNODATA_value -9999\n1 2 3\n4 -9999 6\n' > "$tmp/grid.asc"
"$vola" info "$tmp/grid.asc" > "$tmp/asc_info.txt" || fail "info on an ESRI ASCII grid failed"
grep -q "^cells: *5 with a height" "$tmp/asc_info.txt" || fail "ESRI ASCII grid: $(cat "$tmp/asc_info.txt")"
"$vola" convert "$tmp/grid.asc" "$tmp/asc.vol" --voxel-size 10 --dem-surface-only -q || fail "convert of an ESRI ASCII grid failed"
[[ $(info_field "$tmp/asc.vol" voxels) == 5 ]] || fail "ESRI ASCII grid: not 5 surface voxels"

if [[ $failures -gt 0 ]]; then
  echo "$failures failure(s)" >&2
  exit 1
fi
echo "mesh and DEM conversions: all good"
