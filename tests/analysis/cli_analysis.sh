#!/usr/bin/env bash
# vola census | components | dilate | erode | fill | crop | downsample | diff end to end,
# on the classified Autzen surveys, and components against scipy.ndimage.label.
# Usage: cli_analysis.sh VOLA SCIPY_DUMP SHARED_DATA_DIR
set -euo pipefail
vola=$1 dump=$2 data=$3
source "$(dirname "$0")/../lib/cli_test.sh"
# Debian's interpreter, where python3-scipy installs (a python3 earlier on PATH may lack it).
py=/usr/bin/python3
[ -x "$py" ] || py=python3

las=$data/las/pdal_autzen_trim.las
utm=$data/las/pdal_autzen-utm.las
[ -f "$las" ] && [ -f "$utm" ] || skip "no shared data in $data"
"$vola" convert "$las" "$tmp/t.vol" --voxel-size 2 > /dev/null
"$vola" convert "$utm" "$tmp/u.vol" --voxel-size 2 > /dev/null

# Census: valid JSON whose counts add up.
"$vola" census "$tmp/t.vol" --json --box 636000,849000,0,637000,850000,1000 > "$tmp/census.json"
"$py" - "$tmp/census.json" <<'PY' || fail "census JSON"
import json, sys
d = json.load(open(sys.argv[1]))
cls = [a for a in d["attributes"] if a["name"] == "classification"][0]["classes"]
assert sum(c["voxels"] for c in cls) == d["voxels"] > 0
assert {c["name"] for c in cls} >= {"Ground"}
assert d["levels"][-1]["cells"] == d["voxels"] and d["volume"] == d["voxels"] * 8
assert 0 < d["regions"][0]["voxels"] < d["voxels"]
assert sum(d["heights"]["counts"]) == d["voxels"]
PY
"$vola" census "$tmp/u.vol" | grep -q "Ground" || fail "census table has no Ground class"

# Components per class on both surveys: one row per class, voxels summing to the total.
for f in t u; do
  "$vola" components "$tmp/$f.vol" --per-class --json > "$tmp/$f.classes.json"
  total=$("$vola" census "$tmp/$f.vol" --json | "$py" -c 'import json,sys; print(json.load(sys.stdin)["voxels"])')
  "$py" - "$tmp/$f.classes.json" "$total" <<'PY' || fail "components --per-class on $f"
import json, sys
rows = json.load(open(sys.argv[1]))
assert sum(r["voxels"] for r in rows) == int(sys.argv[2])
assert all(1 <= r["components"] <= r["voxels"] and r["largest"] <= r["voxels"] for r in rows)
assert any(r["name"] == "Ground" for r in rows)
PY
done

# --split refuses a folder holding an earlier run's components (a run keeping fewer left the
# rest behind, mixed with its own), and --overwrite removes them first.
mkdir -p "$tmp/old_parts" && echo > "$tmp/old_parts/component_000007.vol" && echo notes > "$tmp/old_parts/notes.txt"
"$vola" components "$tmp/t.vol" --largest 2 --split "$tmp/old_parts" > /dev/null 2> "$tmp/err.txt" && fail "--split mixed runs"
grep -q "old_parts holds 1 component files of an earlier run" "$tmp/err.txt" || fail "--split: $(cat "$tmp/err.txt")"
"$vola" components "$tmp/t.vol" --largest 2 --split "$tmp/old_parts" --overwrite > /dev/null
[ "$(ls "$tmp/old_parts" | tr '\n' ' ')" = "component_000000.vol component_000001.vol notes.txt " ] ||
  fail "--overwrite left: $(ls "$tmp/old_parts")"
# An upside-down census box is refused (it counted 0 voxels without a word).
"$vola" census "$tmp/t.vol" --box 637000,849000,0,636000,850000,1000 2> "$tmp/err.txt" && fail "an upside-down box was counted"
grep -q "its x range runs from 637000 down to 636000" "$tmp/err.txt" || fail "census box: $(cat "$tmp/err.txt")"

# --split writes one file per kept component; together they hold the kept voxels.
"$vola" components "$tmp/t.vol" --connectivity 26 --min-voxels 50 --list 1000000 --split "$tmp/parts" --json > "$tmp/comp.json"
kept=$("$py" -c 'import json,sys; d=json.load(open(sys.argv[1])); print(d["kept"], sum(c["voxels"] for c in d["list"]))' "$tmp/comp.json")
set -- $kept
[ "$(ls "$tmp/parts" | wc -l)" -eq "$1" ] || fail "--split wrote $(ls "$tmp/parts" | wc -l) files for $1 components"
sum=0
for p in "$tmp"/parts/*.vol; do sum=$((sum + $("$vola" voxels "$p" | wc -l))); done
[ "$sum" -eq "$2" ] || fail "split files hold $sum voxels, listed components $2"
# --labels numbers the same kept components and marks the voxels of the others (their
# filters were ignored: every component got its number).
"$vola" components "$tmp/t.vol" --connectivity 26 --min-voxels 50 --labels "$tmp/labels.vol" > /dev/null
labelled=$("$vola" voxels "$tmp/labels.vol" --attributes | grep -v '^#' | awk '$NF != 4294967295' | wc -l)
distinct=$("$vola" voxels "$tmp/labels.vol" --attributes | grep -v '^#' | awk '$NF != 4294967295 {print $NF}' | sort -u | wc -l)
[ "$labelled" -eq "$2" ] && [ "$distinct" -eq "$1" ] || fail "--labels: $labelled voxels in $distinct components, --split: $2 in $1"

# dilate grows the grid where the voxels reach its faces (a converted survey's origin sits
# on its data's minimum: the inflation below it was cut off); --keep-grid keeps the grid and
# cuts. Then diff counts what was added (the grids differ; diff compares world places).
"$vola" dilate "$tmp/t.vol" --radius 1 --element cube --keep-grid "$tmp/k.vol" > /dev/null
"$vola" info "$tmp/k.vol" | grep -q "voxel size 2, origin (636000" || fail "dilate --keep-grid lost the grid"
"$vola" dilate "$tmp/t.vol" --radius 1 --element cube "$tmp/d.vol" > "$tmp/d.txt"
grep -q "(grid grown: origin moved by -1 -1 -1 voxels, depth 5 -> 5)" "$tmp/d.txt" || fail "dilate summary: $(cat "$tmp/d.txt")"
"$vola" info "$tmp/d.vol" | grep -q "voxel size 2, origin (635998, 848932, 404)" || fail "dilate did not grow the grid"
[ "$("$vola" voxels "$tmp/d.vol" | wc -l)" -gt "$("$vola" voxels "$tmp/k.vol" | wc -l)" ] || fail "the grown grid holds no more"
out=$("$vola" diff "$tmp/t.vol" "$tmp/d.vol" --outputs "$tmp/change")
n_t=$("$vola" voxels "$tmp/t.vol" | wc -l)
n_d=$("$vola" voxels "$tmp/d.vol" | wc -l)
[ "$out" = "added $((n_d - n_t)), removed 0, unchanged $n_t voxels" ] || fail "diff counts: $out"
[ "$("$vola" voxels "$tmp/change/added.vol" | wc -l)" -eq $((n_d - n_t)) ] || fail "added.vol"
# The old form still writes A - B and prints its line.
"$vola" diff "$tmp/d.vol" "$tmp/t.vol" "$tmp/removed.vol" | head -1 | grep -qx "diff: $n_d and $n_t voxels -> $((n_d - n_t)) voxels" \
  || fail "diff A B OUT line changed"
"$vola" erode "$tmp/d.vol" --radius 1 --element cube "$tmp/e.vol" > /dev/null
"$vola" fill "$tmp/t.vol" "$tmp/f.vol" > /dev/null
"$vola" crop "$tmp/t.vol" --min 0,0,0 --max 100,100,40 "$tmp/c.vol" > /dev/null
"$vola" downsample "$tmp/t.vol" --depth 4 "$tmp/s.vol" > /dev/null
"$vola" lod "$tmp/t.vol" --depth 4 "$tmp/l.vol" > /dev/null
cmp -s <("$vola" voxels "$tmp/s.vol") <("$vola" voxels "$tmp/l.vol") || fail "downsample --min-voxels 1 differs from lod"

# scipy.ndimage.label on dense copies: random grids and the Autzen survey at depth 4.
"$py" -c 'import scipy.ndimage, numpy' 2> /dev/null || skip "python3-scipy is not installed"
"$dump" "$tmp/scipy" "$tmp/s.vol" > /dev/null
"$py" "$(dirname "$0")/compare_scipy.py" "$tmp/scipy" || fail "components differ from scipy"
echo "cli_analysis: ok"
