#!/usr/bin/env bash
# vola plan --avoid end to end: a reactive flight around an obstacle arrives, and every
# position it writes is checked with vola collide --sphere; a goal behind a wall that
# fills the grid cannot be reached and says so.
# Usage: cli_avoid.sh VOLA
set -euo pipefail
vola=$1
source "$(dirname "$0")/../lib/cli_test.sh"

# A 64^3 grid: a 9x9 pillar (x, y in [28, 37), every z) and the far corner voxel.
/usr/bin/env python3 - "$tmp/pillar.xyz" <<'PY'
import sys
with open(sys.argv[1], "w") as f:
    for x in range(28, 37):
        for y in range(28, 37):
            for z in range(64):
                f.write(f"{x + 0.5} {y + 0.5} {z + 0.5}\n")
    f.write("63.5 63.5 63.5\n")
PY
"$vola" convert "$tmp/pillar.xyz" "$tmp/pillar.vol" --voxel-size 1 --origin 0 0 0 --depth 3 -q

# Straight through the pillar's axis: the agent must go round it.
"$vola" collide "$tmp/pillar.vol" --grid --segment 10 32 20 55 32 20 -q && fail "the straight line should be blocked"
"$vola" plan "$tmp/pillar.vol" --grid --avoid --from 10 32 20 --to 55 32 20 --radius 1.5 --speed 0.5 \
  -o "$tmp/flight.csv" > "$tmp/out" || fail "no arrival: $(cat "$tmp/out")"
grep -Eq '^[0-9]+ steps to the goal' "$tmp/out" || fail "unexpected output: $(cat "$tmp/out")"
rows=$(tail -n +2 "$tmp/flight.csv" | wc -l)
[ "$rows" -gt 90 ] || fail "only $rows positions for a 45-voxel flight at 0.5 per step"
tail -n 1 "$tmp/flight.csv" | awk -F, '{d = ($1-55)^2 + ($2-32)^2 + ($3-20)^2; exit !(d <= 0.25)}' ||
  fail "the last position is not at the goal: $(tail -n 1 "$tmp/flight.csv")"
# Positions keep the agent's sphere clear (every 8th, to keep the test short; the library
# test checks every step exactly).
tail -n +2 "$tmp/flight.csv" | awk 'NR % 8 == 1' | while IFS=, read -r x y z; do
  "$vola" collide "$tmp/pillar.vol" --grid --sphere "$x" "$y" "$z" 1.5 -q || fail "position $x $y $z collides"
done

# A wall that fills the grid: the agent stops short of it, exit 1 with the reason.
/usr/bin/env python3 - "$tmp/wall.xyz" <<'PY'
import sys
with open(sys.argv[1], "w") as f:
    for y in range(16):
        for z in range(16):
            f.write(f"8.5 {y + 0.5} {z + 0.5}\n")
PY
"$vola" convert "$tmp/wall.xyz" "$tmp/wall.vol" --voxel-size 1 --origin 0 0 0 --depth 2 -q
status=0
"$vola" plan "$tmp/wall.vol" --grid --avoid --from 3 8 8 --to 13 8 8 --radius 1 --max-steps 300 -o "$tmp/stuck.csv" \
  2> "$tmp/err" || status=$?
[ "$status" = 1 ] && grep -q 'did not reach the goal' "$tmp/err" || fail "stuck flight: exit $status, $(cat "$tmp/err")"
tail -n +2 "$tmp/stuck.csv" | awk -F, '$1 > 7.0 {bad = 1} END {exit bad}' || fail "the stuck agent crossed x = 7"
# Starting inside an obstacle is an error.
"$vola" plan "$tmp/wall.vol" --grid --avoid --from 8.5 8 8 --to 13 8 8 -o "$tmp/x.csv" 2> "$tmp/err" && fail "inside"
grep -q 'touches an occupied voxel' "$tmp/err" || fail "inside: $(cat "$tmp/err")"
echo "cli_avoid: ok"
