#!/usr/bin/env bash
# vola tile end to end on the Autzen survey: the same bytes for 1 and 2 threads, a tiny
# memory budget and (with mpirun) 3 ranks; the index; queries through the index (get,
# render, plan) open only the tiles they need; errors for mixed CRSs, bad options and
# inputs that are not regular files.
# Usage: cli_tile.sh VOLA SHARED_DATA_DIR   ($VOLA_SHARED/data, when set, wins)
set -euo pipefail
vola=$1 data=${VOLA_SHARED:+$VOLA_SHARED/data}
data=${data:-$2}
source "$(dirname "$0")/../lib/cli_test.sh"
las=$data/las/pdal_autzen_trim.las
[ -f "$las" ] || skip "no $las (set VOLA_SHARED)"

# Tiles of 256 ft at depth 4: voxels of 1 ft, 5 x 3 tiles over the survey.
"$vola" tile "$las" --tile-size 256 --depth 4 -o "$tmp/one" --threads 1 > "$tmp/one.txt"
grep -q '^tiles: ' "$tmp/one.txt" || fail "no summary: $(cat "$tmp/one.txt")"
"$vola" tile "$las" --tile-size 256 --depth 4 -o "$tmp/two" --threads 2 --memory 1M --chunk-points 5000 -q
diff -r "$tmp/one" "$tmp/two" > /dev/null || fail "2 threads, 1 MiB and small chunks give other bytes than 1 thread"
# The tiles carry the survey's attribute columns, overviews too; --no-attributes drops them.
grep -q '^attributes: .*classification' "$tmp/one.txt" || fail "summary names no attributes: $(cat "$tmp/one.txt")"
some_tile=$(ls "$tmp/one/.generation-1/"tile_*.vol | head -1)
some_overview=$(ls "$tmp/one/.generation-1/overviews/L1/"*.vol | head -1)
for f in "$some_tile" "$some_overview"; do
  "$vola" info "$f" | grep -q '^attribute: *intensity (u16, mean' || fail "$f has no intensity column"
done
# The user's own files in OUTDIR stay, even in a folder named overviews (every file there
# was deleted as if it were an overview of the older layout).
mkdir -p "$tmp/bare/overviews"
echo mine > "$tmp/bare/overviews/notes.txt"
echo mine > "$tmp/bare/notes.txt"
"$vola" tile "$las" --tile-size 256 --depth 4 -o "$tmp/bare" --no-attributes --no-overviews > "$tmp/bare.txt"
[ -f "$tmp/bare/overviews/notes.txt" ] && [ -f "$tmp/bare/notes.txt" ] || fail "vola tile deleted the user's files in OUTDIR"
[ -e "$tmp/bare/.spill" ] && fail "the spill folder is left behind: $(ls -a "$tmp/bare/.spill")"
grep -q '^attributes: *none' "$tmp/bare.txt" || fail "--no-attributes summary: $(cat "$tmp/bare.txt")"
"$vola" info "$(ls "$tmp/bare/.generation-1/"tile_*.vol | head -1)" | grep -q '^attribute:' && fail "--no-attributes tile has columns"

index=$tmp/one/index.geojson
python3 - "$index" "$las" <<'PY' || fail "index check"
import json, sys
index = json.load(open(sys.argv[1]))
v = index["vola"]
assert v["tiles"] == len(index["features"]) > 4, v["tiles"]
assert v["points_in"] == 110000 and v["points_outside"] == 0, v
assert sum(f["properties"]["points"] for f in index["features"]) == 110000
assert v["crs_wkt"], "the survey's WKT travels into the index"
assert "crs" not in index, "RFC 7946: no crs member, coordinates are WGS84"
for f in index["features"]:
    ring = f["geometry"]["coordinates"][0]
    assert ring[0] == ring[-1] and len(ring) > 5, "a closed ring, edges densified"
    for lon, lat in ring:  # Autzen, Oregon
        assert -123.2 < lon < -122.9 and 43.9 < lat < 44.2, (lon, lat)
assert len(v["overviews"]) >= 2 and v["overviews"][-1]["level"] >= 1
PY
# vola info on the tile set (its folder or its index): the index's own figures (it said
# "--format: ... say which", an option info does not have, and "File is actually a directory").
"$vola" info "$tmp/one" --json > "$tmp/info.json" || fail "vola info on the tile folder failed"
"$vola" info "$index" > "$tmp/info.txt" 2> "$tmp/info_err.txt" || fail "vola info on index.geojson failed"
[ ! -s "$tmp/info_err.txt" ] || fail "info of a whole tile set warned: $(cat "$tmp/info_err.txt")"
grep -q "^files:       all [0-9]* present, of the sizes listed$" "$tmp/info.txt" || fail "info's files line: $(cat "$tmp/info.txt")"
# The GeoPackage beside the index names the same set.
"$vola" info "$tmp/one/index.gpkg" > "$tmp/info_gpkg.txt" || fail "vola info on index.gpkg failed"
cmp -s <(sed 1d "$tmp/info.txt") <(sed 1d "$tmp/info_gpkg.txt") || fail "info of index.gpkg differs from index.geojson's"
# A tile deleted, another cut short since vola tile wrote them: info reads the index, and
# said the set was whole.
cp -r "$tmp/one" "$tmp/damaged"
damaged_tiles=($(ls "$tmp/damaged/.generation-1/"tile_*.vol))
rm "${damaged_tiles[0]}"
head -c 100 "${damaged_tiles[1]}" > "$tmp/short.vol" && mv "$tmp/short.vol" "${damaged_tiles[1]}"
"$vola" info "$tmp/damaged" --json > "$tmp/damaged.json" 2> "$tmp/err.txt" || fail "info of a damaged set failed"
grep -q "lists 1 of its [0-9]* files that are not there (first: .generation-1/$(basename "${damaged_tiles[0]}"))" "$tmp/err.txt" ||
  fail "a deleted tile: $(cat "$tmp/err.txt")"
grep -q "1 tiles are not of the size the index lists (first: .generation-1/$(basename "${damaged_tiles[1]}"))" "$tmp/err.txt" ||
  fail "a short tile: $(cat "$tmp/err.txt")"
python3 -c "
import json, sys
info = json.load(open(sys.argv[1]))
assert len(info['missing_files']) == 1 and len(info['resized_files']) == 1, info
" "$tmp/damaged.json" || fail "info --json of a damaged set"
python3 - "$index" "$tmp/info.json" "$tmp/info.txt" <<'PY' || fail "vola info of the tile set"
import json, sys
v = json.load(open(sys.argv[1]))["vola"]
info = json.load(open(sys.argv[2]))
text = open(sys.argv[3]).read()
assert info["kind"] == "tile index" and info["tiles"] == v["tiles"], info
assert info["points"] == 110000 and info["grid"]["depth"] == 4 and info["grid"]["tile_size"] == 256, info
assert "classification" in info["attributes"] and info["crs"]["unit"] == "foot", info
assert [o["level"] for o in info["overviews"]] == sorted({o["level"] for o in v["overviews"]}), info["overviews"]
assert f"tiles:       {v['tiles']}," in text and "crs:         NAD_1983_HARN_Lambert_Conformal_Conic" in text, text
PY
# render and plan read the tiles an index names: an output over one of them is refused.
a_tile=$(ls "$tmp/one/.generation-1/"tile_*.vol | head -1)
cp "$a_tile" "$tmp/tile_before.vol"
"$vola" render "$index" -o "$a_tile" --size 32x24 -q 2> "$tmp/err.txt" && fail "render wrote over a tile it reads"
grep -q "is the input: vola render writes new files" "$tmp/err.txt" || fail "render over a tile: $(cat "$tmp/err.txt")"
cmp -s "$a_tile" "$tmp/tile_before.vol" || fail "render replaced a tile"
"$vola" info "$tmp/bare/overviews" 2> "$tmp/err.txt" && fail "info on a folder without an index succeeded"
grep -q "overviews is a folder with no index.geojson" "$tmp/err.txt" || fail "info on a folder: $(cat "$tmp/err.txt")"

# As QGIS opens them, through OGR: the GeoJSON in WGS84, the GeoPackage in the survey's
# own CRS (a WKT with no EPSG code), both with the tiles' extent.
command -v ogrinfo > /dev/null || skip "ogrinfo not installed (apt-get install gdal-bin)"
ogrinfo -ro -so -al "$index" > "$tmp/ogr_json.txt" || fail "ogrinfo cannot open the index"
ogrinfo -ro -so -al "$tmp/one/index.gpkg" > "$tmp/ogr_gpkg.txt" || fail "ogrinfo cannot open index.gpkg"
"${VOLA_PYTHON:-python3}" - "$index" "$tmp/ogr_json.txt" "$tmp/ogr_gpkg.txt" <<'PY' || fail "ogrinfo CRS and extent"
import json, re, sys
import pyproj
index = json.load(open(sys.argv[1]))
v, ogr_json, ogr_gpkg = index["vola"], open(sys.argv[2]).read(), open(sys.argv[3]).read()
def extent(text):
    m = re.search(r"Extent: \(([-\d.]+), ([-\d.]+)\) - \(([-\d.]+), ([-\d.]+)\)", text)
    return [float(g) for g in m.groups()]
def count(text):
    return int(re.search(r"Feature Count: (\d+)", text).group(1))
assert count(ogr_json) == count(ogr_gpkg) == v["tiles"], (count(ogr_json), count(ogr_gpkg))
assert 'GEOGCRS["WGS 84"' in ogr_json, ogr_json
assert 'PROJCRS["NAD_1983_HARN_Lambert_Conformal_Conic"' in ogr_gpkg, ogr_gpkg
size, (ox, oy, _) = v["tile_size"], v["origin"]
tiles = [f["properties"]["tile"] for f in index["features"]]
want = [ox + min(t[0] for t in tiles) * size, oy + min(t[1] for t in tiles) * size,
        ox + (max(t[0] for t in tiles) + 1) * size, oy + (max(t[1] for t in tiles) + 1) * size]
got = extent(ogr_gpkg)
assert all(abs(a - b) < 1e-6 for a, b in zip(got, want)), (got, want)
# The WGS84 extent holds the native extent's corners as pyproj moves them.
to_wgs84 = pyproj.Transformer.from_crs(pyproj.CRS.from_wkt(v["crs_wkt"]), "EPSG:4326", always_xy=True)
lon0, lat0, lon1, lat1 = extent(ogr_json)
for x in (want[0], want[2]):
    for y in (want[1], want[3]):
        lon, lat = to_wgs84.transform(x, y)
        assert lon0 - 1e-6 <= lon <= lon1 + 1e-6 and lat0 - 1e-6 <= lat <= lat1 + 1e-6, (lon, lat, extent(ogr_json))
PY
ls "$tmp/one/.generation-1/overviews/L1/"*.vol > /dev/null || fail "no overview files"

# get: the centre of a voxel of one tile, through the index, opens that tile only.
first_tile=$(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['features'][0]['properties']['file'])" "$index")
read -r x y z < <("$vola" coords "$tmp/one/$first_tile" 2> /dev/null | sed -n 2p)
"$vola" get "$index" "$x" "$y" "$z" > "$tmp/get.txt"
grep -q "^tile .*: $first_tile" "$tmp/get.txt" || fail "get: $(cat "$tmp/get.txt")"
grep -q ": occupied$" "$tmp/get.txt" || fail "get: $(cat "$tmp/get.txt")"
"$vola" get "$index" 0 0 0 | grep -q "not in the set" || fail "get far away"

# A tile size far below the point spacing (one tile per point: 440,000 files and 2 GB from
# this 3.7 MB survey) is refused before a tile is written.
"$vola" tile "$las" --tile-size 0.01 --depth 5 -o "$tmp/tiny" --max-tiles 50000 2> "$tmp/err.txt" \
  && fail "110,000 tiles of 0.01 ft were written"
grep -q -- "--max-tiles: the 110000 points fall into 110000 tiles of 0.01" "$tmp/err.txt" || fail "error: $(cat "$tmp/err.txt")"
[ -z "$(find "$tmp/tiny" -name '*.vol' 2> /dev/null)" ] || fail "tiles were written before the refusal"

# Filters that keep no point (a crop polygon in longitude/latitude over a survey in feet)
# wrote an empty tile set with exit 0.
echo '{"type": "Polygon", "coordinates": [[[-123.0725, 44.05], [-123.07, 44.05], [-123.07, 44.0515], [-123.0725, 44.05]]]}' \
  > "$tmp/lonlat.geojson"
"$vola" tile "$las" --tile-size 256 --depth 4 -o "$tmp/none" --crop-polygon "$tmp/lonlat.geojson" 2> "$tmp/err.txt" \
  && fail "an empty tile set was written"
grep -q "none of the inputs' 110000 points is left to tile" "$tmp/err.txt" || fail "error: $(cat "$tmp/err.txt")"

# render: rays cross the tiles; the image has hits.
"$vola" render "$index" --size 160x120 -o "$tmp/view.png" > "$tmp/render.txt"
grep -Eq "^view.png|rays hit" "$tmp/render.txt" || fail "render: $(cat "$tmp/render.txt")"
hits=$(sed -n 's/.*: \([0-9]*\) of 19200 rays hit/\1/p' "$tmp/render.txt")
[ "${hits:-0}" -gt 1000 ] || fail "render hit only ${hits:-0} of 19200 rays"
[ -s "$tmp/view.png" ] && [ -s "$tmp/view_depth.png" ] || fail "render wrote no images"
# The tiles' colours and depths are the survey's: the same image as one file on the same
# grid (tile set renders were grey, their red/green/blue columns ignored).
origin=$(python3 -c "
import json, sys
v = json.load(open(sys.argv[1]))['vola']
tiles = [f['properties']['tile'] for f in json.load(open(sys.argv[1]))['features']]
print(*(v['origin'][a] + min(t[a] for t in tiles) * v['tile_size'] for a in range(3)))" "$index")
# shellcheck disable=SC2086  # three numbers
"$vola" convert "$las" "$tmp/whole.vol" --voxel-size 1 --origin $origin -q
camera=(--camera 636800 848500 2500 637500 849700 450 --size 200x150 -q)
"$vola" render "$index" "${camera[@]}" -o "$tmp/tiles_view.png"
"$vola" render "$tmp/whole.vol" "${camera[@]}" -o "$tmp/whole_view.png"
cmp -s "$tmp/tiles_view.png" "$tmp/whole_view.png" || fail "the tile set renders other colours than the survey as one file"
cmp -s "$tmp/tiles_view_depth.png" "$tmp/whole_view_depth.png" || fail "the tile set renders other depths than one file"

# plan: 150 ft above the ground, across two tiles; opens only the tiles around the path.
"$vola" plan "$index" --from 636100 849000 560 --to 636400 849100 560 --radius 2 --margin 20 -o "$tmp/path.csv" \
  > "$tmp/plan.txt"
grep -Eq "planning over [0-9]+ of [0-9]+ tiles" "$tmp/plan.txt" || fail "plan: $(cat "$tmp/plan.txt")"
opened=$(sed -n 's/planning over \([0-9]*\) of \([0-9]*\) tiles.*/\1/p' "$tmp/plan.txt")
total=$(sed -n 's/planning over \([0-9]*\) of \([0-9]*\) tiles.*/\2/p' "$tmp/plan.txt")
[ "$opened" -lt "$total" ] || fail "plan opened $opened of $total tiles"
[ "$(wc -l < "$tmp/path.csv")" -ge 3 ] || fail "plan wrote no path"

# Errors: inputs that disagree on the CRS; a bad budget; no input.
if "$vola" tile "$las" "$data/las/pdal_autzen-utm.las" --tile-size 256 --depth 4 -o "$tmp/mixed" 2> "$tmp/err.txt"; then
  fail "mixed CRSs accepted"
fi
grep -q "disagree on the CRS" "$tmp/err.txt" || fail "mixed CRS message: $(cat "$tmp/err.txt")"
# Different CRSs (feet WKT, EPSG:2991 metres) tile together when reprojected into one, the
# same bytes for 1 and 2 threads; an input with no CRS cannot be reprojected.
for t in 1 2; do
  "$vola" tile "$las" "$data/las/pdal_autzen-bmx-2010.las" --target-crs EPSG:32610 --tile-size 200 --depth 4 \
    -o "$tmp/utm$t" --threads $t -q 2> "$tmp/err.txt" || fail "--target-crs refused: $(cat "$tmp/err.txt")"
done
diff -r "$tmp/utm1" "$tmp/utm2" > /dev/null || fail "--target-crs: 2 threads give other bytes than 1"
python3 -c "import json, sys; v = json.load(open(sys.argv[1]))['vola']; assert v['epsg'] == 32610, v['epsg']" \
  "$tmp/utm1/index.geojson" || fail "the reprojected index does not state EPSG:32610"
"$vola" tile "$data/las/pdal_1.2-with-color.las" --target-crs 32610 --tile-size 200 --depth 4 -o "$tmp/nocrs" \
  2> "$tmp/err.txt" && fail "an input with no CRS was reprojected"
grep -q "states no CRS to reproject from" "$tmp/err.txt" || fail "no-CRS message: $(cat "$tmp/err.txt")"
# Per-point filters chunk by chunk: the ground tiles hold exactly the voxels of converting
# the ground points on the same grid; neighbourhood filters are refused with the way out.
"$vola" tile "$las" --tile-size 256 --depth 4 -o "$tmp/ground" --where "Classification == 2" --chunk-points 7000 -q
"$vola" convert "$las" "$tmp/ground.vol" --voxel-size 1 --origin 0 0 0 --where "Classification == 2" -q
for t in "$tmp"/ground/.generation-1/tile_*.vol; do "$vola" coords "$t"; done | grep -v '^#' | sort > "$tmp/tiled.txt"
"$vola" coords "$tmp/ground.vol" | grep -v '^#' | sort > "$tmp/converted.txt"
[ -s "$tmp/tiled.txt" ] && cmp -s "$tmp/tiled.txt" "$tmp/converted.txt" || fail "--where: tiles differ from convert --where"
"$vola" tile "$las" --tile-size 256 --depth 4 -o "$tmp/smrf" --filter smrf 2> "$tmp/err.txt" && fail "smrf in tile accepted"
grep -q "needs each point's neighbours.*vola translate" "$tmp/err.txt" || fail "smrf message: $(cat "$tmp/err.txt")"
# Points on voxel faces go where vola convert puts them (floor((p - origin) / voxel)): with
# the voxel's inverse, which rounds for 0.4 m, 35 voxels of this real file differed.
face=$data/laz/pdal_faceraster_numerical_imprecision.laz
"$vola" tile "$face" --tile-size 6.4 --depth 2 --origin 686976 6232960 0 -o "$tmp/face" --no-attributes -q
"$vola" convert "$face" "$tmp/face.vol" --voxel-size 0.4 --origin 686976 6232960 0 --no-attributes -q
for t in "$tmp"/face/.generation-1/tile_*.vol; do "$vola" coords "$t"; done | grep -v '^#' |
  awk '{ printf "%.3f %.3f %.3f\n", $1, $2, $3 }' | sort > "$tmp/face_tiles.txt"
"$vola" coords "$tmp/face.vol" | grep -v '^#' | awk '{ printf "%.3f %.3f %.3f\n", $1, $2, $3 }' | sort > "$tmp/face_convert.txt"
[ "$(wc -l < "$tmp/face_tiles.txt")" -gt 2000 ] && cmp -s "$tmp/face_tiles.txt" "$tmp/face_convert.txt" ||
  fail "points on voxel faces: tiles and convert differ ($(diff "$tmp/face_tiles.txt" "$tmp/face_convert.txt" | wc -l) lines)"
# An input of no point is refused (the index it wrote was refused by every reader), a
# point that cannot be tiled is warned of even with -q, and a tile set refuses a query
# at NaN as a .vol does (it answered "voxel 0 0 0: empty").
printf 'x y z\n' > "$tmp/none.xyz"
"$vola" tile "$tmp/none.xyz" --tile-size 256 --depth 4 -o "$tmp/none" -q 2> "$tmp/err.txt" && fail "an empty input was tiled"
grep -q "the inputs hold no point" "$tmp/err.txt" || fail "empty input: $(cat "$tmp/err.txt")"
printf 'x y z\n1 2 3\nnan 2 3\n4 5 6\n' > "$tmp/some.xyz"
"$vola" tile "$tmp/some.xyz" --tile-size 256 --depth 4 -o "$tmp/some" -q 2> "$tmp/err.txt" || fail "tile some.xyz"
grep -q "1 of the 3 points are not tiled" "$tmp/err.txt" || fail "dropped point not warned of with -q: $(cat "$tmp/err.txt")"
"$vola" get "$tmp/some/index.geojson" nan 2 3 2> "$tmp/err.txt" && fail "vola get answered a NaN point"
grep -q "is not finite or lies beyond" "$tmp/err.txt" || fail "get nan: $(cat "$tmp/err.txt")"
# --assign-crs relabels a file that states another CRS, with --target-crs too: said.
"$vola" tile "$las" --assign-crs EPSG:26910 --target-crs EPSG:32610 --tile-size 256 --depth 3 -o "$tmp/relabel" -q \
  2> "$tmp/err.txt" || fail "tile --assign-crs --target-crs"
grep -q "relabels its coordinates without moving them, and --target-crs reprojects them from that label" "$tmp/err.txt" ||
  fail "relabel with --target-crs not warned of: $(cat "$tmp/err.txt")"
# A folder another run is writing is refused (two runs into one folder both exited 0 and
# left a set mixing their tiles): the lock held here as a running vola tile holds it.
mkdir -p "$tmp/locked"
if (flock -x 9 && "$vola" tile "$las" --tile-size 256 --depth 3 -o "$tmp/locked" -q 2> "$tmp/err.txt") 9> "$tmp/locked/.lock"; then
  fail "a tile set folder another run holds was written"
fi
grep -q "another vola tile is writing this tile set" "$tmp/err.txt" || fail "held folder: $(cat "$tmp/err.txt")"
"$vola" tile "$las" --tile-size 256 --depth 3 -o "$tmp/locked" -q || fail "the folder, released, was refused"
# A crop over inputs in different CRSs runs in each one's own CRS (a whole file was dropped
# without a word): said.
"$vola" tile "$data/las/pdal_autzen-utm.las" "$data/las/pdal_autzen_pf1.las" --target-crs EPSG:26910 \
  --crop 636000 4870000 640000 4890000 --tile-size 256 --depth 3 -o "$tmp/mixed_crop" -q 2> "$tmp/err.txt" || true
grep -q "the crop runs in each input's own CRS" "$tmp/err.txt" || fail "a crop over two CRSs: $(cat "$tmp/err.txt")"
# --memory bounds buffers, not a tile being built: a tile that may need more is said.
"$vola" tile "$las" --tile-size 4000 --depth 6 --memory 1M -o "$tmp/big_tile" --no-overviews -q 2> "$tmp/err.txt" ||
  fail "tile under 1M"
grep -q "the largest tile holds 110000 points: building it may take up to .* MiB beyond --memory's 1 MiB" "$tmp/err.txt" ||
  fail "a tile beyond --memory not said: $(cat "$tmp/err.txt")"
# A field the file has but tile does not read: named as such, with what to do (the points
# were said to have no such dimension).
"$vola" tile "$las" --tile-size 256 --depth 4 -o "$tmp/first" --where "ReturnNumber == 1" 2> "$tmp/err.txt" &&
  fail "--where on a field tile does not read was accepted"
grep -q "vola tile's filters see x, y, z and the columns it keeps (.*), not 'ReturnNumber'.*vola translate" "$tmp/err.txt" ||
  fail "ReturnNumber message: $(cat "$tmp/err.txt")"
# Degrees: tiles in a geographic CRS are refused unless reprojected or forced.
geo=$data/las/pdal_epsg_4326.las
"$vola" tile "$geo" --tile-size 0.01 --depth 4 -o "$tmp/degrees" 2> "$tmp/err.txt" && fail "tiles in degrees accepted"
grep -q "^vola: .*pdal_epsg_4326.las is in WGS 84, a geographic CRS.*--allow-geographic" "$tmp/err.txt" ||
  fail "degrees message: $(cat "$tmp/err.txt")"
"$vola" tile "$geo" --tile-size 0.01 --depth 4 -o "$tmp/degrees" --allow-geographic -q || fail "--allow-geographic refused"
"$vola" tile "$geo" --tile-size 200 --depth 4 -o "$tmp/degrees_utm" --target-crs 32615 -q || fail "degrees to UTM refused"
# A geocentric WGS 84 label on UTM metres (a RiSCAN export: x = 515393, ~4900 km from the
# earth's centre): a warning says the label is likely wrong, and the index gives the tiles
# a null geometry (a geocentric x and y are no map position).
mislabelled=$data/laz/pdal_lone-star-split-1.laz
if [ -f "$mislabelled" ]; then
  "$vola" tile "$mislabelled" --tile-size 100 --depth 4 -o "$tmp/mislabelled" -q 2> "$tmp/err.txt" ||
    fail "the mislabelled file refused: $(cat "$tmp/err.txt")"
  grep -q "km from the earth's centre.*geocentric CRS: the CRS label is likely wrong.*null geometry" "$tmp/err.txt" ||
    fail "no warning about the likely wrong label: $(cat "$tmp/err.txt")"
  python3 - "$tmp/mislabelled/index.geojson" <<'PY' || fail "mislabelled tiles' geometries are not null"
import json, sys
features = json.load(open(sys.argv[1]))["features"]
sys.exit(0 if features and all(f["geometry"] is None for f in features) else 1)
PY
  "$vola" tile "$geo" --tile-size 0.01 --depth 4 -o "$tmp/degrees2" --allow-geographic -q 2> "$tmp/err.txt"
  grep -q "likely wrong" "$tmp/err.txt" && fail "a true WGS 84 file was said to be mislabelled: $(cat "$tmp/err.txt")"
fi
# --assign-crs relabels (a warning says the file stated another CRS); --crs is its old name.
"$vola" tile "$las" --assign-crs 2994 --tile-size 256 --depth 4 -o "$tmp/assigned" > /dev/null 2> "$tmp/err.txt" ||
  fail "--assign-crs of the same CRS refused: $(cat "$tmp/err.txt")"
[ -s "$tmp/err.txt" ] && fail "--assign-crs of the file's own CRS warned: $(cat "$tmp/err.txt")"
"$vola" tile "$las" --assign-crs 32610 --tile-size 256 --depth 4 -o "$tmp/relabelled" > /dev/null 2> "$tmp/err.txt"
grep -q "relabels its coordinates without moving them" "$tmp/err.txt" || fail "relabel warning: $(cat "$tmp/err.txt")"
"$vola" tile "$las" --crs 32610 --tile-size 256 --depth 4 -o "$tmp/old_flag" -q 2> "$tmp/err.txt"
grep -q -- "--crs is now --assign-crs" "$tmp/err.txt" || fail "old --crs note: $(cat "$tmp/err.txt")"
# The same CRS spelled by two writers (PDAL's WKT with no code, GeoKeys EPSG:2994) tiles together.
"$vola" tile "$las" "$data/las/pdal_autzen_pf1.las" --tile-size 256 --depth 4 -o "$tmp/spelled" -q 2> "$tmp/err.txt" ||
  fail "one CRS in two spellings refused: $(cat "$tmp/err.txt")"
"$vola" tile "$las" --tile-size 256 --depth 4 -o "$tmp/bad" --memory lots 2> "$tmp/err.txt" && fail "--memory lots accepted"
grep -q -- "--memory 'lots'" "$tmp/err.txt" || fail "--memory message: $(cat "$tmp/err.txt")"
"$vola" tile --tile-size 256 --depth 4 -o "$tmp/none" 2> "$tmp/err.txt" && fail "no input accepted"
grep -q "no input" "$tmp/err.txt" || fail "no-input message: $(cat "$tmp/err.txt")"
# Inputs are regular files: a GDAL network path (no such file here) or a directory never
# reaches a reader.
for case in "/vsicurl/http://127.0.0.1:9/dem.tif|cannot open: No such file" "$tmp/one|not a regular file"; do
  input=${case%|*} message=${case#*|}
  "$vola" tile "$input" --tile-size 256 --depth 4 -o "$tmp/notfile" 2> "$tmp/err.txt" && fail "input $input accepted"
  grep -q "$message" "$tmp/err.txt" || fail "input $input message: $(cat "$tmp/err.txt")"
done

# A tile gone from the set: queries that need it say which file, and do not crash.
cp -r "$tmp/one" "$tmp/broken"
rm "$tmp/broken/$first_tile"
"$vola" get "$tmp/broken/index.geojson" "$x" "$y" "$z" 2> "$tmp/err.txt" && fail "get on a missing tile succeeded"
grep -q "$first_tile" "$tmp/err.txt" || fail "missing-tile message: $(cat "$tmp/err.txt")"
status=0
"$vola" render "$tmp/broken/index.geojson" --size 160x120 -o "$tmp/b.png" 2> "$tmp/err.txt" || status=$?
[ "$status" = 1 ] || fail "render with a missing tile: exit $status, expected 1: $(cat "$tmp/err.txt")"
grep -q "$first_tile" "$tmp/err.txt" || fail "render missing-tile message: $(cat "$tmp/err.txt")"

# Many processes: 3 ranks (2 cores, so oversubscribed) write the same bytes.
if ! command -v mpirun > /dev/null; then
  skip "mpirun not installed (apt-get install openmpi-bin libopenmpi-dev)"
fi
export OMPI_MCA_btl_vader_single_copy_mechanism=none  # no ptrace between ranks in containers
mpirun --allow-run-as-root --oversubscribe -np 3 "$vola" tile "$las" --tile-size 256 --depth 4 -o "$tmp/mpi" \
  --threads 1 --chunk-points 7000 -q || fail "mpirun -np 3 vola tile failed"
diff -r "$tmp/one" "$tmp/mpi" > /dev/null || fail "3 MPI ranks give other bytes than one process"
mpirun --allow-run-as-root --oversubscribe -np 2 "$vola" tile "$las" --tile-size 256 --depth 4 -o "$tmp/mpi2" \
  --threads 2 --memory 1M -q || fail "mpirun -np 2 vola tile failed"
diff -r "$tmp/one" "$tmp/mpi2" > /dev/null || fail "2 MPI ranks (2 threads, 1 MiB) give other bytes than one process"
echo "cli_tile: OK"
