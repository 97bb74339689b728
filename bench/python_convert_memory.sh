#!/usr/bin/env bash
# Python's vola.convert against `vola convert` on the same generated LAS survey: peak memory
# (max RSS) and wall time of each as a whole process, median of RUNS, and whether the two
# .vol files are the same bytes. Both go through vola::convert, which streams LAS.
# usage: bench/python_convert_memory.sh BUILD_DIR [POINTS=10000000] [RUNS=3]
set -euo pipefail
build=$(realpath "$1") points=${2:-10000000} runs=${3:-3}
vola=$build/apps/vola/vola
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
las=$(/usr/bin/python3 -c "import sys; sys.path.insert(0, '$(dirname "$0")'); import las_survey
print(las_survey.write_survey_las('$vola', '$work', $points))")
median() { sort -n | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}'; }
for attributes in True False; do
  flag=""; [ "$attributes" = False ] && flag=--no-attributes
  for run in $(seq "$runs"); do
    /usr/bin/time -f "%e %M" -o "$work/t_cli.$run" "$vola" convert "$las" "$work/cli.vol" --voxel-size 1 -q $flag
    PYTHONPATH=$build/python /usr/bin/time -f "%e %M" -o "$work/t_py.$run" /usr/bin/python3 -c \
      "import vola; vola.convert('$las', voxel_size=1.0, attributes=$attributes, output='$work/py.vol')"
  done
  cli_mem=$(cat "$work"/t_cli.* | awk '{print $2}' | median); py_mem=$(cat "$work"/t_py.* | awk '{print $2}' | median)
  cli_s=$(cat "$work"/t_cli.* | awk '{print $1}' | median); py_s=$(cat "$work"/t_py.* | awk '{print $1}' | median)
  same=$(cmp -s "$work/cli.vol" "$work/py.vol" && echo "same bytes" || echo "DIFFERENT BYTES")
  echo "attributes=$attributes $points points: CLI ${cli_s} s ${cli_mem} KB, Python ${py_s} s ${py_mem} KB," \
       "Python/CLI memory $(awk "BEGIN {printf \"%.2f\", $py_mem / $cli_mem}")x, $same"
  rm -f "$work"/t_cli.* "$work"/t_py.*
done
