#!/usr/bin/python3
"""Bounded memory: converts a generated LAS survey far larger than what the points
would take in memory (default 2e8 points, 6.8 GB), and reports the peak RSS.

The survey is written chunk by chunk (never whole in memory) in flight-strip order, as
an airborne scanner delivers it: strips 10 m wide across a 2 km x 2 km area, a rolling
terrain with noise, LAS 1.2 point format 3, 1 mm scale; the header gets the points'
true extents at the end (--stale-header keeps the nominal 0..200 m z range instead).

usage: bench/las_bounded_memory.py VOLA_BINARY OUT_DIR [--points N] [--voxel SIZE] [--keep] [--las FILE]
                                   [--occupancy-only] [--runs R]
"""
import argparse
import os
import struct
import subprocess
import sys

import numpy as np

RECORD = np.dtype([("x", "<i4"), ("y", "<i4"), ("z", "<i4"), ("intensity", "<u2"), ("returns", "u1"),
                   ("classification", "u1"), ("angle", "i1"), ("user", "u1"), ("source", "<u2"), ("time", "<f8"),
                   ("r", "<u2"), ("g", "<u2"), ("b", "<u2")])
SIZE = 2000.0  # metres
STRIP = 10.0


def header(n, lo, hi, scale):
    h = bytearray(227)
    h[0:4] = b"LASF"
    h[24], h[25] = 1, 2
    struct.pack_into("<H", h, 94, 227)
    struct.pack_into("<I", h, 96, 227)
    h[104] = 3
    struct.pack_into("<H", h, 105, RECORD.itemsize)
    struct.pack_into("<I", h, 107, n)
    struct.pack_into("<3d", h, 131, scale, scale, scale)
    struct.pack_into("<3d", h, 155, 0.0, 0.0, 0.0)
    struct.pack_into("<6d", h, 179, hi[0], lo[0], hi[1], lo[1], hi[2], lo[2])
    return h


def write_survey(path, n, stale_header=False):
    rng = np.random.default_rng(7)
    strips = int(SIZE / STRIP)
    per_strip = n // strips
    scale = 0.001
    lo, hi = np.full(3, np.inf), np.full(3, -np.inf)
    with open(path, "wb") as f:
        f.write(header(per_strip * strips, (0, 0, 0), (SIZE, SIZE, 200.0), scale))
        for s in range(strips):
            x = rng.uniform(0, SIZE, per_strip)
            y = rng.uniform(s * STRIP, (s + 1) * STRIP, per_strip)
            z = 50 + 20 * np.sin(x / 150) * np.cos(y / 170) + 0.05 * x / 10 + rng.normal(0, 0.05, per_strip)
            rec = np.zeros(per_strip, dtype=RECORD)
            rec["x"], rec["y"], rec["z"] = x / scale, y / scale, z / scale
            rec["intensity"] = rng.integers(0, 1000, per_strip)
            rec["returns"] = 0x09
            rec["classification"] = 2
            f.write(rec.tobytes())
            for a, name in enumerate("xyz"):
                lo[a] = min(lo[a], rec[name].min() * scale)
                hi[a] = max(hi[a], rec[name].max() * scale)
        # The points' true extents, as the LAS specification asks of a header (the
        # nominal 0..200 m z range written first would make it stale).
        if not stale_header:
            f.seek(0)
            f.write(header(per_strip * strips, lo, hi, scale))
    return per_strip * strips


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("vola")
    parser.add_argument("out_dir")
    parser.add_argument("--points", type=int, default=200_000_000)
    parser.add_argument("--voxel", type=float, default=0.25)
    parser.add_argument("--keep", action="store_true", help="keep the generated LAS file")
    parser.add_argument("--las", help="convert this survey (written by an earlier --keep run) instead of generating one")
    parser.add_argument("--occupancy-only", action="store_true", help="skip the (slow, memory-hungry) attribute run")
    parser.add_argument("--runs", type=int, default=1, help="conversions per kind (the median is reported)")
    parser.add_argument("--stale-header", action="store_true", help="header z range 0..200 m, not the points'")
    args = parser.parse_args()
    os.makedirs(args.out_dir, exist_ok=True)
    if args.las:
        las = args.las
        with open(las, "rb") as f:
            n = struct.unpack_from("<I", f.read(111), 107)[0]
    else:
        las = os.path.join(args.out_dir, "bounded_%d.las" % args.points)
        n = write_survey(las, args.points, args.stale_header)
        print("generated %s: %d points, %d bytes" % (las, n, os.path.getsize(las)))
    vol = os.path.join(args.out_dir, "bounded.vol")
    kinds = (("occupancy only", ["--no-attributes"]), ("with attribute columns", []))
    for label, extra in kinds[:1] if args.occupancy_only else kinds:
        runs = []
        for _ in range(args.runs):
            result = subprocess.run(["/usr/bin/time", "-f", "%e %M", args.vola, "convert", las, vol, "--voxel-size",
                                     str(args.voxel), *extra], capture_output=True, text=True, check=True)
            seconds, kib = result.stderr.strip().splitlines()[-1].split()
            inside = [line for line in result.stdout.splitlines() if line.startswith("time:")]
            voxels = [line for line in result.stdout.splitlines() if line.startswith("voxels out")][0]
            runs.append((float(seconds), int(kib), float(inside[0].split()[1]) if inside else float("nan"), voxels))
        seconds, kib, inside, voxels = sorted(runs)[len(runs) // 2]
        print("%s: %.1f s (%.1f s inside `vola convert`), %.2f M points/s, peak RSS %.0f MiB (the points alone would "
              "be %.0f MiB as doubles); %s [median of %d: %s s]" % (
                  label, seconds, inside, n / seconds / 1e6, max(r[1] for r in runs) / 1024, n * 24 / 2**20, voxels,
                  len(runs), ", ".join("%.1f" % r[0] for r in runs)))
    if not args.keep and not args.las:
        os.remove(las)


if __name__ == "__main__":
    sys.exit(main())
