#!/usr/bin/env bash
# vola collide end to end: a hand-made scene whose answers are known (grid and world
# coordinates, touching rules, exit statuses, errors), then the Autzen survey, where every
# voxel a segment reports is checked with `vola get`.
# Usage: cli_collide.sh VOLA SHARED_DATA_DIR   ($VOLA_SHARED/data, when set, wins)
set -euo pipefail
vola=$1 data=${VOLA_SHARED:+$VOLA_SHARED/data}
data=${data:-$2}
source "$(dirname "$0")/../lib/cli_test.sh"

# expect STATUS OUTPUT_PATTERN ARGS...: runs vola collide, checks the exit status and output
# (STATUS "usage": any status CLI11 gives a usage error, i.e. not 0, 1 or 3).
expect() {
  local want=$1 pattern=$2 status=0
  shift 2
  "$vola" collide "$@" > "$tmp/out" 2>&1 || status=$?
  if [ "$want" = usage ]; then case $status in 0 | 1 | 3) ;; *) status=usage ;; esac; fi
  [ "$status" = "$want" ] || fail "collide $*: exit $status, expected $want: $(cat "$tmp/out")"
  grep -Eq -- "$pattern" "$tmp/out" || fail "collide $*: output '$(cat "$tmp/out")' does not match '$pattern'"
}

# The scene: a wall of voxels x = 8 (every y, z in 0..15) and one voxel (2, 2, 2), in a
# 16^3 grid whose voxel (0, 0, 0) has its corner at world (100, 200, 10), voxels of 2.
{
  for y in $(seq 0 15); do for z in $(seq 0 15); do
    echo "$((100 + 2 * 8 + 1)) $((200 + 2 * y + 1)) $((10 + 2 * z + 1))"
  done; done
  echo "105 205 15"
  echo "131 231 41"  # voxel (15, 15, 15) so that the grid keeps 16 voxels per side
} > "$tmp/wall.xyz"
"$vola" convert "$tmp/wall.xyz" "$tmp/wall.vol" --voxel-size 2 --origin 100 200 10 --depth 2 -q

# Segments: the first voxel, where it is entered, how far, through which face.
expect 3 '^hit: voxel 8 0 0, entered at 116 201 11 \(world\), 15 world units from the start through face -1 0 0$' \
  "$tmp/wall.vol" --segment 101 201 11 131 201 11
expect 3 '^hit: voxel 8 10 10, entered at 8 10.5 10.5 \(grid\), 7.5 voxels from the start through face -1 0 0$' \
  "$tmp/wall.vol" --grid --segment 0.5 10.5 10.5 14.5 10.5 10.5
expect 3 '^hit: voxel 8 3 4, entered at 9 3.5 4.5 \(grid\), 5.5 voxels from the start through face 1 0 0$' \
  "$tmp/wall.vol" --grid --segment 14.5 3.5 4.5 0.5 3.5 4.5
# A segment 1e300 long: the distance is still 7.5 (its squared length overflowed to inf).
expect 3 '^hit: voxel 8 10 10, entered at 8 10.5 10.5 \(grid\), 7.5 voxels from the start through face -1 0 0$' \
  "$tmp/wall.vol" --grid --segment 0.5 10.5 10.5 1e300 10.5 10.5
expect 0 '^free: no occupied voxel on the segment$' "$tmp/wall.vol" --grid --segment 0.5 10.5 10.5 7.9 10.5 10.5
expect 0 '^free' "$tmp/wall.vol" --segment 101 231 41 115.9 221 31
expect 3 '^hit: the segment starts inside voxel 2 2 2$' "$tmp/wall.vol" --grid --segment 2.5 2.5 2.5 2.5 2.5 5.5
expect 3 '^hit: the segment starts inside voxel 2 2 2$' "$tmp/wall.vol" --segment 105 205 15 101 201 11
# A segment of no length (a robot standing still) is its point.
expect 3 '^hit: the segment starts inside voxel 2 2 2$' "$tmp/wall.vol" --grid --segment 2.5 2.5 2.5 2.5 2.5 2.5
expect 0 '^free: no occupied voxel on the segment$' "$tmp/wall.vol" --grid --segment 3.5 2.5 2.5 3.5 2.5 2.5
expect 0 '^free' "$tmp/wall.vol" --segment 1 2 3 1 2 3
# Segments outside the grid, or crossing into it.
expect 0 '^free' "$tmp/wall.vol" --grid --segment -5 -5 -5 -1 20 20
expect 3 '^hit: voxel 8 5 5, entered at 8 5.5 5.5' "$tmp/wall.vol" --grid --segment -20 5.5 5.5 30 5.5 5.5

# Spheres: touching counts. The wall's face x = 8 is 1.5 voxels (3 world units) away.
expect 0 '^free: no occupied voxel within the radius$' "$tmp/wall.vol" --grid --sphere 6.5 10.5 10.5 1.49
expect 3 '^hit: an occupied voxel is within the radius$' "$tmp/wall.vol" --grid --sphere 6.5 10.5 10.5 1.5
expect 0 '^free' "$tmp/wall.vol" --sphere 113 221 31 2.9
expect 3 '^hit' "$tmp/wall.vol" --sphere 113 221 31 3
expect 3 '^hit' "$tmp/wall.vol" --grid --sphere 2.5 2.5 2.5 0

# Boxes: interiors must overlap; a box touching the wall's face is free.
expect 0 '^free: no occupied voxel overlaps the box$' "$tmp/wall.vol" --grid --box 3 3 3 8 15 15
expect 3 '^hit: an occupied voxel overlaps the box$' "$tmp/wall.vol" --grid --box 3 3 3 8.1 15 15
expect 0 '^free' "$tmp/wall.vol" --box 106 206 16 116 240 50
expect 3 '^hit' "$tmp/wall.vol" --box 106 206 16 116.2 240 50
expect 3 '^hit' "$tmp/wall.vol" --box 104 204 14 106 206 16

# --quiet answers by the exit status alone.
status=0
"$vola" collide "$tmp/wall.vol" --grid --sphere 6.5 10.5 10.5 2 -q > "$tmp/out" || status=$?
[ "$status" = 3 ] && [ ! -s "$tmp/out" ] || fail "--quiet: exit $status, output '$(cat "$tmp/out")'"

# Errors: exit 1 with a message that says what is wrong; usage errors are CLI11's.
expect 1 'exactly one of --segment, --sphere or --box' "$tmp/wall.vol"
expect 1 'exactly one of --segment, --sphere or --box' "$tmp/wall.vol" --sphere 1 1 1 1 --box 0 0 0 1 1 1
expect 1 'min <= max' "$tmp/wall.vol" --box 5 0 0 4 1 1
expect 1 'radius must be finite and >= 0' "$tmp/wall.vol" --sphere 1 1 1 -1
expect 1 'radius must be finite and >= 0' "$tmp/wall.vol" --sphere 1 1 1 inf
expect usage 'At least 6 required' "$tmp/wall.vol" --segment 1 2 3 4 5
printf 'VOLA but not really' > "$tmp/bad.vol"
expect 1 'bad.vol' "$tmp/bad.vol" --sphere 1 1 1 1

# A real survey: vertical segments over a grid of points, each hit checked with vola get;
# a segment high above the survey and a box around all of it.
las=$data/las/pdal_autzen_trim.las
[ -f "$las" ] || skip "no shared data in $data"
"$vola" convert "$las" "$tmp/autzen.vol" --voxel-size 2 -q
hits=0
for x in 636100 636400 636700 637000; do
  for y in 849000 849200 849400; do
    status=0
    "$vola" collide "$tmp/autzen.vol" --segment "$x.5" "$y.5" 900 "$x.5" "$y.5" 300 > "$tmp/out" || status=$?
    [ "$status" = 0 ] && continue
    [ "$status" = 3 ] || fail "survey segment at $x $y: exit $status"
    read -r i j k < <(sed -E 's/^hit: voxel ([0-9]+) ([0-9]+) ([0-9]+),.*/\1 \2 \3/' "$tmp/out")
    "$vola" get "$tmp/autzen.vol" "$i" "$j" "$k" | grep -qi 'occupied' || fail "survey: voxel $i $j $k is not occupied"
    # The voxel below the top of the hit voxel's column is the first: nothing above it.
    "$vola" collide "$tmp/autzen.vol" --grid --segment "$i.5" "$j.5" 1023.9 "$i.5" "$j.5" "$((k + 1)).01" -q \
      || fail "survey: something above the first hit $i $j $k"
    hits=$((hits + 1))
  done
done
[ "$hits" -ge 6 ] || fail "only $hits of 12 vertical segments hit the survey's ground"
expect 0 '^free' "$tmp/autzen.vol" --segment 636000 848934 1500 637100 849400 1500
expect 3 '^hit' "$tmp/autzen.vol" --box 636000 848934 406 637200 849500 521
echo "cli_collide: ok ($hits survey hits checked)"
