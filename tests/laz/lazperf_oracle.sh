#!/usr/bin/env bash
# laz-perf (npm, an independent LAZ implementation) as the oracle of vola's LAZ codec,
# through the CLI:
#  - every LAZ/COPC in the shared data: laz-perf's records equal vola translate's;
#  - every shared LAS of point formats 0-3 and 6-8, compressed by vola translate, and .vol
#    files exported as LAZ: laz-perf decodes them back to the LAS records.
# Usage: lazperf_oracle.sh VOLA NODE LAZPERF_PACKAGE SHARED_DATA_DIR ($VOLA_SHARED/data wins)
set -euo pipefail
vola=$1 node=$2 lazperf=$3 data=${VOLA_SHARED:+$VOLA_SHARED/data}
data=${data:-$4}
here=$(cd "$(dirname "$0")" && pwd)
source "$(dirname "$0")/../lib/cli_test.sh"
[ -d "$data/laz" ] || skip "no $data/laz (set VOLA_SHARED)"
[ -f "$lazperf/package.json" ] || fail "laz-perf is not installed at $lazperf (the build runs npm ci for it)"

# The point records of a LAS file (count x record length bytes after the offset).
records_of() {
  python3 - "$1" "$2" <<'PY'
import struct, sys
d = open(sys.argv[1], "rb").read()
offset, length = struct.unpack_from("<I", d, 96)[0], struct.unpack_from("<H", d, 105)[0]
count = struct.unpack_from("<I", d, 107)[0]
if d[25] >= 4 and count == 0:
    count = struct.unpack_from("<Q", d, 247)[0]
open(sys.argv[2], "wb").write(d[offset:offset + count * length])
PY
}

mkdir "$tmp/shared" "$tmp/written"
for laz in "$data"/laz/*.laz; do
  name=$(basename "$laz" .laz)
  cp "$laz" "$tmp/shared/$name.laz"
  "$vola" translate "$laz" "$tmp/decoded.las" -q
  records_of "$tmp/decoded.las" "$tmp/shared/$name.records"
done
for las in "$data"/las/*.las "$data"/las/permutations/*.las; do
  format=$(python3 -c "import sys; print(open(sys.argv[1], 'rb').read(105)[104] & 63)" "$las")
  case $format in 4|5|9|10) continue ;; esac
  name=$(basename "$las" .las)
  "$vola" translate "$las" "$tmp/written/$name.laz" -q
  records_of "$las" "$tmp/written/$name.records"
done
# vola export of a .vol with attribute columns (point format 7, extra bytes) as LAZ: the
# records of its LAS export.
"$vola" convert "$data/las/pdal_autzen_trim.las" "$tmp/autzen.vol" --voxel-size 2 -q
"$vola" convert "$data/las/pdal_extrabytes.las" "$tmp/extra.vol" --voxel-size 1 -q
for name in autzen extra; do
  "$vola" export "$tmp/$name.vol" "$tmp/written/export_$name.laz" -q
  "$vola" export "$tmp/$name.vol" "$tmp/export_$name.las" -q
  records_of "$tmp/export_$name.las" "$tmp/written/export_$name.records"
done
"$node" "$here/lazperf_roundtrip.mjs" "$lazperf" "$tmp/shared" || fail "vola's decoding of the shared LAZ files differs from laz-perf's"
"$node" "$here/lazperf_roundtrip.mjs" "$lazperf" "$tmp/written" || fail "laz-perf does not decode vola's LAZ to the LAS's records"
