#!/usr/bin/env bash
# A re-tile killed by SIGKILL once some of its tiles exist: the old tile set still reads
# as it did (its index and every file it names unchanged, the same answers), and the next
# run removes the killed run's spill folder and its unfinished generation, then switches
# to its own tiles and removes the old ones.
# Usage: cli_tile_killed.sh VOLA
set -euo pipefail
vola=$1
source "$(dirname "$0")/../lib/cli_test.sh"
pid=
trap '[ -n "$pid" ] && kill -9 "$pid" 2> /dev/null; rm -rf "$tmp"' EXIT
out=$tmp/tiles
common=(--tile-size 200 --depth 5 -o "$out" --threads 1 -q)

# The old set. Its answers and the checksums of the index and of every file it names.
"$vola" tile --generate-survey 200000 --seed 1 "${common[@]}"
index=$out/index.geojson
named() { python3 -c "
import json, sys
v = json.load(open(sys.argv[1]))
for f in v['features']: print(f['properties']['file'])
for o in v['vola']['overviews']: print(o['file'])" "$1"; }
first=$(named "$index" | sed -n 1p)
read -r x y z < <("$vola" coords "$out/$first" 2> /dev/null | sed -n 2p)
probe() { "$vola" get "$index" "$x" "$y" "$z" && "$vola" get "$index" 500150 5000150 100; }
probe > "$tmp/before.txt"
grep -q ": occupied$" "$tmp/before.txt" || fail "the probe voxel is not occupied: $(cat "$tmp/before.txt")"
sums() { (cd "$out" && sha256sum index.geojson $(named index.geojson)); }
sums > "$tmp/sums.txt"

# A re-tile of another survey, killed once it has written a few tiles.
"$vola" tile --generate-survey 40000000 --seed 2 "${common[@]}" --memory 64M &
pid=$!
written=0
for _ in $(seq 1 1200); do
  written=$(find "$out" -name 'tile_*.vol' -newer "$tmp/sums.txt" 2> /dev/null | wc -l)
  [ "$written" -ge 3 ] && break
  kill -0 "$pid" 2> /dev/null || fail "the re-tile ended before it was killed"
  sleep 0.1
done
[ "$written" -ge 3 ] || fail "the re-tile wrote no tiles in 120 s"
kill -9 "$pid"
wait "$pid" 2> /dev/null || true
killed=$pid
pid=
ls -d "$out/.spill/"rank-*-"$killed" > /dev/null 2>&1 || fail "a killed run should leave its spill folder (test premise)"

# The old set is intact and answers the same.
(cd "$out" && sha256sum --quiet -c "$tmp/sums.txt") || fail "the killed re-tile changed files of the old set"
probe > "$tmp/after.txt"
diff "$tmp/before.txt" "$tmp/after.txt" > /dev/null || fail "the old set answers differently after the kill"
"$vola" render "$index" --size 80x60 -o "$tmp/view.png" > /dev/null || fail "the old set no longer renders"

# The next run cleans up after the killed one, switches, and retires the old files.
"$vola" tile --generate-survey 100000 --seed 3 "${common[@]}"
[ -z "$(ls -A "$out/.spill" 2> /dev/null)" ] || fail "stale spill left: $(ls "$out/.spill")"
python3 -c "import json, sys; v = json.load(open(sys.argv[1])); assert v['vola']['points_in'] == 100000, v['vola']" \
  "$index" || fail "the new index is not the last run's"
while read -r file; do
  [ -f "$out/$file" ] || fail "the new index names a missing $file"
done < <(named "$index")
while read -r _ file; do
  [ "$file" = index.geojson ] && continue
  [ ! -e "$out/$file" ] || named "$index" | grep -qx "$file" || fail "old file $file left behind"
done < "$tmp/sums.txt"
generations=$(find "$out" -maxdepth 1 -name '.generation-*' | wc -l)
[ "$generations" = 1 ] || fail "$generations generation folders, expected 1: $(ls -a "$out")"
"$vola" get "$index" 500150 5000150 100 > /dev/null || fail "the new set does not answer"
echo "cli_tile_killed: OK"
