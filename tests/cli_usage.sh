#!/usr/bin/env bash
# The command line as a newcomer meets it: a mistyped subcommand gets the nearest one,
# an unknown word no false suggestion, and a real subcommand still runs.
# Usage: cli_usage.sh VOLA
set -euo pipefail
vola=$1
source "$(dirname "$0")/lib/cli_test.sh"

expect_suggestion() {  # WORD SUGGESTION
  if "$vola" "$1" a b 2> "$tmp/err.txt"; then fail "'$1' ran"; fi
  grep -q "'$1' is not a vola subcommand; did you mean '$2'?" "$tmp/err.txt" || fail "'$1': $(cat "$tmp/err.txt")"
}
expect_suggestion convrt convert
expect_suggestion tiles tile
expect_suggestion transalte translate
expect_suggestion inf info
if "$vola" xyzzy 2> "$tmp/err.txt"; then fail "'xyzzy' ran"; fi
grep -q "'xyzzy' is not a vola subcommand (vola --help" "$tmp/err.txt" || fail "xyzzy: $(cat "$tmp/err.txt")"
# Another tool's word for what a subcommand does: where it is.
"$vola" raster a.vol out.tif 2> "$tmp/err.txt" && fail "vola raster ran"
grep -q "'raster' is not a vola subcommand; use vola export FILE.vol OUT.tif --raster dsm" "$tmp/err.txt" ||
  fail "raster: $(cat "$tmp/err.txt")"
"$vola" info --help > /dev/null || fail "vola info --help failed"

# A mistyped option gets the nearest of its subcommand's options, in one line: CLI11's
# "arguments were not expected" said the same thing again before it.
printf '0 0 0\n1000 0 0\n' > "$tmp/pair.xyz"
expect_option_suggestion() {  # SUBCOMMAND WRONG RIGHT ARGS...
  local command=$1 wrong=$2 right=$3
  shift 3
  if "$vola" "$command" "$@" 2> "$tmp/err.txt"; then fail "'$wrong' ran"; fi
  grep -qF -- "'$wrong' is not an option of vola $command; did you mean '$right'?" "$tmp/err.txt" ||
    fail "'$wrong': $(cat "$tmp/err.txt")"
  [ "$(wc -l < "$tmp/err.txt")" -eq 1 ] || fail "'$wrong' said more than one line: $(cat "$tmp/err.txt")"
}
expect_option_suggestion convert --voxelsize --voxel-size "$tmp/pair.xyz" "$tmp/o.vol" --voxelsize 3
expect_option_suggestion convert --voxel_size --voxel-size "$tmp/pair.xyz" "$tmp/o.vol" --voxel_size=3
expect_option_suggestion info --jsn --json "$tmp/pair.xyz" --jsn
if "$vola" convert "$tmp/pair.xyz" "$tmp/o.vol" --xyzzy 3 2> "$tmp/err.txt"; then fail "--xyzzy ran"; fi
grep -qF -- "'--xyzzy' is not an option of vola convert (vola convert --help lists them)" "$tmp/err.txt" ||
  fail "--xyzzy: $(cat "$tmp/err.txt")"

# A number out of range is named with what the option wants, not with the bounds of a
# double printed in full (CLI11's PositiveNumber); the voxel size in %g, not "0.000000".
printf '0 0 0\n1000 0 0\n' > "$tmp/two.xyz"
expect_refusal() {  # EXPECTED-TEXT ARGS...
  local expected=$1
  shift
  if "$vola" "$@" 2> "$tmp/err.txt"; then fail "'$*' ran"; fi
  grep -qF -- "$expected" "$tmp/err.txt" || fail "'$*': $(cat "$tmp/err.txt")"
  if grep -q "179769313486" "$tmp/err.txt"; then fail "'$*' printed DBL_MAX: $(cat "$tmp/err.txt")"; fi
}
expect_refusal "--voxel-size: must be a positive finite number, not 0" convert "$tmp/two.xyz" "$tmp/o.vol" --voxel-size 0
expect_refusal "--voxel-size: must be a positive finite number, not -2" convert "$tmp/two.xyz" "$tmp/o.vol" --voxel-size -2
expect_refusal "--compress-max: compressed files are sparse, not --dense" convert "$tmp/two.xyz" "$tmp/o.vol" --voxel-size 1 --compress-max --dense
expect_refusal "'abc' is not a number" convert "$tmp/two.xyz" "$tmp/o.vol" --voxel-size abc
"$vola" convert "$tmp/two.xyz" "$tmp/ok.vol" --voxel-size 10 -q || fail "a valid conversion failed"
expect_refusal "--radius: must be a finite number of 0 or more, not -1" plan "$tmp/ok.vol" --from 0 0 0 --to 1 1 1 --radius -1
expect_refusal "at voxel size 1e-09 needs 1e+12 voxels per axis" convert "$tmp/two.xyz" "$tmp/o.vol" --voxel-size 1e-9

# A grid the flags fix must hold the points, never drop them without a word (a survey
# lost 27% of its points to --voxel-size 1 --depth 5 with exit code 0).
expect_refusal "--depth: 2 makes a grid of 16 voxels of 10 a side, 160 from the origin" convert "$tmp/two.xyz" "$tmp/o.vol" --voxel-size 10 --depth 2
expect_refusal "reaches 1000 along x; depth 4 holds it" convert "$tmp/two.xyz" "$tmp/o.vol" --voxel-size 10 --depth 2
expect_refusal "--origin: x = 5 lies above the minimum 0" convert "$tmp/two.xyz" "$tmp/o.vol" --voxel-size 10 --origin 5 0 0
"$vola" convert "$tmp/two.xyz" "$tmp/crop.vol" --voxel-size 10 --depth 2 --origin 0 0 0 --bbox 0 0 0 100 100 100 -q ||
  fail "a bbox inside the grid did not crop"

# convert writes a .vol: not over its input, not under another format's name.
cp "$tmp/two.xyz" "$tmp/same.xyz"
expect_refusal "is the input: convert writes a new .vol file" convert "$tmp/same.xyz" "$tmp/same.xyz" --voxel-size 1
cmp -s "$tmp/two.xyz" "$tmp/same.xyz" || fail "a refused conversion changed its input"
expect_refusal "convert writes a .vol file, not las (.las); name it .vol, or write points with \`vola translate" convert "$tmp/two.xyz" "$tmp/o.las" --voxel-size 1
if [[ -e $tmp/o.las ]]; then fail "a refused conversion wrote o.las"; fi
# A PLY with faces is a mesh: translate says so (it said "this is ply input").
printf 'ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n' > "$tmp/tri.ply"
expect_refusal "this ply file holds a mesh of 1 face: \`vola convert\` makes voxels of it" translate "$tmp/tri.ply" "$tmp/tri.xyz"
echo "cli usage: ok"
