#!/usr/bin/env bash
# Compressed .vol files of a real survey (Autzen, ../shared/data/laz/pdal_autzen_trim.laz)
# through the CLI: the compressed file holds the same voxels and attribute values as the
# uncompressed one, at 1, 2 and 4 ft, and is at most a given fraction of the LAZ's bytes
# (fractions of the LAZ file's size, not recorded sizes).
#
# Issue 20 point 5 asks for 1/2 of the LAZ with the default attributes and 1/10 for the
# occupancy alone. With --compress vola reaches 0.689 and 0.112 at 1 ft; with
# --compress-max (mixed occupancy models, levels flags 4) the occupancy alone is within
# the 1/10 (docs/BENCHMARKS.md, "Compressed files"). The bound with attributes is what is
# reached, so that it cannot silently get worse; it is not the issue's target.
# Usage: cli_compress.sh VOLA SHARED_DATA_DIR   ($VOLA_SHARED/data, when set, wins)
set -euo pipefail
vola=$1 data=${VOLA_SHARED:+$VOLA_SHARED/data}
data=${data:-$2}
source "$(dirname "$0")/../lib/cli_test.sh"
laz=$data/laz/pdal_autzen_trim.laz
[ -f "$laz" ] || skip "no $laz (set VOLA_SHARED)"
laz_bytes=$(stat -c %s "$laz")

# at_most FILE NUMERATOR DENOMINATOR: FILE's bytes <= LAZ bytes * N / D
at_most() {
  local bytes
  bytes=$(stat -c %s "$1")
  (( bytes * $3 <= laz_bytes * $2 )) ||
    fail "$1: $bytes bytes, more than $2/$3 of the LAZ's $laz_bytes"
  echo "$(basename "$1"): $bytes bytes = $(python3 -c "print(round($bytes / $laz_bytes, 4))") of the LAZ"
}

for size in 1 2 4; do
  "$vola" convert "$laz" "$tmp/plain$size.vol" --voxel-size "$size" > /dev/null
  "$vola" convert "$laz" "$tmp/packed$size.vol" --voxel-size "$size" --compress > /dev/null
  "$vola" convert "$laz" "$tmp/occupancy$size.vol" --voxel-size "$size" --compress --no-attributes > /dev/null
  "$vola" voxels --attributes "$tmp/plain$size.vol" > "$tmp/plain.txt"
  "$vola" voxels --attributes "$tmp/packed$size.vol" > "$tmp/packed.txt"
  cmp -s "$tmp/plain.txt" "$tmp/packed.txt" || fail "$size ft: the compressed file reads other voxels or values"
  "$vola" voxels "$tmp/occupancy$size.vol" | cmp -s - <("$vola" voxels "$tmp/plain$size.vol") ||
    fail "$size ft: the compressed occupancy reads other voxels"
  "$vola" info "$tmp/packed$size.vol" | grep -q "version 2" || fail "$size ft: not a compressed file"
  "$vola" convert "$laz" "$tmp/max$size.vol" --voxel-size "$size" --compress-max > /dev/null
  "$vola" convert "$laz" "$tmp/max_occupancy$size.vol" --voxel-size "$size" --compress-max --no-attributes > /dev/null
  "$vola" voxels --attributes "$tmp/max$size.vol" | cmp -s "$tmp/plain.txt" - ||
    fail "$size ft: the --compress-max file reads other voxels or values"
  "$vola" voxels "$tmp/max_occupancy$size.vol" | cmp -s - <("$vola" voxels "$tmp/plain$size.vol") ||
    fail "$size ft: the --compress-max occupancy reads other voxels"
  "$vola" info "$tmp/max_occupancy$size.vol" | grep -q "occupancy coded by mixed models" ||
    fail "$size ft: vola info does not say the levels are coded by mixed models"
  "$vola" info --json "$tmp/occupancy$size.vol" | grep -q '"level_coding": "occupancy context-coded"' ||
    fail "$size ft: vola info --json does not give the level coding"
  (( $(stat -c %s "$tmp/max_occupancy$size.vol") < $(stat -c %s "$tmp/occupancy$size.vol") )) ||
    fail "$size ft: --compress-max is not smaller than --compress"
done
[ "$(wc -l < "$tmp/plain.txt")" -gt 1000 ] || fail "too few voxels compared"
at_most "$tmp/packed1.vol" 77 100
at_most "$tmp/occupancy1.vol" 113 1000
at_most "$tmp/max1.vol" 68 100
at_most "$tmp/max_occupancy1.vol" 1 10   # the issue's target
echo "cli_compress: ok"
