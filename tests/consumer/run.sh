#!/usr/bin/env bash
# Installs the built project into a temporary prefix and builds the consumer against it.
set -euo pipefail
build_dir=$1
source_dir=$(cd "$(dirname "$0")" && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cmake --install "$build_dir" --prefix "$work/prefix" >/dev/null
cmake -S "$source_dir" -B "$work/build" -DCMAKE_PREFIX_PATH="$work/prefix" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$work/build" >/dev/null
"$work/build/consumer" "$work/points.vol"
"$work/build/consumer_convert" "$work"
"$work/build/consumer_modules"
"$work/build/consumer_io" "$work"
"$work/build/consumer_geo"
"$work/build/consumer_tile" "$work"
for component in viewer slam audio learn; do "$work/build/consumer_$component"; done
# The same consumer against the build tree, no install.
cmake -S "$source_dir" -B "$work/from_build" -Dvola_DIR="$build_dir" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$work/from_build" >/dev/null
"$work/from_build/consumer" "$work/points_build.vol"
"$work/from_build/consumer_convert" "$work"
"$work/from_build/consumer_modules"
"$work/from_build/consumer_io" "$work"
"$work/from_build/consumer_geo"
for component in viewer slam audio learn; do "$work/from_build/consumer_$component"; done
