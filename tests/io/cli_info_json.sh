#!/usr/bin/env bash
# vola info --json on point files, checked against what an independent reader found in
# them (EXPECTED.txt): for every LAS/LAZ/COPC file named there, the count, point format,
# header bounds at the file's precision and the points per class (--summary reads them);
# for PLY/PCD/KITTI files, the count; for a mesh, a voxel grid and a DEM, their size and
# bounds. A file of the wrong kind gets a clear message.
# E57 files come from E57_WRITER (fuzz_e57_read_replay --write-corpus: files written by
# tests/io/e57_test_file.hpp), when given.
# Usage: cli_info_json.sh VOLA SHARED_DATA_DIR [E57_WRITER]   ($VOLA_SHARED/data, when set, wins)
set -euo pipefail
vola=$1 e57_writer=${3:-} data=${VOLA_SHARED:+$VOLA_SHARED/data}
data=${data:-$2}
source "$(dirname "$0")/../lib/cli_test.sh"
[ -f "$data/EXPECTED.txt" ] || skip "no $data/EXPECTED.txt (set VOLA_SHARED)"

checked=0
for f in "$data"/las/*.las "$data"/las/permutations/*.las "$data"/laz/*.laz; do
  name=$(basename "$f")
  line=$(grep "^$name: " "$data/EXPECTED.txt" || true)
  [ -n "$line" ] || continue
  "$vola" info --json --summary "$f" > "$tmp/info.json" || fail "$name: info --json --summary failed"
  "${VOLA_PYTHON:-python3}" - "$tmp/info.json" "$line" <<'PY' || fail "$name: info --json differs from EXPECTED.txt"
import json, math, re, sys
info, line = json.load(open(sys.argv[1])), sys.argv[2]
assert info["points"] == int(re.search(r" n=(\d+)", line).group(1)), info["points"]
assert info["point_format"] == int(re.search(r" pf=(\d+)", line).group(1))
lo, hi = re.search(r"bounds=\[([^\]]*)\]\.\.\[([^\]]*)\]", line).groups()
def decimals(scale, offset, magnitude):
    # the fewest decimals holding scale and offset exactly, within a double's 15 digits
    d = next((d for d in range(13) if all(abs(abs(v) * 10**d - round(abs(v) * 10**d)) <= 4e-16 * abs(v) * 10**d + 1e-9
                                       for v in (scale, offset))), 12)
    return min(d, max(0, 15 - (math.floor(math.log10(magnitude)) + 1 if magnitude >= 1 else 1)))
for got, want in ((info["bounds"]["min"], lo), (info["bounds"]["max"], hi)):
    for axis, (g, w, s) in enumerate(zip(got, (float(v) for v in want.split(",")), info["scale"])):
        assert abs(g - w) <= max(s, 0.01) / 2 + 1e-9, (got, want)
        # at the file's precision: no binary noise beyond the decimals of scale and offset
        o = info["offset"][axis]
        d = decimals(s, o, max(abs(o), abs(info["bounds"]["min"][axis]), abs(info["bounds"]["max"][axis])))
        assert round(g, d) == g, (g, s, o, d)
if info["scale"] == [0.00025] * 3:  # RiSCAN's quarter millimetres take five decimals, not four
    assert info["bounds"]["max"][0] == 515400.00175, info["bounds"]
classes = re.search(r"classes=\{([^}]*)\}", line)
if classes:
    want = {int(k): int(v) for k, v in re.findall(r"(\d+): (\d+)", classes.group(1))}
    got = {c["code"]: c["points"] for c in info["summary"].get("classes", [])}
    assert got == want, (got, want)
assert info["summary"]["points_read"] == info["points"]
# Every dimension of the records, as pdal info lists them (not the columns vola convert keeps).
names = [d["name"] for d in info["dimensions"]]
pf = info["point_format"]
want = ["x", "y", "z", "intensity", "return_number", "number_of_returns", "classification", "user_data",
        "point_source_id"] + (["gps_time"] if pf not in (0, 2) else []) + \
       (["red", "green", "blue"] if pf in (2, 3, 5, 7, 8, 10) else []) + ["scan_angle_rank"]
assert names[:len(want)] == want, names
assert "height" not in names, names
for name in want[3:]:
    assert name in info["summary"]["columns"] or info["points"] == 0, (name, info["summary"]["columns"])
PY
  checked=$((checked + 1))
done
[ "$checked" -ge 20 ] || fail "only $checked LAS/LAZ files of EXPECTED.txt were checked"

# Other point files: the count and the columns; the CRS as PROJ names it (or null).
for f in "$data"/ply/pdal_simple_text.ply "$data"/pcd/pcl_bun0.pcd "$data"/kitti/object_training/velodyne/000000.bin; do
  "$vola" info --json --summary "$f" > "$tmp/other.json" || fail "$(basename "$f"): info --json failed"
  "${VOLA_PYTHON:-python3}" -c "
import json, sys
d = json.load(open(sys.argv[1]))
assert d['points'] > 0 and d['summary']['points_read'] == d['points'], d
assert 'crs' in d and isinstance(d['dimensions'], list), d
" "$tmp/other.json" || fail "$(basename "$f"): bad JSON"
done
"${VOLA_PYTHON:-python3}" -c "import json,sys; assert json.load(open(sys.argv[1]))['points'] == 115384" "$tmp/other.json" ||
  fail "KITTI 000000.bin: not 115384 points"
# An organized PCD (640 x 480, its missing points NaN): the finite points, and the others
# counted as left out, as EXPECTED.txt has them (points=307200 finite=209280).
mug=$data/pcd/pcl_table_scene_mug_stereo_textured.pcd
"$vola" info --json "$mug" > "$tmp/mug.json" || fail "info --json on an organized PCD failed"
"${VOLA_PYTHON:-python3}" -c "
import json, sys
d = json.load(open(sys.argv[1]))
assert (d['points'], d['points_not_finite']) == (209280, 97920), d
" "$tmp/mug.json" || fail "organized PCD: not 209280 points and 97920 left out"
"$vola" info "$mug" | grep -q "^points: *209280 (and 97920 with a coordinate that is not finite, left out)" ||
  fail "info on an organized PCD does not say that 97920 NaN points were left out"

# Inputs that are not point clouds, against the files' own headers read here: a binary
# STL's triangle count (bytes 80-83), a binvox file's dims, cube side and run-length
# coded cells, a DEM's cells with a value and its cell centres (GDAL, when python3-gdal
# is there; in CI it must be).
stl=$data/mesh/stl/trimesh_teapot_bin.stl
binvox=$data/binvox/binvoxrw_chair.binvox
dem=$data/dem/pdal_gdal_int16_epsg26711.tif
"$vola" info --json "$stl" > "$tmp/mesh.json" || fail "info --json on a mesh failed"
"$vola" info --json "$binvox" > "$tmp/grid.json" || fail "info --json on a binvox file failed"
"$vola" info --json --summary "$dem" > "$tmp/dem.json" || fail "info --json --summary on a DEM failed"
"$vola" info "$stl" | grep -q "^triangles: " || fail "info on a mesh: no triangle count"
"${VOLA_PYTHON:-python3}" - "$tmp" "$stl" "$binvox" "$dem" <<'PY' || fail "info on a mesh, a voxel grid or a DEM differs from the file"
import json, os, struct, sys
tmp, stl, binvox, dem = sys.argv[1:]
mesh = json.load(open(os.path.join(tmp, "mesh.json")))
assert mesh["kind"] == "mesh" and mesh["triangles"] == struct.unpack_from("<I", open(stl, "rb").read(), 80)[0], mesh
assert all(a <= b for a, b in zip(mesh["bounds"]["min"], mesh["bounds"]["max"])), mesh
grid = json.load(open(os.path.join(tmp, "grid.json")))
raw = open(binvox, "rb").read()
head, body = raw.split(b"data\n", 1)
fields = {l.split()[0]: l.split()[1:] for l in head.decode().splitlines() if l.strip()}
dims = [int(v) for v in fields["dim"]]
occupied = sum(body[i + 1] for i in range(0, len(body) - 1, 2) if body[i] == 1)
assert grid["kind"] == "voxel grid" and grid["grid"]["dims"] == dims and grid["grid"]["occupied"] == occupied, grid
assert abs(grid["grid"]["voxel_size"] * max(dims) - float(fields["scale"][0])) < 1e-9, grid
try:
    from osgeo import gdal
except ImportError:
    if os.environ.get("CI"):
        raise
    sys.exit(0)
d = json.load(open(os.path.join(tmp, "dem.json")))
ds = gdal.Open(dem)
band = ds.GetRasterBand(1)
values = band.ReadAsArray()
nodata = band.GetNoDataValue()
cells = int((values != nodata).sum()) if nodata is not None else values.size
x0, dx, _, y0, _, dy = ds.GetGeoTransform()
assert d["kind"] == "height field" and d["cells"] == cells and d["summary"]["points_read"] == cells, (d["cells"], cells)
assert abs(d["bounds"]["min"][0] - (x0 + dx / 2)) < 1e-6 and abs(d["bounds"]["max"][1] - (y0 + dy / 2)) < 1e-6, d["bounds"]
assert d["bounds"]["min"][2] == float(values[values != nodata].min() if nodata is not None else values.min()), d["bounds"]
assert d["crs"]["epsg"] == 26711, d["crs"]
PY

# A DEM in degrees: vola convert reprojects points only, so info suggests
# --allow-geographic (which works as printed) or gdalwarp to WGS 84's UTM zone at its
# centre (pysheds' DEM lies at 97.3 W, 32.7 N: zone 14 north).
geo_dem=$data/dem/pysheds_dem_int16_tiled_epsg4326.tif
"$vola" info "$geo_dem" > "$tmp/geo_dem.txt" || fail "info on a DEM in degrees failed"
grep -q "^to voxels: .* --allow-geographic" "$tmp/geo_dem.txt" || fail "geographic DEM: $(cat "$tmp/geo_dem.txt")"
grep -q "gdalwarp -t_srs EPSG:32614 " "$tmp/geo_dem.txt" || fail "geographic DEM: no UTM zone 14N: $(cat "$tmp/geo_dem.txt")"
"$vola" convert "$geo_dem" "$tmp/dem.vol" --voxel-size 0.01 --allow-geographic -q || fail "the suggested convert line failed"
! grep -q "allow-geographic\|gdalwarp" <("$vola" info "$dem") || fail "a DEM in metres got the degrees advice"
"$vola" convert "$geo_dem" "$tmp/dem.vol" --voxel-size 0.01 2> "$tmp/err.txt" && fail "a DEM in degrees was voxelised"
grep -q "reproject the raster first (gdalwarp" "$tmp/err.txt" || fail "DEM in degrees: $(cat "$tmp/err.txt")"

# The wrong kind of file: a message naming the file and what to do, exit 1, no crash.
printf 'not a point file\n' > "$tmp/notes.md"
"$vola" info "$tmp/notes.md" 2> "$tmp/err.txt" && fail "info on a .md succeeded"
grep -q "notes.md: cannot tell the format" "$tmp/err.txt" || fail ".md: $(cat "$tmp/err.txt")"
# Text columns without names are not read, and info says so (pyntcloud's diamond.xyz has
# normals after x y z and no header line); named ones are listed.
printf '0.5 0 0.5 0 -1 0\n0 0.5 0.5 -1 0 0\n' > "$tmp/diamond.xyz"
"$vola" info "$tmp/diamond.xyz" | grep -q "each line holds 6 values: the 3 after x y z have no names and are not read" ||
  fail "info on a headerless 6-column .xyz does not say that 3 columns are not read"
printf '# x y z nx ny nz\n0.5 0 0.5 0 -1 0\n' > "$tmp/named.xyz"
"$vola" info "$tmp/named.xyz" | grep -q "^columns: *nx (f64) ny (f64) nz (f64)$" || fail "named .xyz columns: $("$vola" info "$tmp/named.xyz")"
"$vola" info "$tmp/named.xyz" | grep -q "have no names" && fail "info says named columns have no names"
# An OBJ of vertices alone (a point cloud exported from MeshLab or Blender) is points, not triangles.
printf 'v 1 2 3\nv 4 5 6\nv 7 8 9.5\n' > "$tmp/cloud.obj"
"$vola" info "$tmp/cloud.obj" | grep -q "^points: *3 (vertices without faces)$" || fail "vertex-only OBJ: $("$vola" info "$tmp/cloud.obj")"

# An Entwine Point Tiles folder made here from a shared LAZ file (a root node and a child
# behind a subtree file): info from the JSON alone, and --level 0 reads the root only.
ept=$tmp/ept
mkdir -p "$ept/ept-hierarchy" "$ept/ept-data"
cp "$data/laz/laspy_simple.laz" "$ept/ept-data/0-0-0-0.laz"
cp "$data/laz/laspy_simple.laz" "$ept/ept-data/1-0-1-1.laz"
printf '{"bounds": [0, 0, 0, 1, 1, 1], "dataType": "laszip", "hierarchyType": "json", "points": 2130, "schema": [], "srs": {"authority": "EPSG", "horizontal": "32610"}, "version": "1.0.0"}' > "$ept/ept.json"
printf '{"0-0-0-0": 1065, "1-0-1-1": -1}' > "$ept/ept-hierarchy/0-0-0-0.json"
printf '{"1-0-1-1": 1065}' > "$ept/ept-hierarchy/1-0-1-1.json"
"$vola" info "$ept/ept.json" > "$tmp/ept_info.txt" || fail "info on an EPT dataset failed"
grep -q "^points: *2130 in 2 nodes$" "$tmp/ept_info.txt" || fail "EPT info: $(cat "$tmp/ept_info.txt")"
grep -q "^depth 1 .* 1 nodes, 1065 points$" "$tmp/ept_info.txt" || fail "EPT info depths: $(cat "$tmp/ept_info.txt")"
"$vola" info --json --summary "$ept/ept.json" > "$tmp/ept.json" || fail "info --json --summary on an EPT dataset failed"
"${VOLA_PYTHON:-python3}" -c "
import json, sys
d = json.load(open(sys.argv[1]))
assert d['format'] == 'EPT' and d['points'] == 2130 and d['nodes'] == 2, d
assert d['hierarchy'] == [{'depth': 0, 'nodes': 1, 'points': 1065}, {'depth': 1, 'nodes': 1, 'points': 1065}], d
assert d['summary']['points_read'] == 2130 and d['crs']['epsg'] == 32610, d
" "$tmp/ept.json" || fail "EPT info --json: $(cat "$tmp/ept.json")"
"$vola" convert "$ept/ept.json" "$tmp/ept_root.vol" --voxel-size 1 --level 0 -q || fail "convert EPT --level 0"
"$vola" convert "$data/laz/laspy_simple.laz" "$tmp/simple.vol" --voxel-size 1 -q || fail "convert laspy_simple.laz"
"$vola" coords "$tmp/ept_root.vol" 2>/dev/null | cmp -s - <("$vola" coords "$tmp/simple.vol" 2>/dev/null) ||
  fail "EPT --level 0: not the root node's voxels"

# A .vol whose header holds what JSON cannot write: the reference writes PROJ's lat/lon of
# a centre it cannot place (inf) and a NaN bbox from a "nan" input line. They print as
# null; a dense file's levels count its words, as the text report does.
printf '0 0 0\n5 6 7\n' > "$tmp/two.xyz"
"$vola" convert "$tmp/two.xyz" "$tmp/two.dvol" --quantize toolkit --depth 2 --dense -q || fail "convert two.xyz dense"
"${VOLA_PYTHON:-python3}" -c "
import struct, sys
b = bytearray(open(sys.argv[1], 'rb').read())
b[16:40] = struct.pack('<3d', float('inf'), float('-inf'), float('nan'))  # lat, lon, min x
open(sys.argv[1], 'wb').write(b)
" "$tmp/two.dvol"
"$vola" info --json "$tmp/two.dvol" > "$tmp/two.json" || fail "info --json on a header with inf and NaN"
"${VOLA_PYTHON:-python3}" -c "
import json, sys
d = json.loads(open(sys.argv[1]).read(), parse_constant=lambda c: sys.exit('not JSON: ' + c))
assert d['lat'] is None and d['lon'] is None and d['bbox'][0] is None and d['bbox'][1] == 0, d
assert [l['blocks'] for l in d['levels']] == [1, 64], d['levels']
" "$tmp/two.json" || fail "info --json with inf and NaN: $(cat "$tmp/two.json")"
"$vola" info "$tmp/two.dvol" | grep -q "^ *1 *64 " || fail "info: dense level 1's words: $("$vola" info "$tmp/two.dvol")"

# E57: the scans as the XML states them, invalid points said, and a conversion of the points.
if [ -n "$e57_writer" ]; then
  "$e57_writer" --write-corpus "$tmp/e57" > /dev/null || fail "could not write the E57 files"
  "$vola" info "$tmp/e57/spherical_pose.e57" > "$tmp/e57_info.txt" || fail "info on an E57 file failed"
  grep -q "^points: *2 (and 2 the scanner marked as no return or invalid, left out)$" "$tmp/e57_info.txt" ||
    fail "E57 info: $(cat "$tmp/e57_info.txt")"
  grep -q "^scan: *'spherical': 4 records, pose: rotation (w x y z) 0.70710678" "$tmp/e57_info.txt" ||
    fail "E57 info scans: $(cat "$tmp/e57_info.txt")"
  "$vola" info --json --summary "$tmp/e57/two_scans.e57" > "$tmp/e57.json" || fail "info --json on an E57 file failed"
  "${VOLA_PYTHON:-python3}" -c "
import json, sys
d = json.load(open(sys.argv[1]))
assert d['format'] == 'e57' and d['points'] == 41, d
assert [s['records'] for s in d['e57']['scans']] == [40, 1], d
assert [c['name'] for c in d['dimensions']] == ['intensity'], d  # the only field both scans have
assert d['summary']['points_read'] == 41, d
" "$tmp/e57.json" || fail "E57 info --json: $(cat "$tmp/e57.json")"
  "$vola" convert "$tmp/e57/typed.e57" "$tmp/typed.vol" --voxel-size 0.5 -q || fail "convert an E57 file"
  "$vola" info "$tmp/typed.vol" | grep -q "red" || fail "E57 colours not kept: $("$vola" info "$tmp/typed.vol")"
fi
# A .vol with no CRS holds the reference's placeholder code: JSON says so, as the text does.
printf '0 0 0\n1 1 1\n' > "$tmp/nocrs.xyz"
"$vola" convert "$tmp/nocrs.xyz" "$tmp/nocrs.vol" --voxel-size 1 -q
"$vola" info --json "$tmp/nocrs.vol" | grep -q '"crs_placeholder": true' || fail "no CRS, yet crs_placeholder is not true"
"$vola" info --json "$tmp/nocrs.vol" | grep -q '"lat": null' || fail "no CRS, yet a latitude"
# A CRS with an EPSG code: the header's code is it.
"$vola" convert "$data/las/pdal_autzen-utm.las" "$tmp/utm.vol" --voxel-size 20 -q
"$vola" info --json "$tmp/utm.vol" > "$tmp/utm.json"
grep -q '"crs": 26910,' "$tmp/utm.json" && grep -q '"crs_placeholder": false' "$tmp/utm.json" ||
  fail "an EPSG code, yet not the header's crs: $(grep crs "$tmp/utm.json")"
# A WKT with no EPSG code (Oregon feet) leaves the placeholder 2000 in the header, which is
# EPSG:2000 (Anguilla 1957) to a script: "crs" is null there, and the WKT says what it is.
"$vola" convert "$data/las/pdal_autzen_trim.las" "$tmp/autzen.vol" --voxel-size 20 -q
"$vola" info --json "$tmp/autzen.vol" > "$tmp/autzen.json"
grep -q '"crs": null,' "$tmp/autzen.json" && grep -q '"crs_placeholder": true' "$tmp/autzen.json" &&
  grep -q '"crs_named": {"name": "NAD_1983_HARN_Lambert_Conformal_Conic"' "$tmp/autzen.json" &&
  ! grep -q '"lat": null' "$tmp/autzen.json" || fail "a WKT CRS without a code: $(grep -E 'crs|lat' "$tmp/autzen.json")"
# Points with a coordinate that is not finite are counted as left out for every reader, as
# convert counts them (only the PCD reader's were).
printf 'x y z\n1 2 3\nnan 2 3\n4 inf 6\n7 8 9\n' > "$tmp/nan.xyz"
"$vola" info "$tmp/nan.xyz" | grep -q "^points: *2 (and 2 with a coordinate that is not finite, left out)" ||
  fail "info of non-finite rows: $("$vola" info "$tmp/nan.xyz")"
"$vola" info --json "$tmp/nan.xyz" | grep -q '"points_not_finite": 2' || fail "info --json of non-finite rows"
# The header's scale and offset as the file holds them (9 digits cut 674521.9200134277).
"$vola" info "$data/las/pdal_sample_c.las" | grep -q "offset 674521.9200134277 1206740.0800170898 627.530029296875$" ||
  fail "sample_c offset: $("$vola" info "$data/las/pdal_sample_c.las" | grep scale)"
# A column without a value (append-bug's Deviation is no_data on every point): no mean of 0.
"$vola" convert "$data/laz/laspy_append-bug.laz" "$tmp/append.vol" --voxel-size 1 -q 2> /dev/null
"$vola" census "$tmp/append.vol" | grep -q "attribute Deviation: no value (4035 voxels without one)" ||
  fail "census of a column without a value: $("$vola" census "$tmp/append.vol" | grep -A1 Deviation)"
# Point files other than LAS give their points' bounds (--help promised them), and info
# doubts a CRS label the header's bounds cannot fit, as convert does.
"$vola" info "$data/pcd/pdal_autzen-utm.pcd" | grep -q "^bounds: *min (493994.87, 4877429.62, 123.93)" ||
  fail "PCD bounds: $("$vola" info "$data/pcd/pdal_autzen-utm.pcd")"
"$vola" info "$data/laz/pdal_lone-star-split-1.laz" 2> "$tmp/err" > "$tmp/out"
grep -q "a geocentric CRS: the CRS label is likely wrong" "$tmp/err" || fail "lone-star's label: $(cat "$tmp/err")"
# GDAL's WKT of its keys names the CRS "unnamed"; the code PROJ finds has a name.
grep -q "^crs: *WGS 84 (EPSG:4978), geocentric, metre$" "$tmp/out" || fail "lone-star's CRS line: $(grep crs "$tmp/out")"
# Class names from the file's LAS version: 12 is "Overlap Points" in LAS 1.0-1.3 (mvk-thin
# is 1.2), "Reserved" in 1.4's table, which named every file's classes.
"$vola" info "$data/las/pdal_mvk-thin.las" --summary | grep -Eq "^class: +12 Overlap Points +3702$" ||
  fail "LAS 1.2 class 12: $("$vola" info "$data/las/pdal_mvk-thin.las" --summary | grep class)"
echo "cli_info_json: OK ($checked LAS/LAZ files)"
