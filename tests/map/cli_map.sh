#!/usr/bin/env bash
# vola map end to end: two scans with poses (one turned a quarter about z) give a state
# map whose occupied voxels are the hit ones (what every command reads of it) and the
# passed ones in MAP.free.vol at the expected world places; info, census and get --points
# report the states; bad list lines and missing files are errors naming the line, and
# nothing is written then.
# Usage: cli_map.sh VOLA
set -euo pipefail
vola=$1
source "$(dirname "$0")/../lib/cli_test.sh"

mkdir "$tmp/scans"
printf '1.0 0 0\n' > "$tmp/scans/ahead.xyz"
# Sensor at (0.1, 0.1, 0.1); the second scan turned 90 degrees about z: its (1, 0, 0) is
# the world's (0.1, 1.1, 0.1).
cat > "$tmp/list.txt" <<'LIST'
# file tx ty tz qx qy qz qw
scans/ahead.xyz 0.1 0.1 0.1 0 0 0 1
scans/ahead.xyz 0.1 0.1 0.1 0 0 0.70710678 0.70710678
LIST
"$vola" map "$tmp/list.txt" -o "$tmp/map.vol" --voxel-size 0.25 --free > "$tmp/out" || fail "map: $(cat "$tmp/out")"
grep -q '^scans:   2, 2 points' "$tmp/out" || fail "summary: $(cat "$tmp/out")"
"$vola" coords "$tmp/map.vol" | sort > "$tmp/occupied"
printf '0.125 1.125 0.125\n1.125 0.125 0.125\n' | diff - "$tmp/occupied" || fail "occupied voxels differ"
[ "$("$vola" coords "$tmp/map.free.vol" | wc -l)" -eq 7 ] || fail "expected 7 free voxels: $("$vola" coords "$tmp/map.free.vol")"

# Points no voxel of the map can hold (survey coordinates with a pose at 0, voxels far too
# small) made an empty map with exit 0: now an error, and no file.
printf '5000000 0 0\n' > "$tmp/scans/far.xyz"
echo "scans/far.xyz 0 0 0 0 0 0 1" > "$tmp/far.txt"
"$vola" map "$tmp/far.txt" -o "$tmp/far.vol" --voxel-size 1 > "$tmp/far.out" 2>&1 && fail "a map of nothing succeeded"
grep -q 'no point of the 1 made a known voxel (0 not finite, 1 more than 1048576 voxels of 1 from the world origin)' \
  "$tmp/far.out" || fail "far: $(cat "$tmp/far.out")"
[ -e "$tmp/far.vol" ] && fail "a map of nothing was written"

# A pose far from its points (a scan in survey coordinates, the sensor at 0): 20,000 rays
# of 1 km at 5 cm would cross 4e8 voxels (a minute and 9.8 GB); refused before any work,
# with the distances, unless --max-range bounds the rays.
"${VOLA_PYTHON:-/usr/bin/python3}" -c "
import numpy as np
p = np.random.default_rng(1).uniform(-10, 10, (20000, 3)); p[:, 0] += 1000
np.savetxt('$tmp/scans/distant.xyz', p, fmt='%.3f')"
echo "scans/distant.xyz 0 0 0 0 0 0 1" > "$tmp/distant.txt"
"$vola" map "$tmp/distant.txt" -o "$tmp/distant.vol" --voxel-size 0.05 > "$tmp/distant.out" 2>&1 \
  && fail "a scan 1 km from its sensor at 5 cm was inserted"
grep -q 'line 1: .*distant.xyz: its rays cross up to 4.04e+08 voxels of 0.05, more than --max-ray-voxels 2e+08' \
  "$tmp/distant.out" || fail "distant scan message: $(cat "$tmp/distant.out")"
grep -q 'lie 1000.* on average' "$tmp/distant.out" || fail "distant scan distances: $(cat "$tmp/distant.out")"
"$vola" map "$tmp/distant.txt" -o "$tmp/distant.vol" --voxel-size 0.05 --max-range 5 -q || fail "--max-range did not bound the rays"

# An organized PCD's missing points (NaN) count as points not finite: the reader leaves
# them out, and the summary said "0 not finite".
printf '# .PCD v0.7\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 3\nHEIGHT 1\nPOINTS 3\nDATA ascii\n1 0 0\nnan nan nan\n0 1 0\n' \
  > "$tmp/scans/organized.pcd"
echo "scans/organized.pcd 0.1 0.1 0.1 0 0 0 1" > "$tmp/organized.txt"
"$vola" map "$tmp/organized.txt" -o "$tmp/organized.vol" --voxel-size 0.25 > "$tmp/organized.out" \
  || fail "map of a PCD: $(cat "$tmp/organized.out")"
grep -q '^scans:   1, 3 points (1 not finite' "$tmp/organized.out" || fail "organized PCD: $(cat "$tmp/organized.out")"

# The state map: 9 known voxels; commands see the 2 occupied ones.
"$vola" info "$tmp/map.vol" > "$tmp/info"
grep -q 'state map (vola map): 9 known, .* 2 occupied, 7 free' "$tmp/info" || fail "info: $(cat "$tmp/info")"
"$vola" census "$tmp/map.vol" --json > "$tmp/census.json"
python3 - "$tmp/census.json" <<'PY' || fail "census: $(cat "$tmp/census.json")"
import json, sys
c = json.load(open(sys.argv[1]))
assert c["voxels"] == 2 and c["states"]["occupied"] == 2 and c["states"]["free"] == 7, c
# the known voxels span 5 x 5 x 1 cells: 25 - 9 unknown
assert c["states"]["unknown_in_bounds"] == 16, c
PY
[ "$("$vola" voxels "$tmp/map.vol" | wc -l)" -eq 2 ] || fail "voxels: $("$vola" voxels "$tmp/map.vol")"
"$vola" union "$tmp/map.vol" "$tmp/map.free.vol" "$tmp/union.vol" > /dev/null
[ "$("$vola" coords "$tmp/union.vol" | wc -l)" -eq 9 ] || fail "union of occupied and free: $("$vola" coords "$tmp/union.vol")"
"$vola" get "$tmp/map.vol" 4 0 0 | grep -q '^voxel 4 0 0: occupied' || fail "get of an occupied voxel"
"$vola" get "$tmp/map.vol" 2 0 0 | grep -q '^voxel 2 0 0: free' || fail "get of a free voxel"

# get --points: one line per point; P from the log-odds (one hit: 0.7; one miss: 0.4;
# the sensor's voxel, passed by both scans: 1 / (1 + 1.5^2)).
printf '1.1 0.1 0.1
0.6 0.1 0.1

0.1 0.1 0.1
5 5 5
-1 0 0
' > "$tmp/points.txt"
"$vola" get "$tmp/map.vol" --world --points "$tmp/points.txt" > "$tmp/states"
printf 'occupied 0.7000
free 0.4000
free 0.3077
unknown
unknown
' | diff - "$tmp/states" || fail "get --points"
"$vola" get "$tmp/map.free.vol" --world --points "$tmp/points.txt" > "$tmp/plain"
printf 'free
occupied
occupied
free
free
' | diff - "$tmp/plain" || fail "get --points on a plain tree"
printf '1 2 3
1 2
' > "$tmp/bad_points.txt"
"$vola" get "$tmp/map.vol" --world --points "$tmp/bad_points.txt" 2> "$tmp/err" && fail "a bad point line was accepted"
grep -q 'bad_points.txt: line 2: expected three finite numbers' "$tmp/err" || fail "message: $(cat "$tmp/err")"
# Without --world the points are voxel coordinates: one outside the grid (world coordinates
# given without --world, all answered "free") is refused, as the single-point form refuses it.
printf '1 2 3\n-0.5 0 0\n' > "$tmp/off_grid.txt"
"$vola" get "$tmp/map.vol" --points "$tmp/off_grid.txt" 2> "$tmp/err" && fail "a point outside the grid was answered"
grep -q 'off_grid.txt: point 2 (-0.5, 0, 0) is not a voxel coordinate in 0\.\..* (use --world for CRS coordinates)' "$tmp/err" ||
  fail "message: $(cat "$tmp/err")"

# collide on the state map: along the known free voxels, free; into space never seen,
# free of occupied voxels but said to pass through unknown space.
out=$("$vola" collide "$tmp/map.vol" --segment 0.125 0.125 0.125 0.875 0.125 0.125) || fail "collide along known free voxels"
[ "$out" = "free: no occupied voxel on the segment" ] || fail "collide along known space: $out"
out=$("$vola" collide "$tmp/map.vol" --segment 0.125 0.125 0.125 0.375 0.375 0.125) || fail "collide into unknown space"
echo "$out" | grep -q '^free: .*passes through 1 voxel the map has not seen (unknown space' || fail "collide into unknown space: $out"
# Spheres and boxes too (they answered "free" in unknown space without a word).
out=$("$vola" collide "$tmp/map.vol" --sphere 0.625 0.125 0.125 0.05) || fail "sphere in known free space"
[ "$out" = "free: no occupied voxel within the radius" ] || fail "sphere in known space: $out"
out=$("$vola" collide "$tmp/map.vol" --sphere 0.375 0.375 0.125 0.05) || fail "sphere in unknown space"
echo "$out" | grep -q '^free: no occupied voxel within the radius, but it reaches 1 voxel the map has not seen' ||
  fail "sphere in unknown space: $out"
out=$("$vola" collide "$tmp/map.vol" --box 0.3 0.3 0.05 0.45 0.45 0.2) || fail "box in unknown space"
echo "$out" | grep -q '^free: no occupied voxel overlaps the box, but it reaches 1 voxel the map has not seen' ||
  fail "box in unknown space: $out"

# Commands that write a plain tree of a state map's occupied voxels say what is lost.
"$vola" dilate "$tmp/map.vol" "$tmp/dilated.vol" --radius 1 -q 2> "$tmp/err" || fail "dilate a state map"
grep -q "map.vol is a state map (occupied, free and unknown space): vola dilate writes its occupied voxels only" \
  "$tmp/err" || fail "dilate of a state map kept quiet: $(cat "$tmp/err")"
"$vola" lod "$tmp/map.vol" --depth 1 "$tmp/coarse.vol" -q 2> "$tmp/err" || fail "lod of a state map"
grep -q "vola lod writes its occupied voxels only" "$tmp/err" || fail "lod of a state map kept quiet: $(cat "$tmp/err")"

# plan on the state map: unknown space is an obstacle by default. Along x the known free
# voxels lead from the sensor's voxel to (0.875, 0.125); (0.375, 0.375) was never seen.
"$vola" plan "$tmp/map.vol" --from 0.125 0.125 0.125 --to 0.875 0.125 0.125 -o "$tmp/path.csv" -q \
  || fail "plan along known free voxels"
"$vola" plan "$tmp/map.vol" --from 0.125 0.125 0.125 --to 0.375 0.375 0.125 -o "$tmp/path.csv" 2> "$tmp/err" \
  && fail "a goal in unknown space was accepted"
grep -q 'goal .* is inside an obstacle or unknown space' "$tmp/err" || fail "message: $(cat "$tmp/err")"
"$vola" plan "$tmp/map.vol" --from 0.125 0.125 0.125 --to 0.375 0.375 0.125 -o "$tmp/path.csv" -q --unknown free \
  || fail "plan with --unknown free"
"$vola" plan "$tmp/map.free.vol" --from 0.125 0.125 0.125 --to 0.375 0.375 0.125 --unknown occupied \
  -o "$tmp/path.csv" 2> "$tmp/err" && fail "--unknown occupied on a plain .vol was accepted"
grep -q 'is not a state map' "$tmp/err" || fail "message: $(cat "$tmp/err")"

# Errors name the line; no output file appears.
printf 'scans/ahead.xyz 0 0 0 0 0 0 1\nscans/ahead.xyz 0 0 zero 0 0 0 1\n' > "$tmp/bad.txt"
"$vola" map "$tmp/bad.txt" -o "$tmp/bad.vol" --voxel-size 0.25 2> "$tmp/err" && fail "a bad pose was accepted"
grep -q 'line 2: tz is not a finite number' "$tmp/err" || fail "message: $(cat "$tmp/err")"
printf 'scans/ahead.xyz 0 0 0 0 0 0 1\nscans/missing.xyz 0 0 0 0 0 0 1\n' > "$tmp/missing.txt"
"$vola" map "$tmp/missing.txt" -o "$tmp/bad.vol" --voxel-size 0.25 2> "$tmp/err" && fail "a missing scan was accepted"
grep -q 'line 2: .*missing.xyz' "$tmp/err" || fail "message: $(cat "$tmp/err")"
[ ! -e "$tmp/bad.vol" ] || fail "a failed run wrote its output"
ls "$tmp" | grep -q '\.part$' && fail "a temporary was left behind"
echo "cli_map: ok"
