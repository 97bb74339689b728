#!/usr/bin/env bash
# Occupancy maps, vola against OctoMap 1.9.7 on the same scans (bench/map_peers.cpp):
# the two real KITTI scans of the shared data, and a generated lidar drive (40 scans of
# 65536 beams) down a street of a generated city; at 0.2 and 0.1 m voxels with an 80 m
# range. Speed (median of 3, both peers in one process), file sizes and decisions from the
# in-process run; peak memory from one process per peer (--only), so that each figure is
# the peer's own whole process.
# Usage: bench/map_peers.sh BUILD_BENCH_DIR VOLA [SHARED_DATA_DIR]
# Example: bench/map_peers.sh build-bench build/apps/vola/vola ../shared/data
set -euo pipefail
bench=$1 vola=$2 data=${3:-${VOLA_SHARED:+$VOLA_SHARED/data}}
data=$(cd "${data:-$(dirname "$0")/../../shared/data}" && pwd)  # the scan lists need absolute paths
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
kitti=$data/kitti/object_training/velodyne
printf '%s 0 0 0 0 0 0 1\n%s 0 0 0 0 0 0 1\n' "$kitti/000000.bin" "$kitti/000001.bin" > "$tmp/kitti.txt"

"$vola" generate city "$tmp/city.xyz" --points 4000000 > /dev/null
"$vola" convert "$tmp/city.xyz" "$tmp/city.vol" --voxel-size 0.1 -q
mkdir -p "$tmp/drive"
"$bench/bench/vola_lidar_sequence" "$tmp/city.vol" "$tmp/drive" --scans 40 --step 2 --azimuths 1024 --range 80

for list in kitti drive/scans; do
  for voxel in 0.2 0.1; do
    echo "== $list, voxel $voxel m, range 80 m"
    "$bench/bench/vola_map_peers" "$tmp/$list.txt" --voxel-size "$voxel" --max-range 80 --reps 3 --out "$tmp/files"
    for peer in vola octomap; do
      "$bench/bench/vola_map_peers" "$tmp/$list.txt" --voxel-size "$voxel" --max-range 80 --only "$peer" | tail -1
    done
  done
done
