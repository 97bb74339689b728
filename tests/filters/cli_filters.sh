#!/usr/bin/env bash
# Point filters end to end through the CLI on the Autzen survey:
#  - translate --filter smrf writes classes 1 and 2 only, as many ground points as it
#    reports, and every other byte of every record as it was;
#  - convert --where gives the bytes of converting the points translate --where kept;
#  - a JSON pipeline gives the files of the same flags;
#  - unknown dimensions and filters fail with a message that names them.
# Usage: cli_filters.sh VOLA SHARED_DATA_DIR   ($VOLA_SHARED/data, when set, wins)
set -euo pipefail
vola=$1 data=${VOLA_SHARED:+$VOLA_SHARED/data}
data=${data:-$2}
source "$(dirname "$0")/../lib/cli_test.sh"
# The point count a LAS header states (legacy 32-bit field, or the 64-bit one of LAS 1.4).
records_count() {
  python3 -c "
import struct, sys
d = open(sys.argv[1], 'rb').read(255)
n = struct.unpack_from('<I', d, 107)[0]
print(n if n or d[25] < 4 else struct.unpack_from('<Q', d, 247)[0])" "$1"
}
autzen=$data/las/pdal_autzen_trim.las
[ -f "$autzen" ] || skip "no $autzen (set VOLA_SHARED)"

# translate --filter smrf: classes, counts, and the records but their class bits.
"$vola" translate "$autzen" "$tmp/smrf.las" --filter smrf > "$tmp/smrf.txt"
ground=$(sed -n 's/.*smrf: 110000 -> 110000 points, \([0-9]*\) ground/\1/p' "$tmp/smrf.txt")
[ -n "$ground" ] || fail "translate did not report the ground count: $(cat "$tmp/smrf.txt")"
"$vola" info "$tmp/smrf.las" --summary > "$tmp/info.txt"
grep -Eq "^class: +2 Ground +$ground$" "$tmp/info.txt" || fail "info does not count $ground ground points: $(grep class "$tmp/info.txt")"
others=$(awk '/^class:/ && $2 != 1 && $2 != 2 {print}' "$tmp/info.txt")
[ -z "$others" ] || fail "classes other than 1 and 2 after smrf: $others"
python3 - "$autzen" "$tmp/smrf.las" <<'PY' || fail "records differ beyond the classification"
import struct, sys
a, b = (open(p, "rb").read() for p in sys.argv[1:3])
oa, ob = struct.unpack_from("<I", a, 96)[0], struct.unpack_from("<I", b, 96)[0]
n, length = struct.unpack_from("<I", a, 107)[0], struct.unpack_from("<H", a, 105)[0]
assert struct.unpack_from("<I", b, 107)[0] == n
for i in range(n):
    ra, rb = bytearray(a[oa + i * length:oa + (i + 1) * length]), bytearray(b[ob + i * length:ob + (i + 1) * length])
    assert rb[15] & 31 in (1, 2), i
    ra[15] &= 0xE0; rb[15] &= 0xE0
    assert ra == rb, i
PY
# The same to LAZ: the same records once decoded.
"$vola" translate "$autzen" "$tmp/smrf.laz" --filter smrf -q
"$vola" translate "$tmp/smrf.laz" "$tmp/smrf_back.las" -q
python3 - "$tmp/smrf.las" "$tmp/smrf_back.las" <<'PY' || fail "LAZ output decodes to other records"
import struct, sys
a, b = (open(p, "rb").read() for p in sys.argv[1:3])
oa, ob = struct.unpack_from("<I", a, 96)[0], struct.unpack_from("<I", b, 96)[0]
assert a[oa:] == b[ob:ob + len(a) - oa]
PY

# convert --where equals converting the points translate --where kept.
where="Classification == 2 && Z < 450"
"$vola" translate "$autzen" "$tmp/kept.las" --where "$where" -q
"$vola" convert "$tmp/kept.las" "$tmp/kept.vol" --voxel-size 3 -q
"$vola" convert "$autzen" "$tmp/where.vol" --voxel-size 3 --where "$where" -q
cmp "$tmp/kept.vol" "$tmp/where.vol" || fail "convert --where differs from converting the kept points"
"$vola" info "$tmp/kept.las" --summary | grep -Eq "^class: +2 Ground" || fail "no ground left by --where"

# A pipeline gives the files of the same flags.
cat > "$tmp/p.json" <<JSON
["$autzen", {"type": "filters.smrf"}, {"type": "filters.range", "limits": "Classification[2:2]"},
 {"type": "writers.las", "filename": "$tmp/pipe.las"}, {"filename": "$tmp/pipe.vol", "voxel_size": 3}]
JSON
"$vola" pipeline "$tmp/p.json" -q
"$vola" translate "$autzen" "$tmp/flags.las" --filter smrf --where "Classification == 2" -q
"$vola" convert "$autzen" "$tmp/flags.vol" --voxel-size 3 --filter smrf --where "Classification == 2" -q
cmp "$tmp/pipe.las" "$tmp/flags.las" || fail "pipeline LAS differs from the flags'"
cmp "$tmp/pipe.vol" "$tmp/flags.vol" || fail "pipeline .vol differs from the flags'"
# PDAL's usual writer options where vola does what they ask anyway; a contradiction is refused.
cat > "$tmp/pdal.json" <<JSON
{"pipeline": ["$autzen", {"type": "writers.las", "filename": "$tmp/pdal.laz", "forward": "all", "compression": "laszip"}]}
JSON
"$vola" pipeline "$tmp/pdal.json" -q || fail "a PDAL pipeline with forward and compression failed"
echo "[\"$autzen\", \"$tmp/plain.laz\"]" > "$tmp/plain.json"
"$vola" pipeline "$tmp/plain.json" -q
cmp "$tmp/pdal.laz" "$tmp/plain.laz" || fail "forward/compression changed the LAZ"
echo "[\"$autzen\", {\"type\": \"writers.las\", \"filename\": \"$tmp/x.las\", \"compression\": \"laszip\"}]" > "$tmp/bad.json"
if "$vola" pipeline "$tmp/bad.json" 2> "$tmp/err.txt"; then fail "compression to a .las name was accepted"; fi
grep -q '"compression" disagrees with the name' "$tmp/err.txt" || fail "error: $(cat "$tmp/err.txt")"

# Height above ground as a dimension for --where, to PLY.
"$vola" translate "$autzen" "$tmp/high.xyz" --filter smrf --filter hag --where "HeightAboveGround > 2" -q
head -1 "$tmp/high.xyz" | grep -q "height_above_ground" || fail "no height_above_ground column"
awk 'NR > 1 && $NF <= 2 {bad = 1} END {exit bad}' "$tmp/high.xyz" || fail "a point at 2 or less above ground passed"

# Text input: --where sees the --attribute columns by name and keeps them; the same bytes
# as converting the points an awk filter kept.
printf '0.1 0.1 0.1 7 2\n1.2 0.1 0.1 9 5\n2.3 0.1 0.1 8 2\n3.4 2.1 0.1 3 2\n' > "$tmp/pts.xyz"
awk '$5 == 2' "$tmp/pts.xyz" > "$tmp/ground_pts.xyz"
"$vola" convert "$tmp/pts.xyz" "$tmp/text_where.vol" --voxel-size 0.5 --attribute class=5:u8:majority \
  --attribute intensity=4 --where "class == 2" -q
"$vola" convert "$tmp/ground_pts.xyz" "$tmp/text_awk.vol" --voxel-size 0.5 --attribute class=5:u8:majority \
  --attribute intensity=4 -q
cmp "$tmp/text_where.vol" "$tmp/text_awk.vol" || fail "text --where differs from awk's selection"

# Errors name what is wrong.
if "$vola" convert "$autzen" "$tmp/x.vol" --voxel-size 3 --where "Clasification == 2" 2> "$tmp/err.txt"; then fail "a misspelt dimension was accepted"; fi
grep -q "no dimension 'Clasification'" "$tmp/err.txt" || fail "error: $(cat "$tmp/err.txt")"
if "$vola" translate "$autzen" "$tmp/x.las" --filter ground 2> "$tmp/err.txt"; then fail "an unknown filter was accepted"; fi
grep -q "no filter 'ground'" "$tmp/err.txt" || fail "error: $(cat "$tmp/err.txt")"
echo '["a.las", {"type": "filters.smrf", "cells": 2}, "b.las"]' > "$tmp/bad.json"
if "$vola" pipeline "$tmp/bad.json" 2> "$tmp/err.txt"; then fail "a misspelt stage option was accepted"; fi
grep -q 'pipeline stage 1 (filters.smrf): no option "cells"' "$tmp/err.txt" || fail "error: $(cat "$tmp/err.txt")"
# Two overlapping polygons crop to their union (even-odd over both dropped the 600 points
# inside both: 7,888 instead of 8,488); a polygon in longitude/latitude over a survey in
# feet kept nothing without a word: refused, with both extents.
cat > "$tmp/two_areas.geojson" <<'JSON'
{"type": "FeatureCollection", "features": [
 {"type": "Feature", "geometry": {"type": "Polygon", "coordinates": [[[636500, 849000], [636600, 849000], [636600, 849100], [636500, 849100], [636500, 849000]]]}},
 {"type": "Feature", "geometry": {"type": "Polygon", "coordinates": [[[636550, 849050], [636700, 849050], [636700, 849200], [636550, 849200], [636550, 849050]]]}}]}
JSON
"$vola" translate "$autzen" "$tmp/union.las" --crop-polygon "$tmp/two_areas.geojson" -q
"$vola" translate "$autzen" "$tmp/union_where.las" \
  --where "(X > 636500 && X < 636600 && Y > 849000 && Y < 849100) || (X > 636550 && X < 636700 && Y > 849050 && Y < 849200)" -q
[ "$(records_count "$tmp/union.las")" = "$(records_count "$tmp/union_where.las")" ] \
  || fail "two overlapping polygons kept $(records_count "$tmp/union.las") points, their union $(records_count "$tmp/union_where.las")"
echo '{"type": "Polygon", "coordinates": [[[-123.0725, 44.05], [-123.07, 44.05], [-123.07, 44.0515], [-123.0725, 44.05]]]}' \
  > "$tmp/lonlat.geojson"
if "$vola" translate "$autzen" "$tmp/none.las" --crop-polygon "$tmp/lonlat.geojson" 2> "$tmp/err.txt"; then
  fail "a polygon in longitude/latitude over feet kept nothing without a word"
fi
grep -q "the polygons (x -123.0725..-123.07, y 44.05..44.0515) do not meet the points" "$tmp/err.txt" \
  || fail "error: $(cat "$tmp/err.txt")"
# Filters that leave nothing: said so (it said the survey had "no points").
if "$vola" convert "$autzen" "$tmp/nothing.vol" --voxel-size 3 --where "Z > 10000" 2> "$tmp/err.txt"; then
  fail "a conversion of no point succeeded"
fi
grep -q "no point is left after the filters (where:Z > 10000)" "$tmp/err.txt" || fail "error: $(cat "$tmp/err.txt")"
# A writer's type that disagrees with its name's extension is refused (writers.vola named
# o.las wrote LAS and dropped voxel_size).
echo "[\"$autzen\", {\"type\": \"writers.vola\", \"filename\": \"$tmp/o.las\", \"voxel_size\": 3}]" > "$tmp/typed.json"
if "$vola" pipeline "$tmp/typed.json" 2> "$tmp/err.txt"; then fail "writers.vola wrote a .las"; fi
grep -q "writers.vola cannot write .*o.las: vola writes by the name's extension, and .las is writers.las" "$tmp/err.txt" \
  || fail "error: $(cat "$tmp/err.txt")"
# PDAL reads ["a.las", "b.las", "out.las"] as two inputs: vola, reading one, refuses it
# (it took b.las as an output and wrote a.las's points over it); no output may be the input.
cp "$autzen" "$tmp/second.las"
echo "[\"$autzen\", \"$tmp/second.las\", \"$tmp/out.las\"]" > "$tmp/two.json"
if "$vola" pipeline "$tmp/two.json" 2> "$tmp/err.txt"; then fail "a second input was taken as an output"; fi
grep -q "pipeline stage 1: .*second.las: a file named without a type between the first and the last stage is another input to PDAL" "$tmp/err.txt" \
  || fail "error: $(cat "$tmp/err.txt")"
cmp -s "$autzen" "$tmp/second.las" || fail "the second input was changed"
# A range that holds no value is refused naming it, as --crop refuses an upside-down box
# (it wrote an empty LAS and exited 0).
echo "[\"$autzen\", {\"type\": \"filters.range\", \"limits\": \"Z[420:410]\"}, \"$tmp/none.las\"]" > "$tmp/empty.json"
if "$vola" pipeline "$tmp/empty.json" 2> "$tmp/err.txt"; then fail "an empty range ran"; fi
grep -qF "Z's range [420:410] holds no value (a minimum of 420, a maximum of 410)" "$tmp/err.txt" ||
  fail "empty range: $(cat "$tmp/err.txt")"
[ ! -e "$tmp/none.las" ] || fail "an empty range wrote a file"
# SMRF on points in degrees says what to do in the CLI's words (it named target_crs, which
# vola translate does not have and which runs after the filters anyway).
if "$vola" translate "$data/las/pdal_epsg_4326.las" "$tmp/deg.xyz" --filter smrf 2> "$tmp/err.txt"; then
  fail "smrf ran on degrees"
fi
grep -q "smrf: the points' CRS (WGS 84) has coordinates in degree.*filters.reprojection.*--assign-crs" "$tmp/err.txt" ||
  fail "smrf on degrees: $(cat "$tmp/err.txt")"
# A range on a dimension the points lack names it; the position points into the quoted
# expression the limits became (not into text the user never saw).
echo "[\"$autzen\", {\"type\": \"filters.range\", \"limits\": \"Classification[2:2],Nope[1:5]\"}, \"$tmp/nope.las\"]" \
  > "$tmp/nope.json"
if "$vola" pipeline "$tmp/nope.json" 2> "$tmp/err.txt"; then fail "a range on a missing dimension ran"; fi
grep -qF "at character 50 of '(Classification >= 2 && Classification <= 2) && (Nope >= 1 && Nope <= 5)': no dimension 'Nope'" \
  "$tmp/err.txt" || fail "missing dimension: $(cat "$tmp/err.txt")"
cp "$autzen" "$tmp/mine.las"
echo "[\"$tmp/mine.las\", {\"type\": \"filters.range\", \"limits\": \"Classification[2:2]\"}, \"$tmp/mine.las\"]" \
  > "$tmp/self.json"
if "$vola" pipeline "$tmp/self.json" 2> "$tmp/err.txt"; then fail "a pipeline wrote over its input"; fi
grep -q "mine.las is the input: a pipeline.s writers write new files" "$tmp/err.txt" || fail "error: $(cat "$tmp/err.txt")"
if "$vola" translate "$tmp/mine.las" "$tmp/mine.las" --where "Classification == 2" 2> "$tmp/err.txt"; then
  fail "translate wrote over its input"
fi
grep -q "mine.las is the input: vola translate writes a new point file" "$tmp/err.txt" || fail "error: $(cat "$tmp/err.txt")"
cmp -s "$autzen" "$tmp/mine.las" || fail "the input was changed"
# A PLY or XYZ output has no place for the CRS: a warning says so (-q too), a LAS keeps it.
"$vola" translate "$autzen" "$tmp/crs.ply" -q 2> "$tmp/err.txt" || fail "translate to PLY failed"
grep -q "PLY has no place for the CRS of .* (a WKT with no EPSG code): it is not kept" "$tmp/err.txt" ||
  fail "no CRS warning for PLY: $(cat "$tmp/err.txt")"
"$vola" translate "$autzen" "$tmp/crs.xyz" -q 2> "$tmp/err.txt" || fail "translate to XYZ failed"
grep -q "XYZ has no place for the CRS" "$tmp/err.txt" || fail "no CRS warning for XYZ: $(cat "$tmp/err.txt")"
echo "[\"$autzen\", \"$tmp/pipe_crs.ply\"]" > "$tmp/crs.json"
"$vola" pipeline "$tmp/crs.json" -q 2> "$tmp/err.txt" || fail "pipeline to PLY failed"
grep -q "PLY has no place for the CRS" "$tmp/err.txt" || fail "no CRS warning from a pipeline: $(cat "$tmp/err.txt")"
"$vola" translate "$tmp/crs.ply" "$tmp/crs2.xyz" -q 2> "$tmp/err.txt" || fail "translate PLY to XYZ failed"
[ ! -s "$tmp/err.txt" ] || fail "a warning for a file with no CRS: $(cat "$tmp/err.txt")"
# A point file's return numbers (the PDAL-written PCD has returns 1-4) are counted into the
# LAS header's points by return (they were all counted as return 1), and the WKT bit set.
pcd=$data/pcd/pdal_autzen-utm.pcd
if [ -f "$pcd" ]; then
  "$vola" translate "$pcd" "$tmp/frompcd.las" -q
  "$vola" translate "$pcd" "$tmp/frompcd.xyz" -q 2> /dev/null
  "${VOLA_PYTHON:-python3}" - "$tmp/frompcd.las" "$tmp/frompcd.xyz" <<'PY' || fail "points by return of a PCD written as LAS"
import collections, struct, sys
head = open(sys.argv[1], "rb").read(375)
lines = open(sys.argv[2]).read().splitlines()
names = lines[0].lstrip("# ").split()
returns = collections.Counter(int(float(l.split()[names.index("return_number")])) for l in lines[1:])
stated = struct.unpack_from("<15Q", head, 255)
assert list(stated) == [returns.get(r, 0) for r in range(1, 16)], (stated, returns)
assert len(returns) > 1 and struct.unpack_from("<H", head, 6)[0] & 16, (returns, head[6:8])
PY
fi

# An extra-bytes name with a space ("echo width", as some writers name it) is found by the
# spelling the text and PLY writers give it (echo_width).
"${VOLA_PYTHON:-python3}" - "$tmp/spaced.las" <<'PY'
import struct, sys
vlr_data = bytearray(192)
vlr_data[2] = 3  # uint16
vlr_data[4:14] = b"echo width"
points = []
for i in range(10):
    r = bytearray(22)
    struct.pack_into("<3i", r, 0, i * 100, i * 100, i * 100)
    r[14] = 9
    struct.pack_into("<H", r, 20, i * 50)
    points.append(bytes(r))
vlr = bytearray(54)
vlr[2:11] = b"LASF_Spec"
struct.pack_into("<HH", vlr, 18, 4, len(vlr_data))
head = bytearray(227)
head[0:4] = b"LASF"
head[24:26] = bytes([1, 2])
struct.pack_into("<HIIBHI", head, 94, 227, 227 + 54 + 192, 1, 0, 22, 10)
struct.pack_into("<3d", head, 131, 0.01, 0.01, 0.01)
struct.pack_into("<6d", head, 179, 9, 0, 9, 0, 9, 0)
open(sys.argv[1], "wb").write(head + vlr + vlr_data + b"".join(points))
PY
"$vola" translate "$tmp/spaced.las" "$tmp/spaced.xyz" --where "echo_width > 200" -q 2> /dev/null ||
  fail "--where echo_width on a field named 'echo width' failed"
[ "$(grep -vc '^#' "$tmp/spaced.xyz")" = 5 ] || fail "--where echo_width > 200 kept $(grep -vc '^#' "$tmp/spaced.xyz") of 10"

# PDAL's three forms of crop bounds keep the same points (the GeoJSON bbox's four numbers
# were read as the classic form's minx, maxx, miny, maxy: 48,856 points instead of 17,864).
classic='([636500, 636800.5], [849000, 849200])'
for bounds in "\"$classic\"" '"[636500, 849000, 636800.5, 849200]"' '[636500, 849000, 636800.5, 849200]' \
              '{"minx": 636500, "miny": 849000, "maxx": 636800.5, "maxy": 849200}' \
              '"{\"minx\": 636500, \"miny\": 849000, \"maxx\": 636800.5, \"maxy\": 849200}"'; do
  echo "[\"$autzen\", {\"type\": \"filters.crop\", \"bounds\": $bounds}, \"$tmp/crop.las\"]" > "$tmp/crop.json"
  "$vola" pipeline "$tmp/crop.json" > "$tmp/crop.txt" || fail "crop bounds $bounds: $(cat "$tmp/crop.txt")"
  grep -q "110000 -> 17864 points" "$tmp/crop.txt" || fail "crop bounds $bounds: $(cat "$tmp/crop.txt")"
done
echo "[\"$autzen\", {\"type\": \"filters.crop\", \"bounds\": \"[1, 2, 3]\"}, \"$tmp/crop.las\"]" > "$tmp/crop.json"
if "$vola" pipeline "$tmp/crop.json" 2> "$tmp/err.txt"; then fail "three bounds were taken"; fi
grep -q 'pipeline stage 1 (filters.crop): "bounds" must be' "$tmp/err.txt" || fail "bad bounds: $(cat "$tmp/err.txt")"
# A name without a type between the first and the last stage is another input to PDAL,
# after a filter too: refused, the file untouched (it was written over as an output).
cp "$data/las/pdal_1.2-with-color.las" "$tmp/other.las"
echo "[\"$autzen\", {\"type\": \"filters.range\", \"limits\": \"Classification[2:2]\"}, \"$tmp/other.las\", \"$tmp/m.las\"]" \
  > "$tmp/mid.json"
if "$vola" pipeline "$tmp/mid.json" 2> "$tmp/err.txt"; then fail "a middle name was taken as an output"; fi
grep -q "pipeline stage 2: .*other.las: a file named without a type between the first and the last stage" "$tmp/err.txt" ||
  fail "middle name: $(cat "$tmp/err.txt")"
cmp -s "$data/las/pdal_1.2-with-color.las" "$tmp/other.las" || fail "the middle file was changed"
# A stage without a type is the stage its place makes it, options checked as that stage's
# (PDAL's own examples give writers scale_x; vola dropped every option without a word).
echo "[{\"filename\": \"$autzen\", \"override_srs\": \"EPSG:26910\"}, \"$tmp/u.las\"]" > "$tmp/u.json"
if "$vola" pipeline "$tmp/u.json" 2> "$tmp/err.txt"; then fail "a reader's override_srs was dropped"; fi
grep -q 'pipeline stage 0 (readers.las): no option "override_srs"' "$tmp/err.txt" || fail "untyped reader: $(cat "$tmp/err.txt")"
echo "[\"$autzen\", {\"filename\": \"$tmp/u.las\", \"scale_x\": 0.1}]" > "$tmp/u.json"
if "$vola" pipeline "$tmp/u.json" 2> "$tmp/err.txt"; then fail "a writer's scale_x was dropped"; fi
grep -q 'pipeline stage 1 (writers.las): no option "scale_x"' "$tmp/err.txt" || fail "untyped writer: $(cat "$tmp/err.txt")"
# Every .vol writer is checked before any writer runs (the LAS one was left behind).
echo "[\"$autzen\", {\"type\": \"writers.las\", \"filename\": \"$tmp/first.las\"}, {\"type\": \"writers.vola\", \"filename\": \"$tmp/v.vol\"}]" \
  > "$tmp/v.json"
if "$vola" pipeline "$tmp/v.json" 2> "$tmp/err.txt"; then fail "a .vol writer without a voxel size ran"; fi
grep -q 'pipeline writer .*v.vol: how fine should the voxels be? Give "voxel_size"' "$tmp/err.txt" || fail "vola writer: $(cat "$tmp/err.txt")"
[ ! -e "$tmp/first.las" ] || fail "the first writer ran before the last was checked"
# PDAL's defaults and spellings: a voxel filter's cell is 1 by default; spaces around range
# limits; filters.sample by cell.
echo "[\"$autzen\", {\"type\": \"filters.voxelcenternearestneighbor\"}, {\"type\": \"filters.range\", \"limits\": \"Z[ 420 : 430 ]\"}, {\"type\": \"filters.sample\", \"cell\": 2}, \"$tmp/d.las\"]" \
  > "$tmp/d.json"
"$vola" pipeline "$tmp/d.json" > "$tmp/d.txt" || fail "PDAL defaults: $(cat "$tmp/d.txt")"
grep -q "voxel:1: " "$tmp/d.txt" && grep -q "where:(Z >= 420 && Z <= 430)" "$tmp/d.txt" && grep -q "poisson:1.73205" "$tmp/d.txt" ||
  fail "PDAL defaults: $(cat "$tmp/d.txt")"
# filters.outlier as PDAL computes it (the sample standard deviation, a mean at the limit
# is an outlier): PDAL's formula keeps 2,863 of warsaw_small's 3,000 points (vola kept 2,862).
"$vola" translate "$data/las/pdal_warsaw_small.las" "$tmp/o.las" --filter outlier > "$tmp/o.txt"
grep -q "outlier: 3000 -> 2863 points" "$tmp/o.txt" || fail "outlier: $(cat "$tmp/o.txt")"
# SMRF measures in the CRS --assign-crs gives (it read the file's, or none: feet as metres).
"$vola" translate "$autzen" "$tmp/nocrs.xyz" -q 2> /dev/null
"$vola" convert "$tmp/nocrs.xyz" "$tmp/nocrs.vol" --voxel-size 5 --assign-crs EPSG:2994 --filter smrf > "$tmp/a.txt"
grep -q "smrf: 110000 -> 110000 points, $ground ground" "$tmp/a.txt" || fail "smrf under --assign-crs: $(cat "$tmp/a.txt")"
# LAS -> XYZ -> LAS keeps the colours as they were (8-bit values in 16-bit fields were
# widened to 16 bits: red 84 came back 21,588), as PDAL's readers.text keeps them.
"$vola" translate "$tmp/nocrs.xyz" "$tmp/back.las" -q 2> /dev/null
"${VOLA_PYTHON:-python3}" - "$autzen" "$tmp/back.las" <<'PY' || fail "colours changed through XYZ"
import struct, sys
def colours(path):
    d = open(path, "rb").read()
    offset, length, count = struct.unpack_from("<I", d, 96)[0], struct.unpack_from("<H", d, 105)[0], struct.unpack_from("<I", d, 107)[0]
    if count == 0 and d[25] >= 4:  # LAS 1.4: the 64-bit count
        count = struct.unpack_from("<Q", d, 247)[0]
    at = {3: 28, 7: 30}[d[104] & 63]
    return [struct.unpack_from("<3H", d, offset + i * length + at) for i in range(count)]
assert colours(sys.argv[1]) == colours(sys.argv[2])
PY
# CSV (PDAL's writers.text: "X","Y","Z","Intensity",...) reads back into the same fields.
"$vola" translate "$autzen" "$tmp/pdal.csv" -q 2> /dev/null
head -c 60 "$tmp/pdal.csv" | grep -q '^"X","Y","Z","Intensity","ReturnNumber","NumberOfReturns"' ||
  fail "CSV header: $(head -c 120 "$tmp/pdal.csv")"
"$vola" translate "$tmp/pdal.csv" "$tmp/from_csv.las" -q 2> /dev/null
"${VOLA_PYTHON:-python3}" - "$autzen" "$tmp/from_csv.las" <<'PY' || fail "fields changed through CSV"
import struct, sys
def fields(path):
    d = open(path, "rb").read()
    offset, length, count = struct.unpack_from("<I", d, 96)[0], struct.unpack_from("<H", d, 105)[0], struct.unpack_from("<I", d, 107)[0]
    if count == 0 and d[25] >= 4:
        count = struct.unpack_from("<Q", d, 247)[0]
    fmt = d[104] & 63
    colour, intensity = {3: 28, 7: 30}[fmt], 12
    cls = (lambda r: r[15] & 31) if fmt < 6 else (lambda r: r[16])
    out = []
    for i in range(count):
        r = d[offset + i * length:offset + (i + 1) * length]
        out.append((struct.unpack_from("<H", r, intensity)[0], cls(r), struct.unpack_from("<3H", r, colour)))
    return out
assert fields(sys.argv[1]) == fields(sys.argv[2])
PY
# PDAL's LAS 1.4 dimensions in a CSV PDAL could have written: ScanChannel and the four
# one-bit flags go into the LAS fields, come back out under PDAL's names, and --where
# reads the flags of a LAS file by those names.
cat > "$tmp/flags.csv" <<'CSV'
"X","Y","Z","Classification","Synthetic","KeyPoint","Withheld","Overlap","ScanChannel"
1.00,2.00,3.00,2,1,0,0,0,0
4.00,5.00,6.00,1,0,1,1,0,3
7.00,8.00,9.00,5,0,0,1,1,2
CSV
"$vola" translate "$tmp/flags.csv" "$tmp/flags.las" -q 2> /dev/null
"${VOLA_PYTHON:-python3}" - "$tmp/flags.las" <<'PY' || fail "PDAL's flag dimensions did not reach the LAS fields"
import struct, sys
d = open(sys.argv[1], "rb").read()
offset, length = struct.unpack_from("<I", d, 96)[0], struct.unpack_from("<H", d, 105)[0]
assert d[104] & 63 >= 6, d[104]
got = [(d[offset + i * length + 15] & 15, d[offset + i * length + 15] >> 4 & 3) for i in range(3)]
assert got == [(0b0001, 0), (0b0110, 3), (0b1100, 2)], got
PY
"$vola" translate "$tmp/flags.las" "$tmp/flags_back.csv" -q 2> /dev/null
"${VOLA_PYTHON:-python3}" - "$tmp/flags.csv" "$tmp/flags_back.csv" <<'PY' || fail "flags through LAS and back to CSV: $(head -2 "$tmp/flags_back.csv")"
import csv, sys
def table(path):
    rows = list(csv.reader(open(path)))
    names = rows[0]
    wanted = ["Classification", "Synthetic", "KeyPoint", "Withheld", "Overlap", "ScanChannel"]
    return [[float(r[names.index(n)]) for n in wanted] for r in rows[1:]]
assert table(sys.argv[1]) == table(sys.argv[2]), (table(sys.argv[1]), table(sys.argv[2]))
PY
"$vola" translate "$tmp/flags.las" "$tmp/withheld.xyz" --where "Withheld == 1 && ScanChannel == 2" -q 2> /dev/null
[ "$(grep -vc '^#' "$tmp/withheld.xyz")" == 1 ] || fail "--where on Withheld and ScanChannel: $(cat "$tmp/withheld.xyz")"
# An infrared column goes to a format 6 LAS as extra bytes, and comes back by its name
# (format 6 has no NIR field for it to clash with).
printf 'x y z Infrared\n1 2 3 500\n' > "$tmp/nir.xyz"
"$vola" translate "$tmp/nir.xyz" "$tmp/nir.las" -q 2> /dev/null
"$vola" translate "$tmp/nir.las" "$tmp/nir_back.xyz" -q 2> /dev/null
head -1 "$tmp/nir_back.xyz" | grep -q ' nir$' || fail "infrared through LAS: $(head -1 "$tmp/nir_back.xyz")"
# ... and a filtered conversion keeps it as a plain one does (it dropped "nir" as a field).
"$vola" convert "$tmp/nir.las" "$tmp/nir.vol" --voxel-size 1 --where "Z > 0" -q 2> /dev/null
"$vola" info "$tmp/nir.vol" | grep -q "nir" || fail "filtered convert lost the extra-bytes nir: $("$vola" info "$tmp/nir.vol")"
# A column named like a flag that holds other values than 0 and 1 is no flag: extra bytes,
# read back under a name of its own, so that --where "Overlap" is the flag bit.
printf 'x y z overlap\n1 2 3 0.5\n' > "$tmp/overlap.xyz"
"$vola" translate "$tmp/overlap.xyz" "$tmp/overlap.las" -q 2> /dev/null
"$vola" translate "$tmp/overlap.las" "$tmp/overlap_back.xyz" -q 2> /dev/null
[ "$(head -1 "$tmp/overlap_back.xyz" | awk '{print $NF}')" == overlap_2 ] && [ "$(tail -1 "$tmp/overlap_back.xyz" | awk '{print $NF}')" == 0.5 ] ||
  fail "an overlap column of 0.5 through LAS: $(cat "$tmp/overlap_back.xyz")"
"$vola" translate "$tmp/overlap.las" "$tmp/flag.xyz" --where "Overlap == 0 && overlap_2 > 0.4" -q 2> /dev/null
[ "$(grep -vc '^#' "$tmp/flag.xyz")" == 1 ] || fail "--where on the Overlap flag beside an extra overlap: $(cat "$tmp/flag.xyz")"

# Filters on points without a place: one NaN row kept every outlier of the file.
"${VOLA_PYTHON:-python3}" -c "
import random
random.seed(4)
rows = ['%.4f %.4f %.4f' % (random.uniform(0, 10), random.uniform(0, 10), random.uniform(0, 10)) for _ in range(500)]
rows += ['%.1f %.1f %.1f' % (300 + i, 300, 300) for i in range(5)] + ['nan nan nan']
open('$tmp/nan.xyz', 'w').write('\n'.join(rows) + '\n')"
"$vola" translate "$tmp/nan.xyz" "$tmp/no_outliers.xyz" --filter outlier -q 2> /dev/null
awk '$1 > 100' "$tmp/no_outliers.xyz" | grep -q . && fail "outlier kept the far points of a file with a NaN row"
# A column the filters add does not fit a LAS record: said, not dropped in silence.
"$vola" translate "$autzen" "$tmp/hag.las" --filter smrf --filter hag -q 2> "$tmp/err"
grep -q "height_above_ground, which the filters added, is not written" "$tmp/err" ||
  fail "LAS to LAS dropped the hag column without a word: $(cat "$tmp/err")"
# A pipeline nested 100,000 deep is refused (writing it back out for an error message took
# the process down).
"${VOLA_PYTHON:-python3}" -c "
d = 100000
open('$tmp/deep.json', 'w').write('[\"$autzen\", {\"type\": \"filters.outlier\", \"mean_k\": ' + '[' * d + ']' * d + '}, \"$tmp/o.las\"]')"
"$vola" pipeline "$tmp/deep.json" 2> "$tmp/err" && fail "a pipeline nested 100,000 deep was run"
grep -q "JSON nested deeper than 64 levels" "$tmp/err" || fail "deep pipeline: $(head -c 300 "$tmp/err")"

echo "cli_filters: smrf $ground ground points; where, pipeline, hag and errors checked"
