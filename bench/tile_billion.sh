#!/usr/bin/env bash
# Issue 10's bounded-memory run: a generated survey of POINTS points (default 1e9; city
# blocks of 200 m at 10 points per square metre, generated chunk by chunk and never
# stored) tiled within a --memory budget, timed with peak RSS by /usr/bin/time -v.
# Usage: bench/tile_billion.sh VOLA OUTDIR [POINTS] [MEMORY] [THREADS]
# Example: flock /tmp/vola-cpu.lock bench/tile_billion.sh build/apps/vola/vola /tmp/billion
# Prints the tiler's summary, the wall time and the peak resident set size; the
# baseline RSS of the vola binary alone (the libraries it maps) is
# printed too, so that what the run itself held can be told apart. Removes OUTDIR's
# tiles at the end unless KEEP=1.
set -euo pipefail
vola=$1 out=$2 points=${3:-1000000000} memory=${4:-2G} threads=${5:-0}
rm -rf "$out"
baseline=$(/usr/bin/time -f '%M' "$vola" --version 2>&1 > /dev/null | tail -1)
/usr/bin/time -v "$vola" tile --generate-survey "$points" --tile-size 1024 --depth 6 --assign-crs 32633 \
  --memory "$memory" --threads "$threads" -o "$out" 2> "$out.time" | tee "$out.summary"
peak=$(sed -n 's/.*Maximum resident set size (kbytes): //p' "$out.time")
wall=$(sed -n 's/.*Elapsed (wall clock) time (h:mm:ss or m:ss): //p' "$out.time")
echo "wall clock:     $wall"
echo "peak RSS:       $((peak / 1024)) MiB (budget $memory; the binary alone: $((baseline / 1024)) MiB)"
echo "output:         $(du -sh "$out" | cut -f1) in $(find "$out" -name '*.vol' | wc -l) .vol files"
[ "${KEEP:-0}" = 1 ] || rm -rf "$out"
