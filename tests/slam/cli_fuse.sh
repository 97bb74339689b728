#!/usr/bin/env bash
# vola rgbd-generate -> vola fuse -> vola rgbd-eval on a small room sequence, and the
# errors fuse gives for a folder that is not a sequence and for a broken depth list.
set -euo pipefail
vola=$1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

"$vola" rgbd-generate "$work/seq" --frames 12 --width 160 --height 120 --seed 3 > "$work/gen.txt"
grep -q "12 frames of 160 x 120" "$work/gen.txt"
test -f "$work/seq/depth.txt" && test -f "$work/seq/rgb.txt" && test -f "$work/seq/groundtruth.txt"
test "$(grep -vc '^#' "$work/seq/depth.txt")" -eq 12

"$vola" fuse "$work/seq" -o "$work/map.vol" --trajectory "$work/est.txt" --mesh "$work/map.ply" \
  --render "$work/view.png" --voxel-size 0.02 --threads 2 > "$work/fuse.txt"
cat "$work/fuse.txt"
grep -q "12 frames (0 lost)" "$work/fuse.txt"
grep -q "^ATE: RMSE" "$work/fuse.txt"
test "$(grep -vc '^#' "$work/est.txt")" -eq 12
head -c 3 "$work/map.ply" | grep -q ply
grep -aq "element face" "$work/map.ply"
"$vola" info "$work/map.vol" > "$work/info.txt"
grep -qi "red" "$work/info.txt"
test "$(head -c 4 "$work/view.png" | tail -c 3)" = "PNG"

"$vola" rgbd-eval "$work/seq/groundtruth.txt" "$work/est.txt" > "$work/eval.txt"
cat "$work/eval.txt"
awk '$1 == "ate_rmse_m" { exit !($2 < 0.03) }' "$work/eval.txt"

# Errors: the exit status is non-zero and the message names the problem.
mkdir "$work/empty"
if "$vola" fuse "$work/empty" -o "$work/x.vol" 2> "$work/err.txt"; then exit 1; fi
grep -q "no depth.txt" "$work/err.txt"
# Depth in another unit than --depth-factor says (every depth below --min-depth): no
# surface, said as such (it was an error about a --depth option fuse does not have).
if "$vola" fuse "$work/seq" -o "$work/x.vol" --depth-factor 1e9 --groundtruth-poses 2> "$work/err.txt"; then exit 1; fi
grep -q "the frames made no surface: no depth was measured within --min-depth..--max-depth" "$work/err.txt"
test ! -e "$work/x.vol"
printf '1.0 depth/000000.png\nbad line here\n' > "$work/seq/depth.txt"
if "$vola" fuse "$work/seq" -o "$work/x.vol" 2> "$work/err.txt"; then exit 1; fi
grep -q "depth.txt: line 2" "$work/err.txt"
echo "cli_fuse: ok"
