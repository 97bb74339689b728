#!/usr/bin/env bash
# vola dataset / train / classify / evaluate end to end on a small generated npz and the
# committed model. Usage: cli_learn.sh VOLA_BINARY DATA_DIR
set -euo pipefail
vola=$1
data=$2
source "$(dirname "$0")/../lib/cli_test.sh"
work=$tmp

# 20 samples: two per class, cut from the real training split (rows 0, 120, ... spread over classes).
npz=$data/modelnet/modelnet10_32_train.npz
[[ -f $npz ]] || skip "no $npz"
/usr/bin/python3 - "$npz" "$work/small.npz" <<'PY'
import sys, numpy as np
d = np.load(sys.argv[1]); X, y = d["X_train"], d["y_train"]
rows = np.concatenate([np.nonzero(y == k)[0][:2] for k in range(10)])
np.savez_compressed(sys.argv[2], X_test=X[rows].astype(np.int32), y_test=y[rows])
np.savez_compressed(sys.argv[2] + ".bad.npz", X_test=X[rows][:, :, :, :16], y_test=y[rows])
PY

# Clean objects: the test split is written whole, ten class folders of two files.
"$vola" dataset "$work/small.npz" "$work/clean" > "$work/out.txt"
[[ $(find "$work/clean/test" -name '*.vol' | wc -l) == 20 ]] || fail "expected 20 files"
[[ -f $work/clean/test/night_stand/night_stand_00012.vol ]] || fail "layout: $(ls "$work/clean/test")"
"$vola" info "$work/clean/test/chair/chair_00004.vol" | grep -q "depth" || fail "not a VOLA file"
# A second run into the same folders would mix its samples with the first's (another
# seed's validation split put objects in train/ and val/ at once): refused unless
# --overwrite, which leaves exactly the new run's files.
if "$vola" dataset "$work/small.npz" "$work/clean" 2> "$work/err.txt" > /dev/null; then fail "a used folder was taken"; fi
grep -q "test already holds 20 samples .*--overwrite" "$work/err.txt" || fail "used folder: $(cat "$work/err.txt")"
touch "$work/clean/test/notes.txt"
"$vola" dataset "$work/small.npz" "$work/clean" --overwrite > /dev/null
[[ $(find "$work/clean/test" -name '*.vol' | wc -l) == 20 && -f $work/clean/test/notes.txt ]] ||
  fail "--overwrite: $(find "$work/clean/test" | wc -l) entries"

# Objects in rooms: more voxels than the clean ones.
"$vola" dataset "$work/small.npz" "$work/room" --background > /dev/null
clean_size=$(stat -c %s "$work/clean/test/sofa/sofa_00014.vol")
room_size=$(stat -c %s "$work/room/test/sofa/sofa_00014.vol")
(( room_size > clean_size )) || fail "room file not bigger ($room_size <= $clean_size)"

# Meshes: the class from the file name.
"$vola" dataset "$data/modelnet/off/bathtub_0001.off" "$work/meshes" > /dev/null
[[ -f $work/meshes/bathtub/bathtub_0001.vol ]] || fail "mesh not written"
# A folder of meshes can be added to: a second run keeps the first's files.
"$vola" dataset "$data/modelnet/off/gomesh_normalized_chair_0001.off" "$work/meshes" > /dev/null ||
  fail "a second mesh run into the same folder was refused"
[[ -f $work/meshes/bathtub/bathtub_0001.vol && -f $work/meshes/chair/gomesh_normalized_chair_0001.vol ]] ||
  fail "mesh runs do not add up"

# Evaluate with the committed model: 14 of these are training samples and 6 are in the
# balanced validation split (--validation-per-class 100), so nearly all are right.
"$vola" evaluate "$work/clean/test" --png "$work/confusion.png" --threads 2 > "$work/eval.txt"
last=$(tail -n 1 "$work/eval.txt")
[[ $last =~ ^accuracy:\ (0\.[0-9]{4}|1\.0000)$ ]] || fail "last line: $last"
awk '{ if ($2 < 0.9) exit 1 }' <<< "$last" || fail "accuracy on training samples: $last"
grep -q "per-class accuracy" "$work/eval.txt" || fail "no per-class accuracy"
grep -Eq "^mean per-class accuracy: (0\.[0-9]{4}|1\.0000) \(10 classes\)$" "$work/eval.txt" || fail "no mean per-class accuracy"
# With votes: the count is stated, and the last line keeps its form.
"$vola" evaluate "$work/clean/test" --votes 4 --png '' --threads 2 > "$work/eval4.txt"
grep -q "4 votes" "$work/eval4.txt" || fail "votes not stated: $(head -n 1 "$work/eval4.txt")"
[[ $(tail -n 1 "$work/eval4.txt") =~ ^accuracy:\ (0\.[0-9]{4}|1\.0000)$ ]] || fail "votes: last line"
[[ $(head -c 8 "$work/confusion.png" | od -An -tx1 | tr -d ' \n') == 89504e470d0a1a0a ]] || fail "no PNG"

# Classify one file: the first line names the class.
"$vola" classify "$work/clean/test/monitor/monitor_00010.vol" > "$work/one.txt"
[[ $(head -n 1 "$work/one.txt" | cut -d' ' -f1) == monitor ]] || fail "classify: $(cat "$work/one.txt")"
[[ $(wc -l < "$work/one.txt") == 11 ]] || fail "expected 11 lines"
"$vola" classify --votes 12 "$work/clean/test/monitor/monitor_00010.vol" > "$work/one12.txt"
[[ $(head -n 1 "$work/one12.txt" | cut -d' ' -f1) == monitor ]] || fail "classify --votes 12: $(cat "$work/one12.txt")"
if "$vola" classify --votes 0 "$work/clean/test/monitor/monitor_00010.vol" 2> /dev/null; then fail "--votes 0 accepted"; fi
# The model used is named; $VOLA_MODEL may name a folder of models, but one that does not
# exist is an error, not a silent fall-back on the committed model.
grep -q "^model: .*modelnet10-small.pt$" "$work/eval.txt" || fail "evaluate names no model: $(head -n 3 "$work/eval.txt")"
monitor=$work/clean/test/monitor/monitor_00010.vol
if VOLA_MODEL=$work/no-such.pt "$vola" classify "$monitor" > /dev/null 2> "$work/err.txt"; then
  fail "a missing VOLA_MODEL fell back on another model"
fi
grep -q "VOLA_MODEL=.*no-such.pt: no such model file or folder" "$work/err.txt" || fail "VOLA_MODEL: $(cat "$work/err.txt")"
model_dir=$(dirname "$(sed -n 's/^model: //p' "$work/eval.txt")")
VOLA_MODEL=$model_dir "$vola" classify "$monitor" | head -n 1 | grep -q "^monitor " || fail "VOLA_MODEL as a folder"
if "$vola" classify --model "$model_dir" "$monitor" > /dev/null 2> "$work/err.txt"; then fail "a folder as --model"; fi
grep -q "a folder, not a model file" "$work/err.txt" || fail "--model folder: $(cat "$work/err.txt")"
# --model takes a committed model's name, found where the default is; an unknown name says
# where it looked.
(cd "$work" && "$vola" classify --model modelnet10-small "$monitor") | head -n 1 | grep -q "^monitor " ||
  fail "--model by a committed model's name"
if (cd "$work" && "$vola" classify --model no-such-model "$monitor") > /dev/null 2> "$work/err.txt"; then
  fail "an unknown model name was accepted"
fi
grep -q -- "--model no-such-model: no such file here, nor a committed model of that name" "$work/err.txt" ||
  fail "--model unknown name: $(cat "$work/err.txt")"
# A $VOLA_MODEL naming another model file lends its folder to a name, not itself (the
# default model answered for --model modelnet10-small-full-circle, without a word).
VOLA_MODEL=$model_dir/modelnet10-small.pt "$vola" evaluate "$(dirname "$(dirname "$monitor")")" \
  --model modelnet10-small-full-circle --threads 1 > "$work/named.txt"
grep -q "^model: .*modelnet10-small-full-circle.pt$" "$work/named.txt" || fail "VOLA_MODEL file and --model NAME: $(head -n 3 "$work/named.txt")"
if "$vola" classify --orientations mean "$monitor" 2> "$work/err.txt" > /dev/null; then fail "--orientations without --segment"; fi
grep -q -- "--orientations applies only with --segment" "$work/err.txt" || fail "orientations: $(cat "$work/err.txt")"
"$vola" diff "$monitor" "$monitor" "$work/empty.vol" > /dev/null
if "$vola" classify "$work/empty.vol" 2> "$work/err.txt" > /dev/null; then fail "an empty tree was classified"; fi
grep -q "empty.vol: holds no voxels" "$work/err.txt" || fail "empty tree: $(cat "$work/err.txt")"
if "$vola" train "$work/clean/test" --validation "$work/clean/test" -o "$work/same.pt" --epochs 1 2> "$work/err.txt" > /dev/null
then fail "training validated on its own samples"; fi
grep -q "20 of the 20 samples of .* are also in" "$work/err.txt" || fail "shared samples: $(cat "$work/err.txt")"

# --segment: the object found in a room (floor and walls removed, components), classified
# with the clean model; the first line still names the class, the last says what was found.
"$vola" classify --segment "$work/room/test/sofa/sofa_00014.vol" > "$work/seg.txt"
[[ $(wc -l < "$work/seg.txt") == 14 ]] || fail "classify --segment: $(cat "$work/seg.txt")"
grep -Eq "^[a-z_]+ [01]\.[0-9]{4}$" <<< "$(head -n 1 "$work/seg.txt")" || fail "classify --segment first line"
grep -q "^removed planes: x min (x = 0, 1 layer" "$work/seg.txt" || fail "no wall removed: $(cat "$work/seg.txt")"
grep -q "^object: " "$work/seg.txt" || fail "no object line"
"$vola" evaluate "$work/room/test" --segment --png '' --threads 2 > "$work/segeval.txt"
grep -q "segmented, 4 votes" "$work/segeval.txt" || fail "segment evaluate: $(head -n 2 "$work/segeval.txt")"
[[ $(tail -n 1 "$work/segeval.txt") =~ ^accuracy:\ (0\.[0-9]{4}|1\.0000)$ ]] || fail "segment evaluate: last line"
# dataset --segment writes what --segment gives the model: classifying the written object
# (one vote) says what classifying the room with --segment --votes 1 says (with --segment's
# default model, the one trained on such objects).
"$vola" dataset "$work/small.npz" "$work/seg" --background --segment > "$work/segdata.txt"
[[ $(find "$work/seg/test" -name '*.vol' | wc -l) == 20 ]] || fail "dataset --segment: $(cat "$work/segdata.txt")"
grep -q "segmented and normalised" "$work/segdata.txt" || fail "dataset --segment summary: $(cat "$work/segdata.txt")"
segmented_model=$(dirname "$0")/../../models/modelnet10-small-room-segmented.pt
"$vola" classify "$work/seg/test/sofa/sofa_00014.vol" --model "$segmented_model" | head -n 1 > "$work/seg_written.txt"
"$vola" classify --segment --votes 1 "$work/room/test/sofa/sofa_00014.vol" | head -n 1 > "$work/seg_found.txt"
cmp -s "$work/seg_written.txt" "$work/seg_found.txt" ||
  fail "dataset --segment differs from classify --segment: $(cat "$work/seg_written.txt") / $(cat "$work/seg_found.txt")"
# A room with nothing in it but its floor: refused, saying why.
"$vola" crop "$work/room/test/sofa/sofa_00014.vol" "$work/floor.vol" --min 0 0 0 --max 63 63 0 > /dev/null
if "$vola" classify --segment "$work/floor.vol" 2> "$work/err.txt"; then fail "empty room classified"; fi
grep -q "no object left" "$work/err.txt" || fail "empty room message: $(cat "$work/err.txt")"

# Errors: exit 1 and a message naming the file.
if "$vola" dataset "$work/small.npz.bad.npz" "$work/bad" 2> "$work/err.txt"; then fail "bad npz accepted"; fi
grep -q "X_test" "$work/err.txt" || fail "bad npz message: $(cat "$work/err.txt")"
if "$vola" classify --model "$work/eval.txt" "$work/clean/test/chair/chair_00004.vol" 2> "$work/err.txt"; then fail "bad model accepted"; fi
grep -q "eval.txt" "$work/err.txt" || fail "bad model message: $(cat "$work/err.txt")"
echo "cli_learn: ok"
