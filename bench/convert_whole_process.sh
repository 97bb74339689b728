#!/usr/bin/env bash
# `vola convert` of the shared 1e6-point surface set (toolkit depth 5) against OpenVDB's
# MaskGrid build + write of the same points (bench/vdb_convert.cpp), each a whole process,
# alternating A B A B, RUNS pairs; prints each run's wall seconds, the medians and their
# ratio (vola's speed-up). usage: bench/convert_whole_process.sh BENCH_BUILD_DIR [RUNS=11]
set -euo pipefail
build=$(realpath "$1") runs=${2:-11}
shared=${VOLA_SHARED:-$(dirname "$0")/../../shared}
points=$shared/data/bench/surface_points_1e6.npy
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
vola=$build/apps/vola/vola vdb=$build/bench/vola_vdb_convert
[ -x "$vola" ] || vola=$(dirname "$0")/../build/apps/vola/vola
for tool in "$vola" "$vdb"; do [ -x "$tool" ] || { echo "missing $tool" >&2; exit 1; }; done
"$vola" convert "$points" "$work/w.vol" --quantize toolkit --depth 5 -q  # warm the page cache
"$vdb" "$points" "$work/w.vdb"
# Wall seconds of one run of "$@" (microsecond clock), appended to file $1.
timed() {
  local out=$1 start end
  shift
  start=$EPOCHREALTIME
  "$@"
  end=$EPOCHREALTIME
  awk "BEGIN {printf \"%.4f\\n\", $end - $start}" >> "$out"
}
for _ in $(seq "$runs"); do
  timed "$work/vola.t" "$vola" convert "$points" "$work/a.vol" --quantize toolkit --depth 5 -q
  timed "$work/vdb.t" "$vdb" "$points" "$work/a.vdb"
done
median() { sort -n "$1" | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}'; }
v=$(median "$work/vola.t") o=$(median "$work/vdb.t")
echo "vola convert (wall s): $(tr '\n' ' ' < "$work/vola.t")"
echo "OpenVDB MaskGrid build + write (wall s): $(tr '\n' ' ' < "$work/vdb.t")"
echo "medians of $runs: vola $v s, OpenVDB $o s, vola is $(awk "BEGIN {printf \"%.2f\", $o / $v}")x faster"
