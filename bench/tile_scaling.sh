#!/usr/bin/env bash
# vola tile throughput per core and memory per process, for docs/SCALING.md: one LAS
# file (in page cache) tiled on 1 and 2 threads and as 2 and 3 MPI ranks of 1 thread,
# median of RUNS runs each (the tiler's own time on rank 0, from reading the first chunk
# to writing the index, and the wall clock of the whole command, which adds loading the
# binary's libraries and starting MPI), with peak RSS; checks that every run wrote the
# same bytes.
# Usage: bench/tile_scaling.sh VOLA FILE.las TILE_SIZE DEPTH [RUNS]
# Example: flock /tmp/vola-cpu.lock bench/tile_scaling.sh build/apps/vola/vola survey.las 64 4 3
set -euo pipefail
vola=$1 las=$2 size=$3 depth=$4 runs=${5:-3}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
export OMPI_MCA_btl_vader_single_copy_mechanism=none
cat "$las" > /dev/null  # into the page cache
baseline=$(/usr/bin/time -f '%M' "$vola" --version 2>&1 > /dev/null | tail -1)
points=$("$vola" tile "$las" --tile-size "$size" --depth "$depth" -o "$tmp/ref" | sed -n 's/^points in: *\([0-9]*\).*/\1/p')
printf '%-26s %9s %9s %11s %16s %13s\n' setup "tiler s" "wall s" "M points/s" "M points/s/core" "peak RSS MiB"
measure() {  # LABEL CORES COMMAND...
  local label=$1 cores=$2
  shift 2
  local times=() walls=() peak=0
  for _ in $(seq "$runs"); do
    rm -rf "$tmp/out"
    /usr/bin/time -f '%e %M' -o "$tmp/time" "$@" -o "$tmp/out" > "$tmp/summary"
    read -r s kib < "$tmp/time"
    walls+=("$s")
    times+=("$(sed -n 's/^time: *\([0-9.]*\) s.*/\1/p' "$tmp/summary")")
    [ "$kib" -gt "$peak" ] && peak=$kib
    diff -r "$tmp/ref" "$tmp/out" > /dev/null || { echo "$label: other bytes than the reference run" >&2; exit 1; }
  done
  local median wall
  median=$(printf '%s\n' "${times[@]}" | sort -g | sed -n "$(((runs + 1) / 2))p")
  wall=$(printf '%s\n' "${walls[@]}" | sort -g | sed -n "$(((runs + 1) / 2))p")
  awk -v l="$label" -v m="$median" -v w="$wall" -v n="$points" -v c="$cores" -v p="$peak" \
    'BEGIN { printf "%-26s %9.2f %9.2f %11.2f %16.2f %13.0f\n", l, m, w, n / m / 1e6, n / m / 1e6 / c, p / 1024 }'
}
args=(tile "$las" --tile-size "$size" --depth "$depth")
measure "1 process, 1 thread" 1 "$vola" "${args[@]}" --threads 1
measure "1 process, 2 threads" 2 "$vola" "${args[@]}" --threads 2
measure "2 MPI ranks x 1" 2 mpirun --allow-run-as-root -np 2 "$vola" "${args[@]}" --threads 1
measure "3 MPI ranks x 1 (2 cores)" 2 mpirun --allow-run-as-root --oversubscribe -np 3 "$vola" "${args[@]}" --threads 1
echo "points: $points; the vola binary alone: $((baseline / 1024)) MiB resident (peak RSS for MPI is mpirun's, not a rank's)"
