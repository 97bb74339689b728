#!/usr/bin/env bash
# vola info --json on point files, checked against what an independent reader found in
# them (EXPECTED.txt): for every LAS/LAZ/COPC file named there, the count, point format,
# header bounds at the file's precision and the points per class (--summary reads them);
# for PLY/PCD/KITTI files, the count. A file of the wrong kind gets a clear message.
# Usage: cli_info_json.sh VOLA SHARED_DATA_DIR   ($VOLA_SHARED/data, when set, wins)
set -euo pipefail
vola=$1 data=${VOLA_SHARED:+$VOLA_SHARED/data}
data=${data:-$2}
source "$(dirname "$0")/../lib/cli_test.sh"
[ -f "$data/EXPECTED.txt" ] || skip "no $data/EXPECTED.txt (set VOLA_SHARED)"

checked=0
for f in "$data"/las/*.las "$data"/las/permutations/*.las "$data"/laz/*.laz; do
  name=$(basename "$f")
  line=$(grep "^$name: " "$data/EXPECTED.txt" || true)
  [ -n "$line" ] || continue
  "$vola" info --json --summary "$f" > "$tmp/info.json" || fail "$name: info --json --summary failed"
  "${VOLA_PYTHON:-python3}" - "$tmp/info.json" "$line" <<'PY' || fail "$name: info --json differs from EXPECTED.txt"
import json, math, re, sys
info, line = json.load(open(sys.argv[1])), sys.argv[2]
assert info["points"] == int(re.search(r" n=(\d+)", line).group(1)), info["points"]
assert info["point_format"] == int(re.search(r" pf=(\d+)", line).group(1))
lo, hi = re.search(r"bounds=\[([^\]]*)\]\.\.\[([^\]]*)\]", line).groups()
for got, want in ((info["bounds"]["min"], lo), (info["bounds"]["max"], hi)):
    for g, w, s in zip(got, (float(v) for v in want.split(",")), info["scale"]):
        assert abs(g - w) <= max(s, 0.01) / 2 + 1e-9, (got, want)
        # at the file's precision: no binary noise beyond the scale's decimals
        decimals = max(0, math.ceil(-math.log10(s) - 1e-9))
        assert round(g, decimals) == g, (g, s)
classes = re.search(r"classes=\{([^}]*)\}", line)
if classes:
    want = {int(k): int(v) for k, v in re.findall(r"(\d+): (\d+)", classes.group(1))}
    got = {c["code"]: c["points"] for c in info["summary"].get("classes", [])}
    assert got == want, (got, want)
assert info["summary"]["points_read"] == info["points"]
PY
  checked=$((checked + 1))
done
[ "$checked" -ge 20 ] || fail "only $checked LAS/LAZ files of EXPECTED.txt were checked"

# Other point files: the count and the columns; the CRS as PROJ names it (or null).
for f in "$data"/ply/pdal_simple_text.ply "$data"/pcd/pcl_bun0.pcd "$data"/kitti/object_training/velodyne/000000.bin; do
  "$vola" info --json --summary "$f" > "$tmp/other.json" || fail "$(basename "$f"): info --json failed"
  "${VOLA_PYTHON:-python3}" -c "
import json, sys
d = json.load(open(sys.argv[1]))
assert d['points'] > 0 and d['summary']['points_read'] == d['points'], d
assert 'crs' in d and isinstance(d['dimensions'], list), d
" "$tmp/other.json" || fail "$(basename "$f"): bad JSON"
done
"${VOLA_PYTHON:-python3}" -c "import json,sys; assert json.load(open(sys.argv[1]))['points'] == 115384" "$tmp/other.json" ||
  fail "KITTI 000000.bin: not 115384 points"

# The wrong kind of file: a message naming the file and what to do, exit 1, no crash.
"$vola" info "$data/mesh/stl/trimesh_teapot_bin.stl" 2> "$tmp/err.txt" && fail "info on a mesh succeeded"
grep -q "trimesh_teapot_bin.stl: vola info describes .vol and point files" "$tmp/err.txt" || fail "mesh: $(cat "$tmp/err.txt")"
printf 'not a point file\n' > "$tmp/notes.md"
"$vola" info "$tmp/notes.md" 2> "$tmp/err.txt" && fail "info on a .md succeeded"
grep -q "notes.md: cannot tell the format" "$tmp/err.txt" || fail ".md: $(cat "$tmp/err.txt")"
echo "cli_info_json: OK ($checked LAS/LAZ files)"
