#!/usr/bin/env bash
# Dense SLAM figures for docs/BENCHMARKS.md: a generated 300-frame room sequence (ATE,
# RPE, map memory against a dense TSDF grid, frames per second; the same run on a dense
# grid for the identical-trajectory check) and the real ICL-NUIM / Kinect frames.
# Usage: bench/slam_fuse.sh path/to/vola [runs] [work folder]
# SLAM_SEEDS (default "2 3"): further noise seeds of the same room loop, fused once each
# for ATE/RPE (the tracker's result on one seed is not a measurement of its accuracy).
set -euo pipefail
vola=$1
runs=${2:-3}
work=${3:-$(mktemp -d)}
data=${VOLA_SHARED:-$(cd "$(dirname "$0")/../.." && pwd)/shared}/data/rgbd
mkdir -p "$work"
median() { sort -g | awk '{ v[NR] = $1 } END { print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }

if [ ! -f "$work/room300/groundtruth.txt" ]; then
  "$vola" rgbd-generate "$work/room300" --frames 300 --seed 1
fi

echo "== room300, 640x480, 1 cm voxels, sparse bricks: $runs runs"
for i in $(seq 1 "$runs"); do
  "$vola" fuse "$work/room300" -o "$work/room300.vol" --trajectory "$work/room300_est.txt" --mesh "$work/room300.ply" \
    --render "$work/room300_view.png" --render-frame 150 > "$work/room300_run$i.txt"
done
cat "$work/room300_run1.txt"
echo "median frames/s: $(for i in $(seq 1 "$runs"); do awk '/ lost\) in / { print $8 }' "$work/room300_run$i.txt"; done | median)"
"$vola" rgbd-eval "$work/room300/groundtruth.txt" "$work/room300_est.txt"

for seed in ${SLAM_SEEDS-2 3}; do
  if [ ! -f "$work/room300s$seed/groundtruth.txt" ]; then
    "$vola" rgbd-generate "$work/room300s$seed" --frames 300 --seed "$seed" > /dev/null
  fi
  echo "== room300 seed $seed, same settings, one run"
  "$vola" fuse "$work/room300s$seed" --trajectory "$work/room300s${seed}_est.txt" | grep -E 'frames|ATE|RPE|map:'
  "$vola" rgbd-eval "$work/room300s$seed/groundtruth.txt" "$work/room300s${seed}_est.txt" | grep -E 'rmse'
done

echo "== room300, 2 cm voxels, sparse vs dense grid of the same 6.4 m extent (40 bricks per side)"
"$vola" fuse "$work/room300" --trajectory "$work/sparse2.txt" --voxel-size 0.02 --bricks 40 > "$work/sparse2_out.txt"
"$vola" fuse "$work/room300" --trajectory "$work/dense2.txt" --voxel-size 0.02 --bricks 40 --dense > "$work/dense2_out.txt"
cat "$work/sparse2_out.txt" "$work/dense2_out.txt"
if cmp -s "$work/sparse2.txt" "$work/dense2.txt"; then echo "trajectories: identical (byte for byte)"; else echo "trajectories: DIFFER"; fi

echo "== ICL-NUIM (slambook2 ch12, 5 frames with poses)"
icl=(--intrinsics 481.2 -480 319.5 239.5 --depth-factor 5000 --max-depth 8)
"$vola" fuse "$data/iclnuim_slambook2_ch12" "${icl[@]}" --trajectory "$work/icl_est.txt" || true
"$vola" fuse "$data/iclnuim_slambook2_ch12" "${icl[@]}" --groundtruth-poses -o "$work/icl.vol" --mesh "$work/icl.ply" \
  --render "$work/icl_view.png"
echo "== Kinect (slambook2 ch5, 5 frames with poses)"
kinect=(--intrinsics 518 519 325.5 253.5 --depth-factor 1000 --max-depth 7)
"$vola" fuse "$data/kinect_slambook2_ch5" "${kinect[@]}" --trajectory "$work/kinect_est.txt" || true
"$vola" fuse "$data/kinect_slambook2_ch5" "${kinect[@]}" --groundtruth-poses -o "$work/kinect.vol" \
  --render "$work/kinect_view.png"
echo "outputs in $work"
