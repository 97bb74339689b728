#!/usr/bin/env bash
# The C API test on a scratch directory, plus a real survey converted by the CLI (a file
# with attribute columns), and a ROS map converted by the C API's vola_convert_file with
# map_height as the CLI converts it with --map-height.
# Usage: run_capi.sh TEST_CAPI VOLA_CLI DEFAULT_DATA_DIR CONVERT_TOOL
set -euo pipefail
test_capi=$1 vola=$2 convert_tool=$4 data=${VOLA_SHARED:+$VOLA_SHARED/data}
data=${data:-$3}  # VOLA_SHARED wins over the configured default
source "$(dirname "$0")/../lib/cli_test.sh"
scratch=$tmp
las=$data/las/pdal_1.2-with-color.las
las_with_crs=$data/las/pdal_autzen-utm.las
[ -f "$las" ] && [ -f "$las_with_crs" ] || skip "$las or $las_with_crs missing (set VOLA_SHARED)"
"$vola" convert "$las" "$scratch/survey.vol" --voxel-size 5 --quiet
# A state map of one scan: a wall 2 m ahead seen from the origin (free voxels before it).
for y in 0 0.1 0.2 0.3; do for z in 0 0.1 0.2; do echo "2.0 $y $z"; done; done > "$scratch/wall.xyz"
echo "$scratch/wall.xyz 0 0 0 0 0 0 1" > "$scratch/scans.txt"
"$vola" map "$scratch/scans.txt" -o "$scratch/map.vol" --voxel-size 0.1 -q
occupied=$("$vola" voxels "$scratch/map.vol" | grep -vc '^#')
"$test_capi" "$scratch" "$scratch/survey.vol" "$las_with_crs" "$scratch/map.vol" "$occupied"
"$vola" export "$scratch/map.vol" "$scratch/map.yaml" --band 0:0.3 -q
"$vola" convert "$scratch/map.yaml" "$scratch/cli_columns.vol" --map-height 0.3 -q
"$convert_tool" "$scratch/map.yaml" "$scratch/c_columns.vol" map_height=0.3
cmp -s "$scratch/cli_columns.vol" "$scratch/c_columns.vol" || fail "map_height: the C API wrote other bytes than --map-height"
"$vola" convert "$scratch/map.yaml" "$scratch/cli_cells.vol" -q
cmp -s "$scratch/cli_columns.vol" "$scratch/cli_cells.vol" && fail "map_height changed nothing"
true
