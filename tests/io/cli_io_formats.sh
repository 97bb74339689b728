#!/usr/bin/env bash
# `vola convert` on one file of each format read by src/io/{ply,pcd,kitti,npy,binvox}.cpp.
#
#   cli_io_formats.sh VOLA_BINARY DATA_DIR       ($VOLA_SHARED/data wins when set)
#
# Each point file converts with `--quantize toolkit --depth 5` into a non-empty tree of at
# most as many voxels as points; binvox and NPY grids convert one cell to one voxel by
# default (the voxel count equals the file's occupied count: EXPECTED.txt for the binvox)
# and fill their cells on a finer grid (refused beyond 2^25 voxels).
# Exit status: 0 all good, 1 failures, 77 data folder missing (outside CI).
set -uo pipefail

if [[ $# -ne 2 ]]; then
  echo "usage: $0 VOLA_BINARY DATA_DIR" >&2
  exit 2
fi
vola=$1
data=${VOLA_SHARED:+$VOLA_SHARED/data}
data=${data:-$2}
keep_going=1
source "$(dirname "$0")/../lib/cli_test.sh"
[[ -d $data/binvox && -d $data/ply ]] || skip "data folder $data is missing"

# voxels FILE.vol: the occupied count `vola info --json` reports.
voxels() {
  "$vola" info --json "$1" | sed -n 's/^ *"voxels": *\([0-9]*\).*/\1/p'
}

# convert_toolkit INPUT POINTS [options...]: depth-5 toolkit conversion, 1..POINTS voxels.
convert_toolkit() {
  local input=$1 points=$2
  shift 2
  local out=$tmp/$(basename "$input").vol
  if ! "$vola" convert "$input" "$out" --quantize toolkit --depth 5 -q "$@"; then
    fail "vola convert $input --quantize toolkit --depth 5 $*"
    return
  fi
  local n
  n=$(voxels "$out")
  if [[ -z $n || $n -lt 1 || $n -gt $points ]]; then
    fail "$input: $n voxels from $points points"
  else
    echo "ok: $(basename "$input") -> $n voxels (depth 5, toolkit)"
  fi
}

# Point counts from EXPECTED.txt.
convert_toolkit "$data/ply/pdal_simple_binary.ply" 3 --nbits 1
convert_toolkit "$data/pcd/pcl_milk_color.pcd" 13704 --nbits 1
convert_toolkit "$data/kitti/mmdet3d_000008_fov_reduced.bin" 17238 --nbits 1

# A 2x3x4 uint8 NPY grid with cells [0][0][0], [1][2][3] and [1][0][2] occupied.
npy=$tmp/grid.npy
header="{'descr': '|u1', 'fortran_order': False, 'shape': (2, 3, 4), }"
while (((10 + ${#header} + 1) % 64 != 0)); do header+=" "; done
{
  printf '\x93NUMPY\x01\x00'
  printf "\\x$(printf %02x $((${#header} + 1)))\\x00"
  printf '%s\n' "$header"
  printf '\x01\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x01\x00\x00\x00\x00\x01'
} > "$npy"
# At toolkit depth 5 its cells span hundreds of voxels a side: filling them is refused,
# naming the grid's own cell size (each cell's centre alone left isolated voxels).
if message=$("$vola" convert "$npy" "$tmp/deep.vol" --quantize toolkit --depth 5 -q 2>&1); then
  fail "a 2x3x4 grid filled at depth 5"
elif [[ $message != *"more than 2^25"*"the grid's own cell size, 1, gives one voxel a cell"* ]]; then
  fail "grid.npy at depth 5: $message"
fi
if "$vola" convert "$npy" "$tmp/grid.vol" -q; then
  [[ $(voxels "$tmp/grid.vol") == 3 ]] || fail "grid.npy: $(voxels "$tmp/grid.vol") voxels, expected 3 (one per cell)"
else
  fail "vola convert grid.npy"
fi

# binvox: one voxel per occupied cell by default.
chair=$data/binvox/trimesh_chair_model.binvox
occupied=$(sed -n 's/^trimesh_chair_model.binvox .* occupied=\([0-9]*\).*/\1/p' "$data/EXPECTED.txt")
# At toolkit depth 3 (64 voxels over its 32-cell extent) every cell fills 2^3 voxels.
if "$vola" convert "$chair" "$tmp/chair3.vol" --quantize toolkit --depth 3 -q; then
  n=$(voxels "$tmp/chair3.vol")
  [[ $n -gt $occupied && $n -le $((8 * occupied)) ]] || fail "$chair at depth 3: $n voxels for $occupied cells of 2^3"
else
  fail "vola convert $chair --quantize toolkit --depth 3"
fi
if "$vola" convert "$chair" "$tmp/chair.vol" -q; then
  n=$(voxels "$tmp/chair.vol")
  if [[ $n != "$occupied" ]]; then fail "$chair: $n voxels, EXPECTED.txt says occupied=$occupied"
  else echo "ok: chair binvox -> $n voxels, one per occupied cell"; fi
else
  fail "vola convert $chair"
fi

# A point file with nothing saying how fine the voxels are: refused, and the error says
# which options to give (not the toolkit mode's internal name for it).
ply=$(ls "$data"/ply/*.ply | head -1)
if message=$("$vola" convert "$ply" "$tmp/unsized.vol" 2>&1); then
  fail "vola convert $ply without --voxel-size or --depth succeeded"
elif [[ $message != *--voxel-size*--depth* ]]; then
  fail "vola convert without a voxel size: unhelpful error: $message"
else
  echo "ok: no voxel size -> $message"
fi

# A Lyft sweep (five float32 a point, named plain .bin): --format nuscenes in info,
# translate and convert; without it KITTI's error says so.
"${VOLA_PYTHON:-python3}" -c 'import struct, sys; open(sys.argv[1], "wb").write(struct.pack("<10f", 1, 2, 3, 40, 1, 4, 5, 6, 80, 2))' "$tmp/lyft.bin"
if message=$("$vola" info "$tmp/lyft.bin" 2>&1); then
  fail "a 40-byte .bin read as KITTI"
elif [[ $message != *"--format nuscenes"* ]]; then
  fail "the KITTI error does not point to --format nuscenes: $message"
fi
"$vola" info "$tmp/lyft.bin" --format nuscenes | grep -q "points: *2" || fail "vola info --format nuscenes"
"$vola" translate "$tmp/lyft.bin" "$tmp/lyft.xyz" --format nuscenes -q 2> /dev/null
[ "$(tail -n +2 "$tmp/lyft.xyz" | tr '\n' ' ')" == "1 2 3 40 1 4 5 6 80 2 " ] || fail "translate --format nuscenes: $(cat "$tmp/lyft.xyz")"
"$vola" convert "$tmp/lyft.bin" "$tmp/lyft.vol" --format nuscenes --voxel-size 1 -q || fail "convert --format nuscenes"

# A file read as another format than its own is named by its first bytes (a WAV renamed
# .stl read as 2,741 triangles of +-3.4e38; binary read as text asked for --columns).
wav=$data/audio/alsa_Front_Center.wav
cp "$wav" "$tmp/sound.stl"
cp "$wav" "$tmp/sound.xyz"
for f in sound.stl sound.xyz; do
  "$vola" convert "$tmp/$f" "$tmp/sound.vol" --voxel-size 1 2> "$tmp/err" && fail "a WAV named $f was converted"
  grep -q "its first bytes are those of a RIFF file" "$tmp/err" || fail "a WAV named $f: $(cat "$tmp/err")"
done
las=$data/las/pdal_autzen_trim.las
"$vola" info "$las" --format pcd 2> "$tmp/err" && fail "a LAS read as PCD"
grep -q "not a PCD point file: its first bytes are those of a LAS/LAZ point file" "$tmp/err" || fail "LAS as PCD: $(cat "$tmp/err")"
"$vola" info "$las" --format text 2> "$tmp/err" && fail "a LAS read as text"
grep -q "not a text point file" "$tmp/err" || fail "LAS as text: $(cat "$tmp/err")"

# vola info says what it does not read of a plain (N, 6) array, and --summary gives each
# value as short as reads back (9 significant digits made 1234567890.25 1.23456789e+09).
"${VOLA_PYTHON:-python3}" - "$tmp/six.npy" <<'PY'
import struct, sys
header = "{'descr': '<f4', 'fortran_order': False, 'shape': (2, 6), }"
header += " " * (63 - (10 + len(header)) % 64) + "\n"
open(sys.argv[1], "wb").write(b"\x93NUMPY\x01\x00" + struct.pack("<H", len(header)) + header.encode() + struct.pack("<12f", *range(12)))
PY
"$vola" info "$tmp/six.npy" | grep -q "the 3 after x y z are not read" || fail "vola info of an (N, 6) array: $("$vola" info "$tmp/six.npy")"
printf 'x y z\n0.1 2 1234567890.25\n' > "$tmp/big.xyz"
"$vola" info "$tmp/big.xyz" --summary | grep -q "max (0.1, 2, 1234567890.25)" || fail "summary digits: $("$vola" info "$tmp/big.xyz" --summary)"

if ((failures > 0)); then
  echo "$failures failure(s)" >&2
  exit 1
fi
echo "all conversions passed"
