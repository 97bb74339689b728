#!/usr/bin/env bash
# `vola export` and `vola coords --wgs84`, end to end.
#
#   cli_export.sh VOLA_BINARY SHARED_DIR      ($VOLA_SHARED overrides SHARED_DIR)
#
# A real survey (pdal_autzen-utm.las) goes points -> vol -> every export format ->
# `vola convert` on the same grid -> vol, and must give the same voxels (and, for LAS,
# the same attributes and CRS); PNG exports are PNG files of the right count and size;
# bad option combinations fail with a message; --wgs84 puts the golden Irish Grid file
# in Dublin and refuses a file without a CRS.
# Exit status: 0 all good, 1 failures, 77 shared folder missing (outside CI).
set -uo pipefail

if [[ $# -ne 2 ]]; then
  echo "usage: $0 VOLA_BINARY SHARED_DIR" >&2
  exit 2
fi
vola=$1
shared=${VOLA_SHARED:-$2}
las=$shared/data/las/pdal_autzen-utm.las
golden=$shared/golden
keep_going=1
source "$(dirname "$0")/../lib/cli_test.sh"
[[ -f $las && -d $golden ]] || skip "$las or $golden is missing"
# expect_error MESSAGE_PART COMMAND...: the command fails and says MESSAGE_PART.
expect_error() {
  local part=$1
  shift
  if "$@" >"$tmp/out" 2>"$tmp/err"; then
    fail "'$*' succeeded, expected an error saying '$part'"
  elif ! grep -q -- "$part" "$tmp/err"; then
    fail "'$*' failed without saying '$part': $(cat "$tmp/err")"
  fi
}

grid=(--voxel-size 2 --origin 493990 4877420 120 --depth 5 -q)
"$vola" convert "$las" "$tmp/a.vol" "${grid[@]}" || fail "convert $las"
"$vola" voxels "$tmp/a.vol" | sort >"$tmp/a.voxels"
[[ $(wc -l <"$tmp/a.voxels") -gt 1000 ]] || fail "the survey gave too few voxels"

# same_voxels FILE.vol WHAT: the file's voxels are a.vol's.
same_voxels() {
  "$vola" voxels "$1" | sort >"$tmp/b.voxels"
  cmp -s "$tmp/a.voxels" "$tmp/b.voxels" || fail "$2: voxel set differs ($(wc -l <"$tmp/b.voxels") vs $(wc -l <"$tmp/a.voxels") voxels)"
}

# LAS: voxels, attributes (but height, which the reader derives from z) and CRS survive.
"$vola" export "$tmp/a.vol" "$tmp/a.las" -q || fail "export LAS"
"$vola" convert "$tmp/a.las" "$tmp/las.vol" "${grid[@]}" || fail "convert the exported LAS"
same_voxels "$tmp/las.vol" "LAS round trip"
attributes() { "$vola" voxels "$1" --attributes --header | awk '{ $9 = ""; print }' | sort; }
[[ $("$vola" voxels "$tmp/a.vol" --attributes --header | head -1) == "x y z red green blue intensity classification height number_of_returns" ]] ||
  fail "unexpected attribute columns from the survey"
cmp -s <(attributes "$tmp/a.vol") <(attributes "$tmp/las.vol") || fail "LAS round trip: attributes differ"
"$vola" info "$tmp/las.vol" | grep -q "crs:.*EPSG:26910" || fail "LAS round trip lost the CRS (EPSG:26910)"

# Text and PLY (binary, ascii) round trips on the same grid.
for out in a.xyz a.ply ascii.ply; do
  extra=()
  [[ $out == ascii.ply ]] && extra=(--ascii)
  "$vola" export "$tmp/a.vol" "$tmp/$out" "${extra[@]}" -q || fail "export $out"
  "$vola" convert "$tmp/$out" "$tmp/$out.vol" "${grid[@]}" || fail "convert the exported $out"
  same_voxels "$tmp/$out.vol" "$out round trip"
done
head -c 4 "$tmp/a.ply" | grep -q "ply" || fail "a.ply does not start with 'ply'"
grep -q "^format binary_little_endian 1.0" "$tmp/a.ply" || fail "PLY is not binary little-endian by default"
grep -q "^format ascii 1.0" "$tmp/ascii.ply" || fail "--ascii PLY is not ascii"

# The cube mesh: one face per voxel side no other voxel covers.
"$vola" export "$tmp/a.vol" "$tmp/cubes.ply" --cubes >"$tmp/out" || fail "export --cubes"
faces=$(grep -a -m1 "^element face" "$tmp/cubes.ply" | cut -d' ' -f3)
expected_faces=$(awk '{ v[$1" "$2" "$3] = 1 } END {
  n = 0
  for (k in v) { split(k, c, " ")
    if (!((c[1]-1)" "c[2]" "c[3] in v)) n++; if (!((c[1]+1)" "c[2]" "c[3] in v)) n++
    if (!(c[1]" "(c[2]-1)" "c[3] in v)) n++; if (!(c[1]" "(c[2]+1)" "c[3] in v)) n++
    if (!(c[1]" "c[2]" "(c[3]-1) in v)) n++; if (!(c[1]" "c[2]" "(c[3]+1) in v)) n++ }
  print n }' "$tmp/a.voxels")
[[ $faces == "$expected_faces" ]] || fail "--cubes: $faces faces, expected $expected_faces"

# NPY dense grid of the level-of-detail copy: read back as a grid, one cell one voxel.
"$vola" export "$tmp/a.vol" "$tmp/g.npy" --depth 4 -q || fail "export NPY --depth 4"
"$vola" convert "$tmp/g.npy" "$tmp/g.vol" -q || fail "convert the exported NPY"
"$vola" lod "$tmp/a.vol" --depth 4 "$tmp/lod.vol" -q || fail "lod"
cmp -s <("$vola" voxels "$tmp/g.vol" | sort) <("$vola" voxels "$tmp/lod.vol" | sort) || fail "NPY round trip differs from vola lod"
[[ $(stat -c %s "$tmp/g.npy") -eq $((128 + 256 * 256 * 256)) ]] || fail "g.npy is not a 256^3 uint8 grid"
"$vola" convert "$las" "$tmp/deep.vol" --voxel-size 0.5 --depth 6 -q || fail "convert at depth 6"
expect_error "coarser copy (--depth K)" "$vola" export "$tmp/deep.vol" "$tmp/deep.npy"
[[ -e $tmp/deep.npy ]] && fail "a refused NPY export left a file"

# binvox (the binvox writer's own tests check the format; here: the voxels come back).
"$vola" export "$tmp/a.vol" "$tmp/a.binvox" -q || fail "export binvox"
"$vola" convert "$tmp/a.binvox" "$tmp/binvox.vol" -q || fail "convert the exported binvox"
same_voxels "$tmp/binvox.vol" "binvox round trip"

# PNG images.
is_png() { [[ $(head -c 8 "$1" | od -An -tx1 | tr -d ' \n') == 89504e470d0a1a0a ]]; }
png_size() { od -An -tu1 -j16 -N8 "$1" | awk '{ print $1*16777216 + $2*65536 + $3*256 + $4, $5*16777216 + $6*65536 + $7*256 + $8 }'; }
"$vola" export "$tmp/a.vol" "$tmp/slices" --slices --depth 2 -q || fail "export --slices"
[[ $(ls "$tmp/slices" | grep -c '\.png$') -eq 16 ]] || fail "--slices --depth 2 wrote $(ls "$tmp/slices" | grep -c '\.png$') images, not 16"
[[ $(ls "$tmp/slices" | grep -c '\.pgw$') -eq 16 ]] || fail "--slices --depth 2: not one .pgw world file per image"
is_png "$tmp/slices/depth2-015.png" || fail "depth2-015.png is not a PNG"
[[ $(png_size "$tmp/slices/depth2-000.png") == "16 16" ]] || fail "slices are not 16x16"
"$vola" export "$tmp/a.vol" "$tmp/h.png" --map -q || fail "export --map"
is_png "$tmp/h.png" && [[ $(png_size "$tmp/h.png") == "1024 1024" ]] || fail "height map is not a 1024x1024 PNG"
"$vola" export "$tmp/a.vol" "$tmp/o.png" --occupancy-above 10 --depth 4 -q || fail "export --occupancy-above"
is_png "$tmp/o.png" && [[ $(png_size "$tmp/o.png") == "256 256" ]] || fail "occupancy map is not a 256x256 PNG"

# Options that do not go together, and unknown formats.
expect_error "needs --slices" "$vola" export "$tmp/a.vol" "$tmp/x.png"
expect_error "apply to PLY" "$vola" export "$tmp/a.vol" "$tmp/x.las" --ascii
expect_error "give one" "$vola" export "$tmp/a.vol" "$tmp/x.png" --map --occupancy-above 2
expect_error "extension" "$vola" export "$tmp/a.vol" "$tmp/x.foo"
expect_error "deeper" "$vola" export "$tmp/a.vol" "$tmp/x.xyz" --depth 6

# coords --wgs84: the golden Irish Grid file's voxel centres average to Dublin.
irish=$golden/crs29902_sparse/crs29902_sparse.vol
"$vola" coords "$irish" --wgs84 --header >"$tmp/wgs84.txt" || fail "coords --wgs84"
[[ $(head -1 "$tmp/wgs84.txt") == "lon lat z" ]] || fail "coords --wgs84 --header: $(head -1 "$tmp/wgs84.txt")"
awk 'NR > 1 { lon += $1; lat += $2; n++ } END {
  ok = n == 192 && (lat / n - 53.3457) ^ 2 < 0.0001 && (lon / n + 6.2673) ^ 2 < 0.0001
  if (!ok) { printf "mean lon %f lat %f of %d voxels\n", lon / n, lat / n, n; exit 1 } }' "$tmp/wgs84.txt" ||
  fail "coords --wgs84 is not in Dublin"
# z is unchanged.
cmp -s <(awk 'NR > 1 { print $3 }' "$tmp/wgs84.txt") <("$vola" coords "$irish" | awk '{ print $3 }') ||
  fail "coords --wgs84 changed z"
# A UTM northing prints as one ("5000000", not "5e+06"); tiny and huge values stay exact.
printf '500000.5 5000000.5 100.5\n' >"$tmp/utm.xyz"
"$vola" convert "$tmp/utm.xyz" "$tmp/utm.vol" --voxel-size 2 --origin 499999 4999999 99 -q || fail "convert utm.xyz"
[[ $("$vola" coords "$tmp/utm.vol" 2>/dev/null) == "500000 5000000 100" ]] ||
  fail "coords of a UTM voxel: $("$vola" coords "$tmp/utm.vol" 2>/dev/null)"
# A file without a CRS says so; --crs supplies one.
nocrs=$golden/d2_sparse/d2_sparse.vol
expect_error "has no CRS" "$vola" coords "$nocrs" --wgs84
"$vola" coords "$nocrs" --wgs84 --crs 29902 >/dev/null || fail "coords --wgs84 --crs 29902"
"$vola" coords "$nocrs" 2>"$tmp/err" >/dev/null || fail "coords without a CRS"
grep -q "has no CRS" "$tmp/err" || fail "coords on a file without a CRS did not say so"
"$vola" coords "$nocrs" --crs 29902 >/dev/null 2>&1 && fail "coords --crs without --wgs84 was accepted"

# A format with no place for the CRS says it is not kept (export dropped it without a word,
# where translate warned); LAS keeps it and says nothing.
"$vola" export "$irish" "$tmp/crs.ply" -q 2>"$tmp/err" || fail "export to PLY"
grep -q "crs.ply: this format has no place for the CRS of .*: it is not kept" "$tmp/err" || fail "no CRS warning: $(cat "$tmp/err")"
"$vola" export "$irish" "$tmp/crs.las" -q 2>"$tmp/err" || fail "export to LAS"
[[ ! -s $tmp/err ]] || fail "LAS export warned: $(cat "$tmp/err")"
"$vola" export "$nocrs" "$tmp/nocrs.ply" -q 2>"$tmp/err" || fail "export of a file without CRS"
[[ ! -s $tmp/err ]] || fail "a file without a CRS warned: $(cat "$tmp/err")"

# A WKT record PROJ cannot read ("''" in pdal_warsaw_small.las) is not kept, with a
# warning: kept, it made every GeoTIFF export fail ("GDAL cannot read the file's CRS WKT").
warsaw=$shared/data/las/pdal_warsaw_small.las
"$vola" convert "$warsaw" "$tmp/warsaw.vol" --voxel-size 2 -q 2>"$tmp/err" || fail "convert warsaw"
grep -q "its WKT record ('') is not a CRS PROJ can read: it is not kept" "$tmp/err" || fail "no WKT warning: $(cat "$tmp/err")"
"$vola" export "$tmp/warsaw.vol" "$tmp/warsaw.tif" --raster dsm -q || fail "a raster of warsaw"

if [[ $failures -ne 0 ]]; then
  echo "$failures failure(s)" >&2
  exit 1
fi
echo "cli_export: all checks passed"
