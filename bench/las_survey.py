#!/usr/bin/python3
"""LAS -> VOLA sizes and conversion throughput (the numbers docs/BENCHMARKS.md publishes).

For every LAS file in $VOLA_SHARED/data/las and for a generated survey (`vola generate
city`, written as LAS 1.2 point format 3 by this script), converts at voxel sizes of 1x,
2x and 4x the mean point spacing and reports the .vol size against the LAS and, where
the same cloud exists as LAZ in the shared data, the LAZ; then times the end-to-end
conversion of the generated survey (median of several runs) and its peak memory.

usage: bench/las_survey.py VOLA_BINARY OUT_DIR [--points N] [--runs R] [--format 1|3]
"""
import argparse
import math
import os
import re
import statistics
import struct
import subprocess
import sys
import time

import numpy as np

# The same cloud as LAZ in the shared data (EXPECTED.txt: equal counts and bounds).
LAZ_TWINS = {
    "pdal_autzen_trim.las": "pdal_autzen_trim.laz",
    "pdal_1.2-with-color.las": "laspy_simple.laz",
}


def las_header(path):
    with open(path, "rb") as f:
        h = f.read(375)
    n = struct.unpack_from("<I", h, 107)[0]
    if h[25] >= 4:
        n = struct.unpack_from("<Q", h, 247)[0] or n
    maxx, minx, maxy, miny, maxz, minz = struct.unpack_from("<6d", h, 179)
    return n, (minx, miny, minz), (maxx, maxy, maxz)


def mean_spacing(path):
    """Mean horizontal point spacing: sqrt(footprint area / points), the usual LIDAR figure."""
    n, lo, hi = las_header(path)
    area = max(hi[0] - lo[0], 1e-9) * max(hi[1] - lo[1], 1e-9)
    return math.sqrt(area / max(n, 1))


def write_survey_las(vola, out_dir, points, point_format=3):
    """A generated city block survey as LAS 1.2, point format 3 or 1 (no RGB; mm precision)."""
    xyz_path = os.path.join(out_dir, "survey.xyz")
    subprocess.run([vola, "generate", "city", xyz_path, "--points", str(points), "--size", "1000"], check=True,
                   stdout=subprocess.DEVNULL)
    data = np.loadtxt(xyz_path, comments="#")
    os.remove(xyz_path)
    n = len(data)
    lo, hi = data[:, :3].min(axis=0), data[:, :3].max(axis=0)
    scale = 0.001
    offset = np.floor(lo)
    header = bytearray(227)
    header[0:4] = b"LASF"
    header[24], header[25] = 1, 2
    header[58:58 + 12] = b"vola bench  "
    struct.pack_into("<H", header, 94, 227)
    struct.pack_into("<I", header, 96, 227)
    fields = [("x", "<i4"), ("y", "<i4"), ("z", "<i4"), ("intensity", "<u2"), ("returns", "u1"),
              ("classification", "u1"), ("angle", "i1"), ("user", "u1"), ("source", "<u2"), ("time", "<f8")]
    if point_format == 3:
        fields += [("r", "<u2"), ("g", "<u2"), ("b", "<u2")]
    header[104] = point_format
    struct.pack_into("<H", header, 105, np.dtype(fields).itemsize)
    struct.pack_into("<I", header, 107, n)
    struct.pack_into("<3d", header, 131, scale, scale, scale)
    struct.pack_into("<3d", header, 155, *offset)
    struct.pack_into("<6d", header, 179, hi[0], lo[0], hi[1], lo[1], hi[2], lo[2])
    record = np.zeros(n, dtype=fields)
    for axis, name in enumerate("xyz"):
        record[name] = np.round((data[:, axis] - offset[axis]) / scale).astype("<i4")
    record["intensity"] = data[:, 3]
    record["returns"] = 0x09  # return 1 of 1
    record["classification"] = data[:, 4]
    path = os.path.join(out_dir, ("survey_%d.las" if point_format == 3 else "survey_f%d_%%d.las" % point_format) % n)
    with open(path, "wb") as f:
        f.write(header)
        f.write(record.tobytes())
    return path


def convert(vola, las, vol, voxel, extra=()):
    result = subprocess.run(["/usr/bin/time", "-f", "%e %M", vola, "convert", las, vol, "--voxel-size", repr(voxel),
                             "-q", *extra], check=True, capture_output=True, text=True)
    seconds, kib = result.stderr.strip().splitlines()[-1].split()
    info = subprocess.run([vola, "info", "--json", vol], check=True, capture_output=True, text=True).stdout
    voxels = int(re.search(r'"voxels": (\d+)', info).group(1))
    return os.path.getsize(vol), voxels, float(seconds), int(kib)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("vola")
    parser.add_argument("out_dir")
    parser.add_argument("--points", type=int, default=10_000_000)
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--format", type=int, choices=(1, 3), default=3, help="LAS point data record format")
    args = parser.parse_args()
    shared = os.environ.get("VOLA_SHARED", os.path.join(os.path.dirname(__file__), "..", "..", "shared"))
    os.makedirs(args.out_dir, exist_ok=True)
    las_dir = os.path.join(shared, "data", "las")
    files = [os.path.join(las_dir, f) for f in sorted(os.listdir(las_dir)) if f.endswith(".las")]
    files = [f for f in files if las_header(f)[0] >= 1000]  # one-point files say nothing about size
    survey = write_survey_las(args.vola, args.out_dir, args.points, args.format)
    files.append(survey)

    print("| file | points | LAS bytes | LAZ bytes | spacing | voxel | voxels | .vol bytes | bits/voxel | vol/LAS | vol/LAZ | zstd .vol bytes | zstd/LAS | zstd/LAZ | convert s | M points/s | peak MiB |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    vol = os.path.join(args.out_dir, "out.vol")
    for las in files:
        n = las_header(las)[0]
        las_bytes = os.path.getsize(las)
        twin = LAZ_TWINS.get(os.path.basename(las))
        laz_bytes = os.path.getsize(os.path.join(shared, "data", "laz", twin)) if twin else None
        spacing = mean_spacing(las)
        for k in (1, 2, 4):
            voxel = k * spacing
            # End to end, one run (the process start included: small files measure that).
            # In the file's own units, degrees too: vola refuses a geographic CRS for grid
            # voxels unless told (laspy_simple1_4.las is EPSG:4326), and this table is about
            # bytes per voxel, not about metres.
            size, voxels, seconds, kib = convert(args.vola, las, vol, voxel, ["--no-attributes", "--allow-geographic"])
            zsize, _, _, _ = convert(args.vola, las, vol, voxel, ["--no-attributes", "--compress", "--allow-geographic"])
            laz = "%d" % laz_bytes if laz_bytes else "-"
            print("| %s | %d | %d | %s | %.3g | %dx = %.3g | %d | %d | %.2f | %.3f | %s | %d | %.4f | %s | %.2f | %.2f | %.0f |" % (
                os.path.basename(las), n, las_bytes, laz, spacing, k, voxel, voxels, size, 8.0 * size / voxels,
                size / las_bytes, "%.3f" % (size / laz_bytes) if laz_bytes else "-", zsize, zsize / las_bytes,
                "%.3f" % (zsize / laz_bytes) if laz_bytes else "-", seconds, n / max(seconds, 0.01) / 1e6, kib / 1024))

    print()
    print("Throughput, %s (%d points, %d bytes), voxel = 1x spacing, median of %d runs, file in page cache:" % (
        os.path.basename(survey), args.points, os.path.getsize(survey), args.runs))
    print()
    print("| conversion | median s | M points/s | peak RSS MiB | voxels |")
    print("|---|---|---|---|---|")
    spacing = mean_spacing(survey)
    subprocess.run(["cat", survey], stdout=subprocess.DEVNULL, check=True)  # into the page cache
    for label, extra in (("occupancy only (--no-attributes)", ["--no-attributes"]),
                         ("with attribute columns (default)", []),
                         ("with the reference payload (--nbits 1)", ["--no-attributes", "--nbits", "1"])):
        times, peak, voxels = [], 0, 0
        for _ in range(args.runs):
            _, voxels, seconds, kib = convert(args.vola, survey, vol, spacing, extra)
            times.append(seconds)
            peak = max(peak, kib)
        median = statistics.median(times)
        print("| %s | %.2f | %.1f | %.0f | %d |" % (label, median, args.points / median / 1e6, peak / 1024, voxels))


if __name__ == "__main__":
    sys.exit(main())
