#!/usr/bin/env bash
# vola sonify's physical response on a real open scene (the Autzen survey at 3 ft voxels,
# the README's example): after the direct sound the energy in 10 ms windows never climbs
# more than 3 dB above the loudest window before it (no flutter, no late bursts: the sound
# leaves an open scene), and 100 ms after the direct sound it is 20 dB below it.
# Usage: cli_sonify_open_scene.sh VOLA SHARED_DIR
set -euo pipefail
vola=$1 shared=${VOLA_SHARED:-$2}
source "$(dirname "$0")/../lib/cli_test.sh"
las=$shared/data/las/pdal_autzen_trim.las wav=$shared/data/audio/alsa_Front_Center.wav
[ -f "$las" ] && [ -f "$wav" ] || skip "no shared data at $shared"

"$vola" convert "$las" "$tmp/autzen.vol" --voxel-size 3 -q
# The survey is in feet: positions in feet, sound in metres. Source 45 ft (13.716 m) from
# the listener, 6 ft above the ground.
"$vola" sonify "$tmp/autzen.vol" --source 636250.5 849217.5 435 --listener 636205.5 849217.5 435 \
  --in "$wav" --out "$tmp/wet.wav" --ir "$tmp/ir.wav" --rays 8000 > "$tmp/out" \
  || fail "sonify failed: $(cat "$tmp/out")"
grep -q "direct 13.716 m, 39.98 ms (sample 1919)" "$tmp/out" || fail "45 ft is not 13.716 m at 343 m/s: $(cat "$tmp/out")"
/usr/bin/python3 - "$tmp/ir.wav" <<'PY' || fail "the open scene's response rings or does not decay"
import sys
import numpy as np
from scipy.io import wavfile
rate, ir = wavfile.read(sys.argv[1])
ir = ir.astype(np.float64).reshape(len(ir), -1)[:, 0]
window = int(0.01 * rate)
energy = np.array([np.sum(ir[i:i + window] ** 2) for i in range(0, len(ir), window)])
direct = int(np.argmax(np.abs(ir) > 0.5 * np.abs(ir).max())) // window
loudest, worst = energy[direct], -np.inf
for k in range(direct + 1, len(energy)):
    if energy[k] > 0:
        worst = max(worst, 10 * np.log10(energy[k] / loudest))
    loudest = max(loudest, energy[k])
later = 10 * np.log10(max(energy[direct + 10], 1e-300) / energy[direct]) if direct + 10 < len(energy) else -np.inf
print(f"autzen: {len(ir) / rate:.3f} s response, largest rise over the windows before {worst:.1f} dB, "
      f"+100 ms at {later:.1f} dB re direct")
sys.exit(0 if worst <= 3.0 and later <= -20.0 else 1)
PY
echo "cli_sonify_open_scene: ok"
