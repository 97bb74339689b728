#!/usr/bin/env bash
# vola tile with the default attribute columns against occupancy only (--no-attributes),
# the two alternated RUNS times in one script (the machine's noise hits both alike):
# median wall time, the tiler's own stage times of that run, peak RSS, and the bytes of
# tiles and spill; checks that every attribute run wrote the same bytes.
# Usage: bench/tile_attributes.sh VOLA FILE.las TILE_SIZE DEPTH [RUNS] [extra vola tile options]
# Example: bench/tile_attributes.sh build/apps/vola/vola /tmp/survey/survey_10000000.las 64 4 5
set -euo pipefail
vola=$1 las=$2 size=$3 depth=$4 runs=${5:-5}
shift $(($# < 5 ? $# : 5))
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cat "$las" > /dev/null  # into the page cache
declare -A walls peaks lines
for i in $(seq "$runs"); do
  for mode in occupancy attributes; do
    flag=()
    [ "$mode" = occupancy ] && flag=(--no-attributes)
    rm -rf "$tmp/out"
    /usr/bin/time -f '%e %M' -o "$tmp/time" "$vola" tile "$las" --tile-size "$size" --depth "$depth" -o "$tmp/out" \
      "${flag[@]}" "$@" > "$tmp/summary"
    read -r s kib < "$tmp/time"
    walls[$mode]+="$s "
    [ "$kib" -gt "${peaks[$mode]:-0}" ] && peaks[$mode]=$kib
    lines[$mode,$s]="$(grep -E '^(tiles|spilled|time):' "$tmp/summary" | tr '\n' ' ')"
    if [ "$mode" = attributes ]; then
      if [ -d "$tmp/first" ]; then
        diff -r "$tmp/first" "$tmp/out" > /dev/null || { echo "attribute run $i wrote other bytes" >&2; exit 1; }
      else
        mv "$tmp/out" "$tmp/first"
      fi
    fi
  done
done
for mode in occupancy attributes; do
  median=$(printf '%s\n' ${walls[$mode]} | sort -g | sed -n "$(((runs + 1) / 2))p")
  echo "$mode: wall s ${walls[$mode]}-> median $median s, peak $((peaks[$mode] / 1024)) MiB"
  echo "  median run: ${lines[$mode,$median]}"
done
