#!/usr/bin/env bash
# A CRS that names a file must not make GDAL open it (docs/SECURITY.md, "no escapes").
#
#   cli_gdal_crs_files.sh VOLA_BINARY PYTHON
#
# A WKT's EXTENSION["PROJ4", "+init=FILE:id"] is followed by PROJ when GDAL builds a
# transformation with the CRS, and GDAL's PROJ contexts are not confined as vola's are.
# The named FILE here is a FIFO: a process that opens it blocks, so `timeout` tells an
# open from a refusal. gdalinfo, when installed, shows the trap works (it blocks). Then
# vola must refuse, promptly and by name, a GeoTIFF carrying such a CRS (GDAL reads
# it), a LAS carrying it in `vola tile` (footprints through OGR), and a .vol carrying it
# in a GeoTIFF export.
set -uo pipefail

if [[ $# -ne 2 ]]; then
  echo "usage: $0 VOLA_BINARY PYTHON" >&2
  exit 2
fi
vola=$(realpath "$1")
python=$2
keep_going=1
source "$(dirname "$0")/../lib/cli_test.sh"
cd "$tmp" || exit 1

mkfifo trap.init
wkt='PROJCS["x",GEOGCS["WGS 84",DATUM["WGS_1984",SPHEROID["WGS 84",6378137,298.257223563]],PRIMEM["Greenwich",0],UNIT["degree",0.0174532925199433]],PROJECTION["Transverse_Mercator"],PARAMETER["latitude_of_origin",0],PARAMETER["central_meridian",15],PARAMETER["scale_factor",0.9996],PARAMETER["false_easting",500000],PARAMETER["false_northing",0],UNIT["metre",1],EXTENSION["PROJ4","+init='"$tmp"'/trap.init:site +wktext"]]'

# A 2 x 2 GeoTIFF whose CRS is a user-defined model with that WKT as its ESRI PE string
# (the citation GDAL reads the CRS from), written byte by byte.
"$python" - "$wkt" <<'PYEOF'
import struct, sys
citation = ("ESRI PE String = " + sys.argv[1] + "|").encode() + b"\0"
keys = [1, 1, 0, 3, 1024, 0, 1, 32767, 1025, 0, 1, 1, 3073, 34737, len(citation) - 1, 0]
tags = [(256, 3, 1, struct.pack("<H", 2)), (257, 3, 1, struct.pack("<H", 2)), (258, 3, 1, struct.pack("<H", 8)),
        (259, 3, 1, struct.pack("<H", 1)), (262, 3, 1, struct.pack("<H", 1)), (273, 4, 1, None),
        (277, 3, 1, struct.pack("<H", 1)), (278, 3, 1, struct.pack("<H", 2)), (279, 4, 1, struct.pack("<I", 4)),
        (33550, 12, 3, struct.pack("<3d", 1, 1, 0)), (33922, 12, 6, struct.pack("<6d", 0, 0, 0, 500000, 5000000, 0)),
        (34735, 3, len(keys), struct.pack("<%dH" % len(keys), *keys)), (34737, 2, len(citation), citation)]
data_at = 8 + 2 + 12 * len(tags) + 4
extra, entries = bytes([10, 20, 30, 40]), b""
for tag, kind, count, payload in tags:
    payload = struct.pack("<I", data_at) if payload is None else payload
    if len(payload) <= 4:
        entries += struct.pack("<HHI", tag, kind, count) + payload.ljust(4, b"\0")
    else:
        extra += b"\0" * (len(extra) % 2)
        entries += struct.pack("<HHII", tag, kind, count, data_at + len(extra))
        extra += payload
open("trap.tif", "wb").write(b"II*\0" + struct.pack("<IH", 8, len(tags)) + entries + b"\0\0\0\0" + extra)
PYEOF

if command -v gdalinfo > /dev/null; then
  timeout 10 gdalinfo trap.tif > /dev/null 2>&1
  [[ $? -eq 124 ]] || echo "note: gdalinfo did not block on the FIFO (this GDAL or PROJ does not follow the string)" >&2
fi

# refused NAME EXPECTED_TEXT COMMAND...: exit 1 within 30 s, the reference named.
refused() {
  local name=$1 expected=$2
  shift 2
  local message status
  message=$(timeout 30 "$@" 2>&1)
  status=$?
  [[ $status -ne 124 ]] || fail "$name: blocked on the FIFO (the named file was opened)"
  [[ $status -eq 1 ]] || fail "$name: exit status $status, expected 1"
  [[ $message == *"$expected"* && $message == *"+init="* ]] || fail "$name: message '$message'"
}

refused "DEM with a file-naming CRS" "trap.tif" "$vola" convert trap.tif dem.vol --voxel-size 1 -q

printf '500000 5000000 0\n500001 5000001 1\n500002 5000000 2\n' > points.xyz
"$vola" convert points.xyz crs.vol --voxel-size 1 --assign-crs "$wkt" -q || fail "convert with the WKT assigned"
timeout 30 "$vola" export crs.vol crs.las -q || fail "LAS export"
refused "GeoTIFF export" "names a file" "$vola" export crs.vol crs.tif --raster dsm -q
refused "tile" "names a file" "$vola" tile crs.las -o tiles --tile-size 64 --depth 3 -q

# The same survey with a CRS that names no file tiles as before (@null is PROJ's own grid).
nullgrid=${wkt//+init=$tmp\/trap.init:site/+proj=utm +zone=33 +datum=WGS84 +nadgrids=@null}
"$vola" convert points.xyz ok.vol --voxel-size 1 --assign-crs "$nullgrid" -q || fail "convert with a @null grid"
timeout 30 "$vola" export ok.vol ok.tif --raster dsm -q || fail "GeoTIFF export with a @null grid"

if ((failures > 0)); then
  echo "$failures failure(s)" >&2
  exit 1
fi
echo "cli_gdal_crs_files: all passed"
