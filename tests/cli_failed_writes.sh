#!/usr/bin/env bash
# Failed writes and killed processes leave the old file intact and no temporary.
#
#   cli_failed_writes.sh VOLA_BINARY SHARED_DIR      ($VOLA_SHARED overrides SHARED_DIR)
#
# Each writer runs with a file-size limit of 0 (`ulimit -f 0`, SIGXFSZ ignored), so every
# write to a regular file fails with EFBIG, over an existing output holding "old": the
# command must exit 1 with a message (not a signal), the output must still say "old",
# and no .part file may be left. Then `vola generate` of a large scene is killed with
# SIGTERM, SIGINT and SIGKILL while its temporary is being written: it must die of that
# signal with the old output intact and no temporary left (the temporary is an unnamed
# O_TMPFILE file, found through /proc/PID/fd). Finally a cut WAV is refused.
# Exit status: 0 all good, 1 failures, 77 shared folder missing (outside CI).
set -uo pipefail

if [[ $# -ne 2 ]]; then
  echo "usage: $0 VOLA_BINARY SHARED_DIR" >&2
  exit 2
fi
vola=$(realpath "$1")
shared=$(realpath "${VOLA_SHARED:-$2}")
keep_going=1
source "$(dirname "$0")/lib/cli_test.sh"
dry=$shared/data/audio/codec2_speech_orig_16k.wav
[[ -f $dry ]] || skip "$dry is missing"
work=$tmp
cd "$work" || exit 1

# A 6 x 4 x 3 m room of 25 cm voxels (for sonify and plan) and a generated city.
awk 'BEGIN { for (i = 0; i <= 24; i++) for (j = 0; j <= 16; j++) for (k = 0; k <= 12; k++)
  if (i == 0 || i == 24 || j == 0 || j == 16 || k == 0 || k == 12) print i * 0.25, j * 0.25, k * 0.25 }' > room.xyz
"$vola" convert room.xyz room.vol --voxel-size 0.25 > /dev/null || fail "convert room"
"$vola" generate city city.xyz --points 20000 > /dev/null 2>&1 || fail "generate city"
"$vola" convert city.xyz city.vol --voxel-size 2 > /dev/null || fail "convert city"

# fails_keeping NAME OUTPUT COMMAND...: COMMAND writes OUTPUT under a zero file-size limit.
fails_keeping() {
  local name=$1 output=$2
  shift 2
  mkdir -p out && rm -f out/*
  echo old > "out/$output"
  local message status
  # stderr to a pipe: the limit applies to regular files only.
  message=$( (trap '' XFSZ; ulimit -f 0; exec "$@") 2>&1 >/dev/null)
  status=$?
  [[ $status -eq 1 ]] || fail "$name: exit status $status, expected 1 ($message)"
  [[ -n $message ]] || fail "$name: no message"
  [[ $(cat "out/$output") == old ]] || fail "$name: the old $output was replaced or cut ($(stat -c %s "out/$output") bytes)"
  local left
  left=$(ls out | grep -v "^$output\$")
  [[ -z $left ]] || fail "$name: left behind: $left"
}

fails_keeping "convert .vol" c.vol "$vola" convert city.xyz out/c.vol --voxel-size 1
fails_keeping "generate" g.xyz "$vola" generate city out/g.xyz --points 5000
fails_keeping "export binvox" e.binvox "$vola" export city.vol out/e.binvox -q
fails_keeping "export ply" e.ply "$vola" export city.vol out/e.ply -q
fails_keeping "export png map" e.png "$vola" export city.vol out/e.png --map -q
fails_keeping "export tif raster" e.tif "$vola" export city.vol out/e.tif --raster dsm -q
fails_keeping "render png" r.png "$vola" render city.vol -o out/r.png --size 64x48 -q
fails_keeping "plan csv" p.csv "$vola" plan room.vol --from 1 1 1 --to 5 3 2 -o out/p.csv -q
fails_keeping "sonify wav" s.wav "$vola" sonify room.vol --source 2 1.5 1.25 --listener 4 3 2 --in "$dry" \
  --out out/s.wav -q

# temporary_with_bytes PID DIR: true once PID has a file open in DIR, unnamed or named
# .part, that holds bytes.
temporary_with_bytes() {
  local fd target
  for fd in /proc/"$1"/fd/*; do
    target=$(readlink "$fd" 2> /dev/null) || continue
    [[ $target == "$2"/* && ( $target == *"(deleted)" || $target == *.part ) ]] || continue
    [[ $(stat -L -c %s "$fd" 2> /dev/null || echo 0) -gt 0 ]] && return 0
  done
  return 1
}

# killed_while_writing SIGNAL: generate a scene large enough to take seconds to write,
# kill it once its temporary holds bytes.
killed_while_writing() {
  local signal=$1
  mkdir -p big && rm -f big/*
  echo old > big/city.xyz
  # A background job of a script starts with SIGINT ignored: give it the default back
  # (SIGKILL's cannot be changed).
  local defaults=(env --default-signal="$signal")
  [[ $signal == KILL ]] && defaults=()
  "${defaults[@]}" "$vola" generate city big/city.xyz --points 50000000 > /dev/null 2>&1 &
  local pid=$! writing="" i
  for ((i = 0; i < 500; i++)); do
    temporary_with_bytes "$pid" "$PWD/big" && writing=yes && break
    sleep 0.02
  done
  [[ -n $writing ]] || fail "SIG$signal: no temporary appeared"
  kill -s "$signal" "$pid"
  wait "$pid"
  local status=$?
  local expected=$((128 + $(kill -l "$signal")))
  [[ $status -eq $expected ]] || fail "SIG$signal: exit status $status, expected $expected (killed by the signal)"
  [[ $(cat big/city.xyz) == old ]] || fail "SIG$signal: the old output was replaced or cut"
  local left
  left=$(ls big | grep -v '^city.xyz$')
  [[ -z $left ]] || fail "SIG$signal: left behind: $left"
}
killed_while_writing TERM
killed_while_writing INT
killed_while_writing KILL

# A WAV cut in its data chunk: libsndfile would read the shorter sound without a word.
size=$(stat -c %s "$dry")
head -c $((size / 2)) "$dry" > cut.wav
message=$("$vola" sonify room.vol --source 2 1.5 1.25 --listener 4 3 2 --in cut.wav --out cut_out.wav -q 2>&1)
status=$?
[[ $status -eq 1 ]] || fail "cut WAV: exit status $status, expected 1"
[[ $message == *"cut.wav: byte "*"the file is cut"* ]] || fail "cut WAV: message '$message' names no file, offset and cause"
[[ ! -e cut_out.wav ]] || fail "cut WAV: an output was written"

# What an output path holds is not replaced unless it is a regular, writable file: a
# rename onto /dev/null or a FIFO would replace the node itself, a read-only survey would
# be lost; a link is written through. And no command writes over its own input.
mkdir -p special
mkfifo special/pipe.ply
refused() {  # refused NAME PATTERN COMMAND...: exit 1 with a message matching PATTERN
  local name=$1 pattern=$2
  shift 2
  local message status
  message=$("$@" 2>&1)
  status=$?
  [[ $status -eq 1 ]] || fail "$name: exit status $status, expected 1 ($message)"
  [[ $message == *$pattern* ]] || fail "$name: message '$message' does not say '$pattern'"
}
refused "export to a FIFO" "pipe.ply: is a FIFO" "$vola" export city.vol special/pipe.ply -q
[[ -p special/pipe.ply ]] || fail "the FIFO was replaced"
refused "export to /dev/null" "/dev/null: is a character device" "$vola" export city.vol /dev/null --format xyz -q
[[ -c /dev/null ]] || fail "/dev/null is no longer a device"
cp city.vol special/kept.vol
chmod 444 special/kept.vol
refused "convert over a read-only file" "kept.vol: is read-only" "$vola" convert room.xyz special/kept.vol --voxel-size 1 -q
cmp -s city.vol special/kept.vol || fail "the read-only file was replaced"
ln -s ../city.vol special/link.vol
refused "export over its input" "is the input: vola export writes another file" \
  "$vola" export special/link.vol city.vol --format xyz -q
# A PNG, CSV, WAV or map written over the scene, recording or scan list it comes from:
# refused (render, plan, sonify and map replaced their input and exited 0).
cp room.vol special/scene.vol
cp "$dry" special/dry.wav
refused "render over its input" "scene.vol is the input: vola render writes new files" \
  "$vola" render special/scene.vol -o special/scene.vol --size 32x24 -q
refused "plan over its input" "scene.vol is the input: vola plan writes new files" \
  "$vola" plan special/scene.vol --from 1 1 1 --to 5 3 2 -o special/scene.vol -q
refused "sonify over its recording" "dry.wav is the input: vola sonify writes new files" \
  "$vola" sonify special/scene.vol --source 1 1 1 --listener 5 3 2 --in special/dry.wav --out special/dry.wav -q
for op in "lod --depth 2" "dilate --radius 1" "crop --min 0,0,0 --max 3,3,3"; do
  # shellcheck disable=SC2086
  refused "${op%% *} over its input" "scene.vol is the input: vola ${op%% *} writes new files" \
    "$vola" ${op%% *} special/scene.vol special/scene.vol ${op#* } -q
done
refused "union over an input" "scene.vol is the input: vola union writes new files" \
  "$vola" union room.vol special/scene.vol special/scene.vol -q
cp room.vol special/removed.vol
refused "diff --outputs over an input" "removed.vol is the input: vola diff writes new files" \
  "$vola" diff room.vol special/removed.vol --outputs special -q
cmp -s room.vol special/removed.vol || fail "diff --outputs replaced its input"
cmp -s room.vol special/scene.vol || fail "an output replaced the scene"
cmp -s "$dry" special/dry.wav || fail "sonify replaced the recording"
cp room.xyz special/scan.xyz
echo "scan.xyz 0 0 0 0 0 0 1" > special/scanlist.txt
refused "map over its scan list" "scanlist.txt is the input: vola map writes new files" \
  "$vola" map special/scanlist.txt -o special/scanlist.txt --voxel-size 1 -q
refused "map over a scan" "scan.xyz is the input: vola map writes new files" \
  "$vola" map special/scanlist.txt -o special/scan.xyz --voxel-size 1 -q
cp room.vol special/target.vol
ln -s target.vol special/through.vol
"$vola" lod city.vol --depth 2 special/through.vol > /dev/null || fail "writing through a link failed"
[[ -L special/through.vol ]] || fail "the link was replaced by a file"
cmp -s room.vol special/target.vol && fail "the link's target was not written"

# A FIFO named as an input blocked the reader forever (convert, info, map): refused.
mkfifo special/in.las special/in.xyz special/in.vol
echo "in.xyz 0 0 0 0 0 0 1" > special/scans.txt
refused "info of a FIFO" "not a regular file" timeout 20 "$vola" info special/in.las
refused "convert of a FIFO" "not a regular file" timeout 20 "$vola" convert special/in.xyz special/x.vol --voxel-size 1 -q
refused "translate of a FIFO" "not a regular file" timeout 20 "$vola" translate special/in.las special/x.ply -q
refused "map of a FIFO scan" "not a regular file" timeout 20 "$vola" map special/scans.txt -o special/m.vol --voxel-size 1 -q
refused "info of a FIFO .vol" "not a regular file" timeout 20 "$vola" info special/in.vol

if [[ $failures -ne 0 ]]; then
  echo "$failures failure(s)" >&2
  exit 1
fi
echo "all failed writes kept the old files"
