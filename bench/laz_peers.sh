#!/usr/bin/env bash
# LAZ speed, the figures docs/BENCHMARKS.md publishes:
#  1. decode throughput on one core: vola's codec (vola_laz_bench) and laz-perf (npm,
#     WebAssembly under node, the only other LAZ decoder on this system) on the same
#     real files, one after the other in the same run;
#  2. whole-process `vola convert` of a LAZ against its LAS (median of RUNS, /usr/bin/time),
#     occupancy only and with the default attribute columns, on the real Autzen survey and
#     on a generated 1e7-point survey (bench/las_survey.py's, compressed by vola translate).
# Usage: bench/laz_peers.sh BUILD_BENCH_DIR BUILD_DIR [RUNS]   (VOLA_SHARED: the shared folder)
set -euo pipefail
bench_build=$1 build=$2 runs=${3:-3}
root=$(cd "$(dirname "$0")/.." && pwd)
shared=${VOLA_SHARED:-$root/../shared}
vola=$build/apps/vola/vola
lazperf=$build/tests/lazperf/node_modules/laz-perf
[ -x "$bench_build/bench/vola_laz_bench" ] || { echo "build vola_laz_bench first (scripts/bench)"; exit 1; }
[ -d "$lazperf" ] || { echo "no laz-perf at $lazperf (the test build's npm ci installs it)"; exit 1; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

echo "== decode, one core (points/s: best and median)"
for name in pdal_autzen_trim pdal_lone-star-split-1 laspy_append-bug; do
  file=$shared/data/laz/$name.laz
  "$bench_build/bench/vola_laz_bench" "$file" 15 | grep -E "^decode" | sed "s|^|vola     $name: |"
  node "$root/bench/lazperf_decode.mjs" "$lazperf" "$file" 7 | sed "s|^laz-perf [^:]*:|laz-perf $name:|"
done

# median_seconds CMD...: the median wall time of RUNS runs.
median_seconds() {
  for _ in $(seq "$runs"); do /usr/bin/time -f "%e" "$@" 2>&1 >/dev/null | tail -1; done | sort -n |
    awk '{a[NR] = $1} END {print a[int((NR + 1) / 2)]}'
}

/usr/bin/python3 -c "
import sys; sys.path.insert(0, '$root/bench')
import las_survey
las_survey.write_survey_las('$vola', '$work', 10_000_000, 3)" >/dev/null
"$vola" translate "$work/survey_10000000.las" "$work/survey_10000000.laz" -q
echo "== vola convert, whole process, median of $runs (wall seconds: LAZ, LAS, ratio)"
for pair in "$shared/data/laz/pdal_autzen_trim.laz:$shared/data/las/pdal_autzen_trim.las:1" \
            "$work/survey_10000000.laz:$work/survey_10000000.las:1"; do
  IFS=: read -r laz las voxel <<< "$pair"
  for mode in "--no-attributes" "--attributes"; do
    flags=(--voxel-size "$voxel" -q)
    [ "$mode" = "--no-attributes" ] && flags+=(--no-attributes)
    a=$(median_seconds "$vola" convert "$laz" "$work/a.vol" "${flags[@]}")
    b=$(median_seconds "$vola" convert "$las" "$work/b.vol" "${flags[@]}")
    cmp -s "$work/a.vol" "$work/b.vol" || echo "WARNING: the LAZ and LAS outputs differ"
    printf '%-28s %-16s LAZ %6.2f s  LAS %6.2f s  %5.2fx\n' "$(basename "$laz")" "${mode#--}" "$a" "$b" \
      "$(echo "$a / $b" | bc -l)"
  done
done
