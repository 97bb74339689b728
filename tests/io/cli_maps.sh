#!/usr/bin/env bash
# `vola export` to OctoMap (.bt, .ot) and OpenVDB (.vdb) and `vola convert` back, end to end.
#
#   cli_maps.sh VOLA_BINARY SHARED_DIR      ($VOLA_SHARED overrides SHARED_DIR)
#
# A real survey (pdal_autzen-utm.las, UTM metres) at 2 m goes vol -> .bt/.ot/.vdb -> vol
# and must give the same voxels (.bt/.ot: moved to OctoMap's 0 with a warning, since UTM
# coordinates lie beyond OctoMap's keys; .vdb: the same world centres); a `vola map` with
# a state map exports occupied and free voxels with their log-odds (plain trees: --free), and a
# ROS map of a scanned room; wrong voxel sizes, damaged files and misplaced options fail
# with a message.
# Exit status: 0 all good, 1 failures, 77 shared folder missing (outside CI).
set -uo pipefail

if [[ $# -ne 2 ]]; then
  echo "usage: $0 VOLA_BINARY SHARED_DIR" >&2
  exit 2
fi
vola=$1
shared=${VOLA_SHARED:-$2}
las=$shared/data/las/pdal_autzen-utm.las
keep_going=1
source "$(dirname "$0")/../lib/cli_test.sh"
[[ -f $las ]] || skip "$las is missing"
# expect_error MESSAGE_PART COMMAND...: the command fails and says MESSAGE_PART.
expect_error() {
  local part=$1
  shift
  if "$@" >"$tmp/out" 2>"$tmp/err"; then
    fail "'$*' succeeded, expected an error saying '$part'"
  elif ! grep -q -- "$part" "$tmp/err"; then
    fail "'$*' failed without saying '$part': $(cat "$tmp/err")"
  fi
}

"$vola" convert "$las" "$tmp/a.vol" --voxel-size 2 -q || fail "convert $las"
"$vola" voxels "$tmp/a.vol" | sort >"$tmp/a.voxels"
"$vola" coords "$tmp/a.vol" | sort >"$tmp/a.coords"
[[ $(wc -l <"$tmp/a.voxels") -gt 1000 ]] || fail "the survey gave too few voxels"

for ext in bt ot; do
  "$vola" export "$tmp/a.vol" "$tmp/a.$ext" >"$tmp/out" 2>"$tmp/err" || fail "export .$ext: $(cat "$tmp/err")"
  grep -q "lies beyond OctoMap's 32768 cells of 2 around 0, so it moved by" "$tmp/err" ||
    fail ".$ext export did not warn about the shift: $(cat "$tmp/err")"
  grep -q "^OctoMap OcTree (.$ext" "$tmp/out" || fail ".$ext summary: $(cat "$tmp/out")"
  "$vola" convert "$tmp/a.$ext" "$tmp/$ext.vol" -q || fail "convert .$ext"
  "$vola" voxels "$tmp/$ext.vol" | sort | cmp -s - "$tmp/a.voxels" || fail ".$ext round trip: the voxels differ"
  "$vola" info "$tmp/$ext.vol" | grep -q "voxel size 2, origin (0, 0, 0)" || fail ".$ext round trip: not the map's grid"
done

"$vola" export "$tmp/a.vol" "$tmp/a.vdb" >"$tmp/out" 2>"$tmp/err" || fail "export .vdb: $(cat "$tmp/err")"
# OpenVDB keeps the grid's placement whole (no shift warning); only the CRS is not kept.
grep -v "has no place for the CRS" "$tmp/err" | grep -q . && fail ".vdb export warned: $(cat "$tmp/err")"
grep -q "a.vdb: this format has no place for the CRS" "$tmp/err" || fail ".vdb export kept quiet about the CRS"
grep -q "^OpenVDB grids occupied:" "$tmp/out" || fail ".vdb summary: $(cat "$tmp/out")"
"$vola" convert "$tmp/a.vdb" "$tmp/vdb.vol" -q || fail "convert .vdb"
"$vola" coords "$tmp/vdb.vol" | sort | cmp -s - "$tmp/a.coords" || fail ".vdb round trip: the voxel centres differ"

# An occupancy map with free space and log-odds (the scans of tests/map/cli_map.sh).
mkdir "$tmp/scans"
printf '1.0 0 0\n' >"$tmp/scans/ahead.xyz"
printf 'scans/ahead.xyz 0.1 0.1 0.1 0 0 0 1\nscans/ahead.xyz 0.1 0.1 0.1 0 0 0.70710678 0.70710678\n' >"$tmp/list.txt"
"$vola" map "$tmp/list.txt" -o "$tmp/map.vol" --voxel-size 0.25 --free -q || fail "vola map"
# A state map (what vola map writes) holds its free voxels: they go out with it.
"$vola" export "$tmp/map.vol" "$tmp/map.ot" >"$tmp/out" 2>"$tmp/err" || fail "export map.ot: $(cat "$tmp/err")"
grep -q "(.ot, log-odds from the log_odds columns) of .* nodes: 2 occupied and 7 free voxels of 0.25" "$tmp/out" ||
  fail "map.ot summary: $(cat "$tmp/out")"
[[ ! -s $tmp/err ]] || fail "a vola map export warned: $(cat "$tmp/err")"
"$vola" convert "$tmp/map.ot" "$tmp/map_back.vol" -q 2>"$tmp/err" || fail "convert map.ot"
[[ ! -s $tmp/err ]] || fail "convert map.ot warned: $(cat "$tmp/err")"
# The free cells come back too: a state map with the same states and log-odds as vola map's.
"$vola" info "$tmp/map_back.vol" | grep -q "state map (vola map): 9 known.*: 2 occupied, 7 free" ||
  fail "map.ot came back without its free cells: $("$vola" info "$tmp/map_back.vol")"
cmp -s <("$vola" voxels "$tmp/map_back.vol" --attributes | sort) <("$vola" voxels "$tmp/map.vol" --attributes | sort) ||
  fail "map.ot round trip: the known voxels or their log-odds differ"
"$vola" export "$tmp/map.vol" "$tmp/map.bt" -q || fail "export map.bt"
"$vola" convert "$tmp/map.bt" "$tmp/bt_back.vol" -q || fail "convert map.bt"
"$vola" info "$tmp/bt_back.vol" | grep -q "state map (vola map): 9 known.*: 2 occupied, 7 free" ||
  fail "map.bt came back without its free cells: $("$vola" info "$tmp/bt_back.vol")"
# Occupancy alone asked for: the free cells are not kept, and that is said.
"$vola" convert "$tmp/map.ot" "$tmp/occupied_only.vol" --no-attributes -q 2>"$tmp/err" || fail "convert map.ot --no-attributes"
grep -q "map.ot: the map's 7 free cells are not kept: the .vol holds its 2 occupied cells" "$tmp/err" ||
  fail "convert map.ot --no-attributes kept quiet about the free cells: $(cat "$tmp/err")"
"$vola" coords "$tmp/map_back.vol" | sort | cmp -s - <("$vola" coords "$tmp/map.vol" | sort) ||
  fail "map.ot round trip: the occupied voxels differ"
"$vola" voxels "$tmp/map_back.vol" --attributes --header | head -1 | grep -q "log_odds" || fail "map.ot lost the log-odds"
"$vola" export "$tmp/map.vol" "$tmp/map.vdb" >"$tmp/out" || fail "export map.vdb"
grep -q "^OpenVDB grids log_odds free_log_odds: 2 occupied and 7 free" "$tmp/out" || fail "map.vdb summary: $(cat "$tmp/out")"
"$vola" convert "$tmp/map.vdb" "$tmp/vdb_back.vol" -q || fail "convert map.vdb"
"$vola" coords "$tmp/vdb_back.vol" | sort | cmp -s - <("$vola" coords "$tmp/map.vol" | sort) ||
  fail "map.vdb round trip: not the occupied voxels (free_log_odds sorts before log_odds)"
"$vola" convert "$tmp/map.vdb" "$tmp/free_back.vol" --grid free_log_odds -q || fail "convert map.vdb --grid free_log_odds"
"$vola" coords "$tmp/free_back.vol" | sort | cmp -s - <("$vola" coords "$tmp/map.free.vol" | sort) ||
  fail "map.vdb: the free voxels differ"
# vola info shows the default grid, or the one --grid names (a file of several others
# names them and points to --grid, which info takes as convert does).
"$vola" info "$tmp/map.vdb" | grep -q "^occupied: *2 cells" || fail "info map.vdb: $("$vola" info "$tmp/map.vdb")"
"$vola" info "$tmp/map.vdb" --grid free_log_odds | grep -q "^occupied: *7 cells" ||
  fail "info map.vdb --grid free_log_odds: $("$vola" info "$tmp/map.vdb" --grid free_log_odds)"
expect_error "has no grid named 'density'" "$vola" info "$tmp/map.vdb" --grid density
expect_error "applies to OpenVDB (.vdb) and NumPy .npz files" "$vola" info "$tmp/map.vol" --grid occupied

# At a coarser --depth a cell holding occupied and free voxels is occupied, not both (the
# .ot writer refused "voxel ... is given as occupied and as free"; the .vdb one wrote the
# cell into both grids).
"$vola" export "$tmp/map.vol" "$tmp/lod.ot" --depth 1 >"$tmp/out" 2>"$tmp/err" || fail "export --depth 1: $(cat "$tmp/err")"
grep -q ": 2 occupied and 1 free voxels of 1 " "$tmp/out" || fail "lod.ot summary: $(cat "$tmp/out")"
"$vola" export "$tmp/map.vol" "$tmp/lod.vdb" --depth 1 -q || fail "export lod.vdb"
"$vola" convert "$tmp/lod.vdb" "$tmp/lod_occupied.vol" --grid occupied -q || fail "convert lod.vdb occupied"
"$vola" convert "$tmp/lod.vdb" "$tmp/lod_free.vol" --grid free -q || fail "convert lod.vdb free"
[[ $("$vola" voxels "$tmp/lod_free.vol") == "0 0 0" ]] || fail "lod.vdb free cells: $("$vola" voxels "$tmp/lod_free.vol")"
"$vola" intersect "$tmp/lod_occupied.vol" "$tmp/lod_free.vol" "$tmp/lod_both.vol" -q || fail "intersect"
"$vola" info "$tmp/lod_both.vol" | grep -q "^voxels: *0 occupied" || fail "lod.vdb has cells both occupied and free"

# Plain trees take their free voxels from --free (here the state map's two halves; the
# union keeps no log-odds, so the occupied leaves get OctoMap's clamping maximum).
"$vola" union "$tmp/map.vol" "$tmp/map.vol" "$tmp/occupied.vol" -q || fail "union: the occupied voxels as a plain tree"
"$vola" export "$tmp/occupied.vol" "$tmp/plain.ot" --free "$tmp/map.free.vol" >"$tmp/out" || fail "export --free"
grep -q ": 2 occupied and 7 free voxels of 0.25" "$tmp/out" || fail "plain.ot summary: $(cat "$tmp/out")"
"$vola" convert "$tmp/plain.ot" "$tmp/plain_back.vol" -q || fail "convert plain.ot"
"$vola" coords "$tmp/plain_back.vol" | sort | cmp -s - <("$vola" coords "$tmp/map.vol" | sort) ||
  fail "plain.ot: the occupied voxels differ from the state map's"

# Errors.
# A voxel given as occupied and as free is refused by every map writer (the .vdb one wrote
# it into both grids).
for map in x.bt x.ot x.vdb; do
  expect_error "voxel (.*) is given as occupied and as free" "$vola" export "$tmp/occupied.vol" "$tmp/$map" --free "$tmp/occupied.vol"
done
expect_error "voxel (.*) is given as occupied and as free" "$vola" export "$tmp/occupied.vol" "$tmp/x.yaml" --band 0:1 \
  --free "$tmp/occupied.vol"
[[ ! -e $tmp/x.vdb ]] || fail "a refused map export wrote its output"
expect_error "is a state map and holds its free voxels" "$vola" export "$tmp/map.vol" "$tmp/x.ot" --free "$tmp/map.free.vol"
expect_error "is a map of 2 cells" "$vola" convert "$tmp/a.bt" "$tmp/x.vol" --voxel-size 3
expect_error "its grids: 'occupied'" "$vola" convert "$tmp/a.vdb" "$tmp/x.vol" --grid density
expect_error "applies to OpenVDB and .npz input only" "$vola" convert "$tmp/a.bt" "$tmp/x.vol" --grid occupied
expect_error "--free applies to .bt, .ot, .vdb and ROS (.yaml) maps" "$vola" export "$tmp/a.vol" "$tmp/x.ply" --free "$tmp/map.free.vol"
head -c 300 "$tmp/a.bt" >"$tmp/cut.bt"
expect_error "$tmp/cut.bt.*the node stream ends inside a node" "$vola" convert "$tmp/cut.bt" "$tmp/x.vol"
head -c 2000 "$tmp/a.vdb" >"$tmp/cut.vdb"
expect_error "$tmp/cut.vdb" "$vola" convert "$tmp/cut.vdb" "$tmp/x.vol"
[[ ! -e $tmp/x.vol ]] || fail "a failed conversion wrote its output"

# Set operations refuse one grid in two CRSs (UTM metres and, relabelled, Oregon feet):
# the same voxel indices are different places. --ignore-frame still combines them.
"$vola" convert "$las" "$tmp/utm.vol" --voxel-size 2 --origin 493000 4877000 100 -q || fail "convert utm"
"$vola" convert "$las" "$tmp/feet.vol" --voxel-size 2 --origin 493000 4877000 100 --assign-crs 2994 -q 2>/dev/null ||
  fail "convert feet"
expect_error "utm.vol is in NAD83 / UTM zone 10N (EPSG:26910)" "$vola" union "$tmp/utm.vol" "$tmp/feet.vol" "$tmp/u.vol"
expect_error "feet.vol in NAD83(HARN) / Oregon GIC Lambert (ft) (EPSG:2994)" "$vola" intersect "$tmp/utm.vol" "$tmp/feet.vol" "$tmp/u.vol"
expect_error "the same voxel indices are different places" "$vola" diff "$tmp/feet.vol" "$tmp/utm.vol"
"$vola" union "$tmp/utm.vol" "$tmp/feet.vol" "$tmp/u.vol" --ignore-frame -q || fail "--ignore-frame did not combine two CRSs"

# A robot's 2D map for ROS navigation (map_server YAML + PGM) from a scan of a room: a
# sensor 0.5 m above the floor of a 4 x 4 m room with a box 1 m high at (1, 0). For a
# robot 0.1-0.45 m high (the floor voxels are centred at 0.05), the walls and the box are
# obstacles, the space the rays crossed is free, and the box's shadow is unknown.
/usr/bin/python3 - "$tmp/room.xyz" <<'PYTHON' || fail "writing the room scan"
import sys
points = []
steps = [i / 10 - 1.95 for i in range(40)]          # -1.95 .. 1.95
for a in steps:
    for h in [i / 10 + 0.05 for i in range(15)]:     # walls 0 .. 1.5 m high
        for x, y in ((2.0, a), (-2.0, a), (a, 2.0), (a, -2.0)):
            points.append((x, y, h))
    for b in steps:
        if not (0.8 <= a <= 1.2 and -0.2 <= b <= 0.2):
            points.append((a, b, 0.0))               # floor
for a in [0.8 + i / 20 for i in range(9)]:
    for b in [-0.2 + i / 20 for i in range(9)]:
        points.append((a, b, 1.0))                   # the box's top
    for h in [i / 20 for i in range(21)]:
        points.append((0.8, a - 1.0, h))             # its side facing the sensor
def hidden(x, y, z):  # the segment from the sensor stops inside the box first (a slab test)
    start, end = (0.0, 0.0, 0.5), (x, y, z)
    low, high = 0.0, 0.999
    for s, e, lo, hi in zip(start, end, (0.8, -0.2, 0.0), (1.2, 0.2, 1.0)):
        if s == e:
            if not lo <= s <= hi:
                return False
            continue
        t0, t1 = sorted(((lo - s) / (e - s), (hi - s) / (e - s)))
        low, high = max(low, t0), min(high, t1)
    return low <= high
with open(sys.argv[1], "w") as out:
    for x, y, z in points:
        if not hidden(x, y, z):
            out.write(f"{x} {y} {z - 0.5}\n")        # in the sensor's frame
PYTHON
printf 'room.xyz 0 0 0.5 0 0 0 1\n' >"$tmp/room_list.txt"
"$vola" map "$tmp/room_list.txt" -o "$tmp/room.vol" --voxel-size 0.1 -q || fail "vola map of the room"
"$vola" export "$tmp/room.vol" "$tmp/room.yaml" --band 0.1:0.45 >"$tmp/out" 2>"$tmp/err" || fail "ROS map export: $(cat "$tmp/err")"
grep -q "ROS map (map_server YAML + PGM, trinary)" "$tmp/out" || fail "ROS map export said: $(cat "$tmp/out")"
grep -q "free voxels in the band" "$tmp/out" || fail "a state map's free voxels were not used: $(cat "$tmp/out")"
/usr/bin/python3 - "$tmp/room.yaml" <<'PYTHON' || fail "the room's ROS map"
import math, os, sys
fields = dict(line.split(": ", 1) for line in open(sys.argv[1]).read().splitlines())
assert fields["mode"] == "trinary" and fields["negate"] == "0", fields
resolution = float(fields["resolution"])
ox, oy, _ = (float(v) for v in fields["origin"].strip("[]").split(","))
data = open(os.path.join(os.path.dirname(sys.argv[1]), fields["image"]), "rb").read()
magic, width, height, maxval, pixels = data.split(maxsplit=4)
width, height = int(width), int(height)
assert magic == b"P5" and maxval == b"255" and len(pixels) == width * height, (magic, width, height, len(pixels))
def at(x, y):
    col, row = math.floor((x - ox) / resolution), height - 1 - math.floor((y - oy) / resolution)
    return pixels[row * width + col]
expected = {(2.0, 0.55): 0, (-2.0, -1.05): 0, (0.35, 2.0): 0, (0.85, 0.05): 0,  # walls, the box's near side
            (0.55, 0.55): 254, (-1.05, -1.05): 254, (-1.55, 0.35): 254,          # space the rays crossed
            (1.05, 0.05): 205, (1.55, 0.05): 205}                                # inside the box, its shadow
for (x, y), value in expected.items():
    assert at(x, y) == value, f"cell at ({x}, {y}) is {at(x, y)}, expected {value}"
PYTHON
# And back: the occupied cells as voxel columns 0.5 m high (five voxels of 0.1 m).
occupied=$(grep -o "[0-9]* occupied" "$tmp/out" | grep -o "[0-9]*")
"$vola" convert "$tmp/room.yaml" "$tmp/room_back.vol" --map-height 0.5 -q || fail "convert of the ROS map"
"$vola" info "$tmp/room_back.vol" | grep -q "voxels: *$((occupied * 5)) occupied" ||
  fail "the ROS map did not read back as $occupied columns of 5 voxels: $("$vola" info "$tmp/room_back.vol" | grep voxels)"
expect_error "map-height: applies to ROS map input only" "$vola" convert "$las" "$tmp/x.vol" --voxel-size 2 --map-height 1
expect_error "a ROS map needs the height band" "$vola" export "$tmp/room.vol" "$tmp/r2.yaml"
expect_error "holds no voxel centre of the map" "$vola" export "$tmp/room.vol" "$tmp/r2.yaml" --band 50:60
expect_error "band applies to a ROS map" "$vola" export "$tmp/room.vol" "$tmp/r2.ply" --band 0:1
[[ ! -e $tmp/r2.yaml && ! -e $tmp/r2.pgm ]] || fail "a refused ROS map export wrote a file"

if [[ $failures -ne 0 ]]; then
  echo "cli_maps: $failures failure(s)" >&2
  exit 1
fi
echo "cli_maps: ok"
