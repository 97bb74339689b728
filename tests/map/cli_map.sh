#!/usr/bin/env bash
# vola map end to end: two scans with poses (one turned a quarter about z) give the hit
# voxels in MAP.vol and the passed ones in MAP.free.vol at the expected world places; bad
# list lines and missing files are errors naming the line, and nothing is written then.
# Usage: cli_map.sh VOLA
set -euo pipefail
vola=$1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

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
