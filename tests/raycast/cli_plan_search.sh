#!/usr/bin/env bash
# vola plan picks its search: start and goal 1024 voxels apart or more plan hierarchically
# (with a note; --exact forces the optimal search), closer ones exactly; --exact and
# --hierarchical together are refused. Both searches' legs cross no voxel (vola collide
# --segment; clearance at the radius is tests/raycast/test_path_planner.cpp's), and their
# path lengths agree within 1%.
# Usage: cli_plan_search.sh VOLA
set -euo pipefail
vola=$1
source "$(dirname "$0")/../lib/cli_test.sh"

# A 1.5 m-voxel wall across a 2048-voxel-long box (grid of depth 6: 4096 voxels a side),
# with a gap near one end, and the far corner so the grid spans the run.
/usr/bin/env python3 - "$tmp/wall.xyz" <<'PY'
import sys
with open(sys.argv[1], "w") as f:
    for y in range(0, 40):
        if 30 <= y < 34:
            continue  # the gap
        for z in range(0, 8):
            f.write(f"1000.5 {y + 0.5} {z + 0.5}\n")
    f.write("2047.5 39.5 7.5\n")
PY
"$vola" convert "$tmp/wall.xyz" "$tmp/wall.vol" --voxel-size 1 --origin 0 0 0 --depth 6 -q

"$vola" plan "$tmp/wall.vol" --from 2.5 5.5 2.5 --to 2040.5 5.5 2.5 --radius 0.5 -o "$tmp/auto.csv" > "$tmp/auto.out" \
  || fail "the far plan failed"
grep -q "searching hierarchically" "$tmp/auto.out" || fail "points 2038 voxels apart did not plan hierarchically"
"$vola" plan "$tmp/wall.vol" --from 2.5 5.5 2.5 --to 2040.5 5.5 2.5 --radius 0.5 --exact -o "$tmp/exact.csv" \
  > "$tmp/exact.out" || fail "the exact plan failed"
grep -q "searching hierarchically" "$tmp/exact.out" && fail "--exact searched hierarchically"
"$vola" plan "$tmp/wall.vol" --from 2.5 5.5 2.5 --to 900.5 5.5 2.5 --radius 0.5 -o "$tmp/near.csv" > "$tmp/near.out" \
  || fail "the near plan failed"
grep -q "searching hierarchically" "$tmp/near.out" && fail "points 898 voxels apart planned hierarchically"
"$vola" plan "$tmp/wall.vol" --from 2.5 5.5 2.5 --to 2040.5 5.5 2.5 --exact --hierarchical 2> "$tmp/err" \
  && fail "--exact with --hierarchical was accepted"
grep -q "exclude" "$tmp/err" || fail "the refusal does not say the flags exclude each other: $(cat "$tmp/err")"
# A goal far outside the grid is refused as such, with no note of a search by its distance first.
"$vola" plan "$tmp/wall.vol" --from 2.5 5.5 2.5 --to 1e300 5.5 2.5 -o "$tmp/far.csv" > "$tmp/far.out" 2> "$tmp/err" \
  && fail "a goal at x = 1e300 was accepted"
grep -q "outside the volume" "$tmp/err" || fail "the far goal's refusal: $(cat "$tmp/err")"
grep -q "searching hierarchically" "$tmp/far.out" && fail "a goal outside the grid got a note about its distance"

# Every leg crosses no voxel, and the two lengths are within 1%.
for path in auto exact; do
  /usr/bin/env python3 - "$tmp/$path.csv" > "$tmp/$path.legs" <<'PY'
import sys
rows = [tuple(map(float, l.split(","))) for l in open(sys.argv[1]).read().split()[1:]]
for a, b in zip(rows, rows[1:]):
    print("--segment", *a, *b)
PY
  while read -r _ x0 y0 z0 x1 y1 z1; do
    "$vola" collide "$tmp/wall.vol" --segment "$x0" "$y0" "$z0" "$x1" "$y1" "$z1" -q \
      || fail "$path leg $x0 $y0 $z0 -> $x1 $y1 $z1 hits a voxel"
  done < "$tmp/$path.legs"
done
/usr/bin/env python3 - "$tmp/auto.csv" "$tmp/exact.csv" <<'PY' || fail "the hierarchical path is more than 1% longer"
import math, sys
def length(p):
    rows = [tuple(map(float, l.split(","))) for l in open(p).read().split()[1:]]
    return sum(math.dist(a, b) for a, b in zip(rows, rows[1:]))
auto, exact = length(sys.argv[1]), length(sys.argv[2])
print(f"hierarchical {auto:.3f}, exact {exact:.3f}")
sys.exit(0 if auto <= exact * 1.01 + 1e-9 else 1)
PY
echo "cli_plan_search: ok"
