#!/usr/bin/env bash
# `vola export --raster` (GeoTIFF) and the world files of `--map` / `--slices`, end to end.
#
#   cli_raster.sh VOLA_BINARY SHARED_DIR [PYTHON]      ($VOLA_SHARED overrides SHARED_DIR)
#
# pdal_autzen_trim.las (Autzen, Oregon; feet, a Lambert conformal conic WKT) is voxelised
# at 3 ft; the rasters are read back with GDAL's Python bindings (PYTHON, default
# /usr/bin/python3, needs osgeo.gdal and numpy) and checked against what the test
# computes itself from the voxels (`vola export` to XYZ: centres, height, intensity,
# classification) and from the LAS points (`vola translate` to XYZ): CRS, geotransform,
# nodata, cropping, COG layout, and every cell's value, for dsm, dtm, intensity,
# density and count, cells of the voxel size and of two voxels, a grid tree without
# attributes (voxel faces), a toolkit tree (bbox frame) and a reference file with an
# EPSG code for its CRS. A --map PNG's world file must place every voxel column on its
# pixel as GDAL reads it.
# Exit status: 0 all good, 1 failures, 77 data or GDAL's Python missing (outside CI).
set -uo pipefail

if [[ $# -lt 2 || $# -gt 3 ]]; then
  echo "usage: $0 VOLA_BINARY SHARED_DIR [PYTHON]" >&2
  exit 2
fi
vola=$1
shared=${VOLA_SHARED:-$2}
python=${3:-/usr/bin/python3}
las=$shared/data/las/pdal_autzen_trim.las
golden=$shared/golden/crs29902_sparse/crs29902_sparse.vol  # a reference file: EPSG code only
keep_going=1
source "$(dirname "$0")/../lib/cli_test.sh"
[[ -f $las && -f $golden ]] || skip "$las or $golden is missing"
"$python" -c 'import numpy; from osgeo import gdal, osr' 2>/dev/null || skip "$python has no numpy or osgeo.gdal"
expect_error() {
  local part=$1
  shift
  if "$@" >"$tmp/out" 2>"$tmp/err"; then
    fail "'$*' succeeded, expected an error saying '$part'"
  elif ! grep -q -- "$part" "$tmp/err"; then
    fail "'$*' failed without saying '$part': $(cat "$tmp/err")"
  fi
}
run() { "$@" || fail "$*"; }

# A grid tree with LAS attributes (height, intensity, classification), one without,
# and a toolkit tree (frame from the bbox, no grid record).
run "$vola" convert "$las" "$tmp/a.vol" --voxel-size 3 -q
run "$vola" convert "$las" "$tmp/b.vol" --voxel-size 3 --no-attributes -q
run "$vola" convert "$las" "$tmp/t.vol" --depth 6 --no-attributes -q
for tree in a b t; do run "$vola" export "$tmp/$tree.vol" "$tmp/$tree.xyz" -q; done
run "$vola" translate "$las" "$tmp/points.xyz" -q
"$vola" info "$tmp/a.vol" >"$tmp/a.info" || fail "info a.vol"
sed -n 's/^crs wkt: *//p' "$tmp/a.info" >"$tmp/a.wkt"
[[ -s $tmp/a.wkt ]] || fail "a.vol has no CRS WKT"
# The grid's origin, as the file records it.
read -r ox oy oz < <(sed -n 's/^grid: .*origin (\([^,]*\), \([^,]*\), \([^)]*\)).*/\1 \2 \3/p' "$tmp/a.info")
[[ -n ${oz:-} ]] || fail "no grid origin in vola info"

for product in dsm dtm intensity density count; do
  run "$vola" export "$tmp/a.vol" "$tmp/a_$product.tif" --raster "$product" -q
done
run "$vola" export "$tmp/a.vol" "$tmp/a_dsm6.tif" --raster dsm --resolution 6 -q
run "$vola" export "$tmp/a.vol" "$tmp/a_count6.tif" --raster count --resolution 6 -q
run "$vola" export "$tmp/a.vol" "$tmp/a_intensity6.tif" --raster intensity --resolution 6 -q
run "$vola" export "$tmp/b.vol" "$tmp/b_dsm.tif" --raster dsm -q
# The products in any case, as GIS tools write them: the same file.
run "$vola" export "$tmp/b.vol" "$tmp/b_DSM.tif" --raster DSM -q
cmp -s "$tmp/b_dsm.tif" "$tmp/b_DSM.tif" || fail "--raster DSM wrote another file than --raster dsm"
run "$vola" export "$tmp/b.vol" "$tmp/b_dtm.tif" --raster dtm -q
run "$vola" export "$tmp/t.vol" "$tmp/t_dsm.tif" --raster dsm -q
run "$vola" export "$golden" "$tmp/g_count.tif" --raster count -q
run "$vola" export "$golden" "$tmp/g.xyz" -q
run "$vola" export "$tmp/a.vol" "$tmp/h.png" --map -q
[[ -f $tmp/h.pgw ]] || fail "--map wrote no h.pgw world file"
run "$vola" export "$tmp/a.vol" "$tmp/slices" --slices --depth 3 -q
[[ $(ls "$tmp/slices" | grep -c '\.pgw$') == 64 ]] || fail "--slices --depth 3: not 64 world files"

"$python" - "$tmp" "$ox" "$oy" "$oz" <<'PY' || fail "the rasters read back with GDAL differ from the voxels (above)"
import math
import sys

import numpy as np
from osgeo import gdal, osr

gdal.UseExceptions()
tmp = sys.argv[1]
origin = [float(v) for v in sys.argv[2:5]]
VOXEL, NODATA = 3.0, -9999.0
bad = []


def check(ok, what):
    if not ok:
        bad.append(what)
        print("  " + what, file=sys.stderr)


def columns(path):
    with open(path) as f:
        names = f.readline().lstrip("#").split()
    return names, np.loadtxt(path, comments="#", ndmin=2)


def read(name):
    ds = gdal.Open(f"{tmp}/{name}")
    band = ds.GetRasterBand(1)
    return ds, band, band.ReadAsArray().astype(np.float64)


def check_file(name, ds, band, wkt):
    check(ds.GetDriver().ShortName == "GTiff", f"{name}: driver {ds.GetDriver().ShortName}")
    check(ds.RasterCount == 1 and band.DataType == gdal.GDT_Float32, f"{name}: not one Float32 band")
    check(band.GetNoDataValue() == NODATA, f"{name}: nodata {band.GetNoDataValue()}")
    structure = ds.GetMetadata("IMAGE_STRUCTURE")
    check(structure.get("LAYOUT") == "COG", f"{name}: layout {structure.get('LAYOUT')}")
    check(structure.get("COMPRESSION") == "DEFLATE", f"{name}: compression {structure.get('COMPRESSION')}")
    srs = ds.GetSpatialRef()
    if wkt is None:
        check(srs is None, f"{name}: a CRS although the tree has none")
    else:
        check(srs is not None and same_crs(srs, wkt),
              f"{name}: CRS {srs.ExportToWkt() if srs else None} is not the file's")


def same_crs(srs, wkt):
    want = osr.SpatialReference()
    want.ImportFromWkt(wkt)
    if srs.IsSame(want):
        return True
    # GeoTIFF keys hold a datum by its EPSG code: the file's Esri name for it
    # (NAD83_High_Accuracy_Regional_Network) comes back as EPSG's. The same code, and
    # everything else the same, is the same CRS.
    code = want.GetAuthorityCode("DATUM")
    if not code or code != srs.GetAuthorityCode("DATUM"):
        return False
    renamed = osr.SpatialReference()
    renamed.ImportFromWkt(want.ExportToWkt().replace(f'DATUM["{want.GetAttrValue("DATUM")}"',
                                                     f'DATUM["{srs.GetAttrValue("DATUM")}"'))
    return bool(srs.IsSame(renamed))


def expect_grid(name, ds, cell, x0, y0, width, height):
    gt = ds.GetGeoTransform()
    want = (x0, cell, 0.0, y0, 0.0, -cell)
    check(all(math.isclose(a, b, rel_tol=0, abs_tol=1e-6) for a, b in zip(gt, want)),
          f"{name}: geotransform {gt}, want {want}")
    check((ds.RasterXSize, ds.RasterYSize) == (width, height),
          f"{name}: {ds.RasterXSize} x {ds.RasterYSize} cells, want {width} x {height}")


def per_cell(cols, rows, values, reduce, shape):
    out = np.full(shape, np.nan)
    flat = rows * shape[1] + cols
    order = np.argsort(flat, kind="stable")
    flat, values = flat[order], values[order]
    starts = np.flatnonzero(np.r_[True, flat[1:] != flat[:-1]])
    out.flat[flat[starts]] = reduce(values, starts)
    return out


def expect_values(name, got, want, rel=0.0):
    valid = ~np.isnan(want)
    check(np.array_equal(got == NODATA, ~valid),
          f"{name}: {int(np.sum((got == NODATA) != ~valid))} cells differ in having a value")
    expected = want[valid].astype(np.float32).astype(np.float64)
    diff = np.abs(got[valid] - expected)
    tolerance = rel * np.abs(expected)
    check(np.all(diff <= tolerance),
          f"{name}: {int(np.sum(diff > tolerance))} cells differ, largest by {diff.max() if diff.size else 0}")


wkt = open(f"{tmp}/a.wkt").read().strip()
names, a = columns(f"{tmp}/a.xyz")
col = {n: i for i, n in enumerate(names)}
x, y, z = a[:, 0], a[:, 1], a[:, 2]
# Voxel indices from the centres: origin + (i + 0.5) * voxel.
i = np.rint((x - origin[0]) / VOXEL - 0.5).astype(np.int64)
j = np.rint((y - origin[1]) / VOXEL - 0.5).astype(np.int64)
k = np.rint((z - origin[2]) / VOXEL - 0.5).astype(np.int64)
check(np.allclose(origin[0] + (i + 0.5) * VOXEL, x) and np.allclose(origin[2] + (k + 0.5) * VOXEL, z),
      "centres off the grid")


def grid_of(cell_i, cell_j):
    width = int(cell_i.max() - cell_i.min() + 1)
    height = int(cell_j.max() - cell_j.min() + 1)
    return cell_i - cell_i.min(), cell_j.max() - cell_j, (height, width)


cols, rows, shape = grid_of(i, j)
x0 = origin[0] + i.min() * VOXEL
y0 = origin[1] + (j.max() + 1) * VOXEL
height = a[:, col["height"]]
cls = a[:, col["classification"]]
ground = cls == 2
check(ground.any(), "no ground voxel in the survey")
vmax = lambda v, s: np.maximum.reduceat(v, s)
vmin = lambda v, s: np.minimum.reduceat(v, s)
vsum = lambda v, s: np.add.reduceat(v, s)

expected = {
    "dsm": per_cell(cols, rows, height, vmax, shape),
    "dtm": per_cell(cols[ground], rows[ground], height[ground], vmin, shape),
    "count": per_cell(cols, rows, np.ones_like(x), vsum, shape),
}
expected["density"] = expected["count"] / (VOXEL * VOXEL)
# Intensity: each voxel column's top voxel, averaged over the columns of the cell (one
# per cell here).
column = i * (1 << 32) + j
order = np.lexsort((k, column))
last = np.r_[column[order][1:] != column[order][:-1], True]
top = order[last]
mean = lambda v, s: vsum(v, s) / np.diff(np.r_[s, len(v)])
expected["intensity"] = per_cell(cols[top], rows[top], a[top, col["intensity"]], mean, shape)
for product, want in expected.items():
    name = f"a_{product}.tif"
    ds, band, got = read(name)
    check_file(name, ds, band, wkt)
    expect_grid(name, ds, VOXEL, x0, y0, shape[1], shape[0])
    expect_values(name, got, want, 1e-6 if product in ("intensity", "density") else 0.0)
    check(band.GetDescription() == product, f"{name}: band description {band.GetDescription()!r}")
ds, band, got = read("a_count.tif")
check(int(got[got != NODATA].sum()) == len(x), "count: the cells do not add up to the voxels")
print(f"dsm/dtm/intensity/density/count: {shape[1]} x {shape[0]} cells, {len(x)} voxels, "
      f"{int(np.sum(~np.isnan(expected['dtm'])))} cells with ground", file=sys.stderr)

# The DSM against the LAS points themselves: the top voxel's mean z lies within one
# voxel below the highest point of its column. Integer hundredths of a foot: the
# points' own precision, and exact cell arithmetic.
pnames, p = columns(f"{tmp}/points.xyz")
pi = (np.rint(p[:, 0] * 100).astype(np.int64) - round(origin[0] * 100)) // round(VOXEL * 100)
pj = (np.rint(p[:, 1] * 100).astype(np.int64) - round(origin[1] * 100)) // round(VOXEL * 100)
top_z = per_cell(pi - i.min(), j.max() - pj, p[:, 2], vmax, shape)
_, _, dsm = read("a_dsm.tif")
valid = dsm != NODATA
check(np.array_equal(valid, ~np.isnan(top_z)), "dsm: cells with a value are not the cells with LAS points")
check(np.all(dsm[valid] <= top_z[valid] + 1e-3) and np.all(dsm[valid] > top_z[valid] - VOXEL),
      "dsm: a value outside (highest point - voxel, highest point]")

# Cells of two voxels: voxel column i goes to cell floor((i + 0.5) * 3 / 6) = i // 2.
cols6, rows6, shape6 = grid_of(i // 2, j // 2)
intensity6 = per_cell(cols6[top], rows6[top], a[top, col["intensity"]], mean, shape6)
for product, want in (("dsm6", per_cell(cols6, rows6, height, vmax, shape6)),
                      ("count6", per_cell(cols6, rows6, np.ones_like(x), vsum, shape6)),
                      ("intensity6", intensity6)):
    name = f"a_{product}.tif"
    ds, band, got = read(name)
    check_file(name, ds, band, wkt)
    expect_grid(name, ds, 6.0, origin[0] + (i // 2).min() * 6, origin[1] + ((j // 2).max() + 1) * 6,
                shape6[1], shape6[0])
    expect_values(name, got, want, 1e-6 if product == "intensity6" else 0.0)

# Without attributes: voxel faces.
_, b = columns(f"{tmp}/b.xyz")
bi = np.rint((b[:, 0] - origin[0]) / VOXEL - 0.5).astype(np.int64)
bj = np.rint((b[:, 1] - origin[1]) / VOXEL - 0.5).astype(np.int64)
bk = np.rint((b[:, 2] - origin[2]) / VOXEL - 0.5).astype(np.int64)
bcols, brows, bshape = grid_of(bi, bj)
for name, want in (("b_dsm.tif", per_cell(bcols, brows, origin[2] + (bk + 1) * VOXEL, vmax, bshape)),
                   ("b_dtm.tif", per_cell(bcols, brows, origin[2] + bk * VOXEL, vmin, bshape))):
    ds, band, got = read(name)
    check_file(name, ds, band, wkt)
    expect_grid(name, ds, VOXEL, origin[0] + bi.min() * VOXEL, origin[1] + (bj.max() + 1) * VOXEL, bshape[1], bshape[0])
    expect_values(name, got, want)

# Toolkit tree: no recorded grid; the frame comes from the bbox. Every voxel centre must
# fall mid-cell, and the cell's value be its column's highest centre + half a voxel.
_, t = columns(f"{tmp}/t.xyz")
ds, band, got = read("t_dsm.tif")
check_file("t_dsm.tif", ds, band, wkt)
gt = ds.GetGeoTransform()
step = gt[1]
check(gt[5] == -step and gt[2] == 0 and gt[4] == 0, f"t_dsm.tif: geotransform {gt}")
fc = (t[:, 0] - gt[0]) / step
fr = (gt[3] - t[:, 1]) / step
check(np.all(np.abs(fc - np.floor(fc) - 0.5) < 1e-6) and np.all(np.abs(fr - np.floor(fr) - 0.5) < 1e-6),
      "t_dsm.tif: voxel centres are not mid-cell")
tc, tr = np.floor(fc).astype(np.int64), np.floor(fr).astype(np.int64)
check(tc.min() == 0 and tr.min() == 0 and tc.max() == ds.RasterXSize - 1 and tr.max() == ds.RasterYSize - 1,
      "t_dsm.tif: not cropped to the voxels")
want = per_cell(tc, tr, t[:, 2] + step / 2, vmax, (ds.RasterYSize, ds.RasterXSize))
valid = ~np.isnan(want)
check(np.array_equal(got != NODATA, valid) and np.allclose(got[valid], want[valid], rtol=0, atol=1e-4),
      "t_dsm.tif: values are not the columns' top faces")

# A reference file: toolkit grid from the header bbox, CRS as an EPSG code only.
_, g = columns(f"{tmp}/g.xyz")
ds, band, got = read("g_count.tif")
srs = ds.GetSpatialRef()
check(srs is not None and srs.GetAuthorityCode(None) == "29902", "g_count.tif: CRS is not EPSG:29902")
gt = ds.GetGeoTransform()
gc = np.floor((g[:, 0] - gt[0]) / gt[1]).astype(np.int64)
gr = np.floor((g[:, 1] - gt[3]) / gt[5]).astype(np.int64)
want = per_cell(gc, gr, np.ones(len(g)), vsum, (ds.RasterYSize, ds.RasterXSize))
expect_values("g_count.tif", got, want)

# --map: the world file places voxel column (i, j) on the pixel GDAL computes for its
# centre, whose value is the column's highest k + 1.
png = gdal.Open(f"{tmp}/h.png")
gt = png.GetGeoTransform()
want = (origin[0], VOXEL, 0.0, origin[1] + 1024 * VOXEL, 0.0, -VOXEL)
check(all(math.isclose(g, w, abs_tol=1e-9) for g, w in zip(gt, want)),
      f"h.png: GDAL reads geotransform {gt} from h.pgw, want {want}")
image = png.GetRasterBand(1).ReadAsArray().astype(np.int64)
pc = np.floor((x - gt[0]) / gt[1]).astype(np.int64)
pr = np.floor((y - gt[3]) / gt[5]).astype(np.int64)
top_k = per_cell(pc, pr, k + 1.0, vmax, image.shape)
placed = ~np.isnan(top_k)
check(np.array_equal(image[placed], top_k[placed].astype(np.int64)) and np.all(image[~placed] == 0),
      "h.png: the world file does not put the columns' tops on their pixels")
with open(f"{tmp}/slices/depth3-000.pgw") as f:
    first = [float(v) for v in f.read().split()]
check(len(first) == 6 and first[0] == 48.0 and first[3] == -48.0 and first[4] == origin[0] + 24.0,
      f"slices: depth3-000.pgw is {first}")
sys.exit(1 if bad else 0)
PY

# Refusals that name the way out.
expect_error "--raster dsm" "$vola" export "$tmp/a.vol" "$tmp/m.tif" --map
expect_error "name it .png" "$vola" export "$tmp/a.vol" "$tmp/m.jpg" --occupancy-above 3
expect_error "needs --raster" "$vola" export "$tmp/a.vol" "$tmp/m.tif"
expect_error "writes a GeoTIFF: name the output .tif, not $tmp/m.png" "$vola" export "$tmp/a.vol" "$tmp/m.png" --raster dsm
expect_error "finer than the voxels" "$vola" export "$tmp/a.vol" "$tmp/m.tif" --raster dsm --resolution 2
expect_error "no intensity column" "$vola" export "$tmp/b.vol" "$tmp/m.tif" --raster intensity
expect_error "applies to --raster" "$vola" export "$tmp/a.vol" "$tmp/m.las" --resolution 6
expect_error "give one" "$vola" export "$tmp/a.vol" "$tmp/m.tif" --raster dsm --map
[[ ! -e $tmp/m.tif && ! -e $tmp/m.png ]] || fail "a refused export left a file"
ls "$tmp" | grep -q '\.part$' && fail "a temporary .part file was left"
# GDAL writes in memory only: no .aux.xml or overview files beside the output.
ls "$tmp" | grep -q -e '\.aux\.xml$' -e '\.ovr$' && fail "GDAL left side files: $(ls "$tmp" | grep -e aux -e ovr)"

# A DEM at its own cell size comes back on its own cells: same geotransform, the same
# heights where the source has data (the default origin follows the raster's lattice,
# not multiples of the voxel size, which moved this one 20 m west).
dem=$shared/data/dem/pdal_gdal_int16_epsg26711.tif
if [[ -f $dem ]]; then
  "$vola" convert "$dem" "$tmp/dem.vol" --voxel-size 60 --dem-surface-only -q || fail "convert the DEM"
  "$vola" export "$tmp/dem.vol" "$tmp/dem.tif" --raster dsm -q || fail "export the DEM's DSM"
  "$python" - "$dem" "$tmp/dem.tif" <<'PY' || fail "the DEM's DSM is not on the DEM's cells"
import sys
import numpy as np
from osgeo import gdal
src, out = gdal.Open(sys.argv[1]), gdal.Open(sys.argv[2])
assert src.GetGeoTransform() == out.GetGeoTransform(), (src.GetGeoTransform(), out.GetGeoTransform())
a = src.GetRasterBand(1).ReadAsArray().astype(float)
b = out.GetRasterBand(1).ReadAsArray().astype(float)
assert a.shape == b.shape, (a.shape, b.shape)
# The DSM holds the top of each cell's voxel: within one 60-unit voxel above the height.
ok = b != out.GetRasterBand(1).GetNoDataValue()
assert ok.all(), ok.sum()
assert ((b - a >= 0) & (b - a <= 60)).all(), np.abs(b - a).max()
PY
  # At voxels half the cell, each cell covers its 2 x 2 voxel columns (only the one under
  # its centre had a column: three in four were nodata), each at the cell's height.
  "$vola" convert "$dem" "$tmp/dem30.vol" --voxel-size 30 --dem-surface-only -q || fail "convert the DEM at 30"
  "$vola" export "$tmp/dem30.vol" "$tmp/dem30.tif" --raster dsm -q || fail "export the DEM's DSM at 30"
  "$python" - "$dem" "$tmp/dem30.tif" <<'PY' || fail "the DEM's cells do not cover their voxels at half their size"
import sys
import numpy as np
from osgeo import gdal
src, out = gdal.Open(sys.argv[1]), gdal.Open(sys.argv[2])
g, h = src.GetGeoTransform(), out.GetGeoTransform()
assert (h[0], h[3], h[1], h[5]) == (g[0], g[3], g[1] / 2, g[5] / 2), (g, h)
a = src.GetRasterBand(1).ReadAsArray().astype(float)
b = out.GetRasterBand(1).ReadAsArray().astype(float)
assert b.shape == (2 * a.shape[0], 2 * a.shape[1]), (a.shape, b.shape)
assert (b != out.GetRasterBand(1).GetNoDataValue()).all(), "nodata cells"
up = np.repeat(np.repeat(a, 2, 0), 2, 1)
assert ((b - up >= 0) & (b - up <= 30)).all(), np.abs(b - up).max()
PY
else
  fail "$dem is missing"
fi

if ((failures)); then
  echo "$failures failure(s)" >&2
  exit 1
fi
echo "cli_raster: all good"
