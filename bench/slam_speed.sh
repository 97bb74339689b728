#!/usr/bin/env bash
# Tracking + fusion speed of vola fuse for docs/BENCHMARKS.md (issue 25's 15 frames/s at
# 320 x 240 and 5 at 640 x 480 on two cores): two generated 60-frame sequences of the
# room loop at 1.2 degrees per frame, fused alternately `runs` times each on `threads`
# threads; prints every run's rate (the one vola fuse prints apart from reading the PNG
# frames), the median per size and each run's ATE.
# Usage: bench/slam_speed.sh path/to/vola [runs] [threads] [work folder]
set -euo pipefail
vola=$1
runs=${2:-5}
threads=${3:-2}
work=${4:-$(mktemp -d)}
mkdir -p "$work"
median() { sort -g | awk '{ v[NR] = $1 } END { print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }

[ -f "$work/r12_640/groundtruth.txt" ] || "$vola" rgbd-generate "$work/r12_640" --frames 60 --degrees-per-frame 1.2 > /dev/null
[ -f "$work/r12_320/groundtruth.txt" ] || "$vola" rgbd-generate "$work/r12_320" --frames 60 --degrees-per-frame 1.2 \
  --width 320 --height 240 > /dev/null

for size in 320 640; do : > "$work/rates_$size.txt"; done
for i in $(seq 1 "$runs"); do
  for size in 320 640; do
    out=$("$vola" fuse "$work/r12_$size" --threads "$threads" 2>&1)
    rate=$(awk '/^tracking \+ fusion:/ { print $6 }' <<< "$out")
    ate=$(awk '/^ATE:/ { print $3 }' <<< "$out")
    echo "run $i, ${size}: $rate frames/s, ATE $ate m"
    echo "$rate" >> "$work/rates_$size.txt"
  done
done
for size in 320 640; do
  echo "median ${size}: $(median < "$work/rates_$size.txt") frames/s over $runs runs ($threads threads)"
done
