#!/usr/bin/env bash
# The vola command-line tool against the reference implementation's golden files.
#
#   golden_cli.sh VOLA_BINARY GOLDEN_DIR
#
# For every case of GOLDEN_DIR/MANIFEST.tsv: `vola convert` the case's input.txt with
# its parameters and compare the output with the reference file byte for byte, except
# bytes 16..31 (lat, lon: float64, compared within 1e-9 degree because PROJ versions
# may differ in the last bits); then check `vola voxels` (sorted) against
# expected_voxels.txt and, for nbits cases, `vola voxels --payload` against
# spec_voxels.txt. The two documented differences are checked, not skipped:
#   zero_payload_sparse  the reference file is corrupt (a zero payload word dropped):
#                        `vola voxels` must refuse it; ours is the reference plus one
#                        zero word in a level-1 payload slot (144 bytes, not 136).
#   single_point_dense   the reference crashed and wrote nothing: ours must be a valid
#                        dense file whose only voxel is (0,0,0), with the header of
#                        single_point_sparse but for the mode byte.
# Exit status: 0 all good, 1 failures, 77 golden folder missing (outside CI).
set -uo pipefail

if [[ $# -ne 2 ]]; then
  echo "usage: $0 VOLA_BINARY GOLDEN_DIR" >&2
  exit 2
fi
vola=$1
golden=$2
if [[ ! -x $vola ]]; then
  echo "FAIL: $vola is not an executable" >&2
  exit 1
fi
if [[ ! -f $golden/MANIFEST.tsv ]]; then
  if [[ -n ${CI:-} ]]; then
    echo "FAIL: golden folder $golden is missing (CI is set)" >&2
    exit 1
  fi
  echo "SKIP: golden folder $golden is missing" >&2
  exit 77
fi

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
failures=0
fail() {
  echo "FAIL [$case_name]: $*" >&2
  failures=$((failures + 1))
}

# params.json field as text (lists joined by spaces); "" when absent.
param() {
  python3 - "$1" "$2" <<'PY'
import json, sys
p = json.load(open(sys.argv[1]))
v = p.get(sys.argv[2])
if v is None:
    print("")
elif sys.argv[2] == "bbox":
    # min x y z then max x y z, repr() keeps every bit of the float64
    print(" ".join(repr(float(c)) for c in v[0] + v[1]))
else:
    print(v)
PY
}

# Compares two files: equal size, no differing byte outside 16..31 (cmp -l counts
# from 1, so 17..32), lat/lon within 1e-9. Prints why on a difference.
same_file() {
  local ref=$1 ours=$2
  local ref_size ours_size
  ref_size=$(stat -c %s "$ref")
  ours_size=$(stat -c %s "$ours")
  if [[ $ref_size != "$ours_size" ]]; then
    echo "sizes differ: reference $ref_size, ours $ours_size"
    return 1
  fi
  local outside
  outside=$(cmp -l "$ref" "$ours" | awk '$1 < 17 || $1 > 32 { print $1 - 1; exit }')
  if [[ -n $outside ]]; then
    echo "first difference outside lat/lon at byte $outside"
    return 1
  fi
  python3 - "$ref" "$ours" <<'PY'
import struct, sys
a = open(sys.argv[1], "rb").read()[16:32]
b = open(sys.argv[2], "rb").read()[16:32]
(lat_a, lon_a), (lat_b, lon_b) = struct.unpack("<2d", a), struct.unpack("<2d", b)
if not (abs(lat_a - lat_b) <= 1e-9 and abs(lon_a - lon_b) <= 1e-9):
    print(f"lat/lon differ: reference {lat_a!r} {lon_a!r}, ours {lat_b!r} {lon_b!r}")
    sys.exit(1)
PY
}

# `vola voxels FILE` sorted, against a sorted "x y z" list.
check_voxels() {
  local file=$1 expected=$2 what=$3
  if ! "$vola" voxels "$file" < /dev/null > "$tmp/voxels.txt" 2> "$tmp/voxels.err"; then
    fail "vola voxels $what failed: $(head -c 300 "$tmp/voxels.err")"
    return
  fi
  if ! diff -q <(sort "$tmp/voxels.txt") <(sort "$expected") > /dev/null; then
    fail "vola voxels $what differs from $(basename "$expected") ($(wc -l < "$tmp/voxels.txt") vs $(wc -l < "$expected") lines)"
  fi
}

# `vola voxels FILE --payload` ("x y z 0x<hex>") against spec_voxels.txt ("x y z hex").
check_payloads() {
  local file=$1 spec=$2 what=$3
  if ! "$vola" voxels "$file" --payload < /dev/null > "$tmp/payload.txt" 2> "$tmp/payload.err"; then
    fail "vola voxels --payload $what failed: $(head -c 300 "$tmp/payload.err")"
    return
  fi
  if ! grep -qE '^[0-9]+ [0-9]+ [0-9]+ 0x[0-9a-fA-F]{16}$' "$tmp/payload.txt"; then
    fail "vola voxels --payload $what: lines are not 'x y z 0x<16 hex digits>'"
    return
  fi
  if ! diff -q <(sed 's/ 0x/ /' "$tmp/payload.txt" | tr 'A-F' 'a-f' | sort) <(tr 'A-F' 'a-f' < "$spec" | sort) > /dev/null; then
    fail "vola voxels --payload $what differs from $(basename "$spec")"
  fi
}

checked=0
rows=0
while IFS=$'\t' read -r case_name depth mode nbits crs _npoints _nvoxels vol_file _vol_size _sha; do
  [[ -z $case_name || $case_name == case ]] && continue
  rows=$((rows + 1))
  dir=$golden/$case_name
  ours=$tmp/$case_name.out

  args=(convert "$dir/input.txt" "$ours" --quantize toolkit --depth "$depth" --assign-crs "$crs")
  [[ $mode == 1 ]] && args+=(--dense)
  [[ $nbits != 0 ]] && args+=(--nbits 1)
  # A bbox that is not the points' own min/max (fixed_bbox_clip) must be passed.
  if [[ $(param "$dir/params.json" bbox_source) == fixed ]]; then
    read -r -a bbox <<< "$(param "$dir/params.json" bbox)"
    args+=(--bbox "${bbox[@]}")
  fi
  if ! "$vola" "${args[@]}" < /dev/null > "$tmp/convert.log" 2>&1; then
    fail "vola ${args[*]} failed: $(tail -c 300 "$tmp/convert.log")"
    continue
  fi

  if [[ $vol_file == None ]]; then
    # The reference wrote nothing; only single_point_dense is documented so.
    if [[ $case_name != single_point_dense ]]; then
      fail "no reference file, and this is not the documented single_point_dense case"
      continue
    fi
    words=0
    for ((level = 0; level < depth; level++)); do words=$((words + (1 << (6 * level)))); done
    size=$(stat -c %s "$ours")
    [[ $size == $((80 + 8 * words)) ]] || fail "dense file is $size bytes, expected $((80 + 8 * words))"
    [[ $(od -An -tu1 -j6 -N1 "$ours" | tr -d ' ') == 1 ]] || fail "mode byte is not 1 (dense)"
    check_voxels "$ours" "$dir/expected_voxels.txt" "of our file"
    # Header = single_point_sparse's header with mode 1.
    head -c 80 "$golden/single_point_sparse/single_point_sparse.vol" > "$tmp/ref_header"
    head -c 80 "$ours" | python3 -c 'import sys; b = bytearray(sys.stdin.buffer.read()); b[6] = 0; sys.stdout.buffer.write(b)' > "$tmp/our_header"
    msg=$(same_file "$tmp/ref_header" "$tmp/our_header") || fail "header differs from single_point_sparse's: $msg"
    checked=$((checked + 1))
    continue
  fi

  ref=$dir/$vol_file
  if [[ $vol_file == *.gz ]]; then
    ref=$tmp/$case_name.ref
    gzip -dc -- "$dir/$vol_file" > "$ref" || { fail "cannot gunzip $vol_file"; continue; }
  fi

  if [[ $case_name == zero_payload_sparse ]]; then
    if "$vola" voxels "$ref" < /dev/null > /dev/null 2>&1; then
      fail "vola voxels accepted the corrupt reference file"
    fi
    # Ours minus the first 8-byte word where it departs from the reference must be
    # the reference, and that word must be zero.
    msg=$(python3 - "$ref" "$ours" <<'PY'
import struct, sys
def die(message):
    print(message)
    sys.exit(1)
ref = open(sys.argv[1], "rb").read()
ours = open(sys.argv[2], "rb").read()
if len(ours) != len(ref) + 8:
    die(f"ours is {len(ours)} bytes, expected {len(ref) + 8}")
diff = next((i for i in range(96, len(ref)) if ref[i] != ours[i]), len(ref))
slot = diff - diff % 8
if ours[slot:slot + 8] != bytes(8):
    die(f"the word at byte {slot} where ours departs from the reference is not zero")
rest = ours[:slot] + ours[slot + 8:]
if rest[:16] != ref[:16] or rest[32:] != ref[32:]:
    die("ours without the zero word differs from the reference")
a, b = struct.unpack("<2d", ref[16:32]), struct.unpack("<2d", rest[16:32])
if any(abs(x - y) > 1e-9 for x, y in zip(a, b)):
    die(f"lat/lon differ: {a} vs {b}")
n1 = bin(struct.unpack("<Q", ref[80:88])[0]).count("1")
if not 96 + 8 * n1 <= slot < 96 + 16 * n1:
    die(f"the zero word at byte {slot} is not a level-1 payload slot")
PY
) || fail "$msg"
    check_voxels "$ours" "$dir/expected_voxels.txt" "of our file"
    check_payloads "$ours" "$golden/zero_payload_dense/spec_voxels.txt" "of our file"
    checked=$((checked + 1))
    continue
  fi

  msg=$(same_file "$ref" "$ours") || fail "output differs from $vol_file: $msg"
  check_voxels "$ours" "$dir/expected_voxels.txt" "of our file"
  check_voxels "$ref" "$dir/expected_voxels.txt" "of the reference file"
  if [[ $nbits != 0 ]]; then
    check_payloads "$ref" "$dir/spec_voxels.txt" "of the reference file"
    check_payloads "$ours" "$dir/spec_voxels.txt" "of our file"
  fi
  checked=$((checked + 1))
done < "$golden/MANIFEST.tsv"

if [[ $rows == 0 ]]; then
  echo "FAIL: no cases in $golden/MANIFEST.tsv" >&2
  exit 1
fi
echo "golden_cli: $checked of $rows cases checked, $failures failures"
[[ $failures == 0 && $checked == "$rows" ]]
