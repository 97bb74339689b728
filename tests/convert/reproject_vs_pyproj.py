#!/usr/bin/env python3
"""`vola convert --target-crs` against pyproj (python3-pyproj, an independent binding of
PROJ): for real LAS files in several CRSs, the points vola reprojects give exactly the
voxels of the same points reprojected by pyproj and converted from an .npy file.

Usage: reproject_vs_pyproj.py --vola VOLA --python-path BUILD/python --shared-default DIR
Exit 77 (skip) without the shared data or pyproj, unless CI is set (then 1).
"""
import argparse
import json
import os
import struct
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

# (file under data/las, target CRS, voxel size in the target's units)
CASES = [
    ("pdal_autzen_trim.las", "EPSG:32610", 1.0),   # a WKT with no code, international feet -> UTM metres
    ("pdal_autzen_pf1.las", "32610", 0.5),         # EPSG:2994 in GeoKeys, feet; the target as a bare code
    ("pdal_epsg_4326.las", "EPSG:32615", 0.25),    # degrees -> UTM zone 15N
    ("pdal_autzen-bmx-2010.las", "EPSG:6557", 2.0),  # compound (metres + NAVD88 ftUS) -> Oregon GIC Lambert ft
]


def skip(message):
    if os.environ.get("CI"):
        print("FAIL: " + message, file=sys.stderr)
        sys.exit(1)
    print("SKIP: " + message)
    sys.exit(77)


def las_points(path):
    """x y z of every point record, from the header's scale and offset (LAS 1.0-1.4)."""
    data = path.read_bytes()
    minor = data[25]
    offset_to_points = struct.unpack_from("<I", data, 96)[0]
    record_length = struct.unpack_from("<H", data, 105)[0]
    count = struct.unpack_from("<I", data, 107)[0]
    if minor >= 4 and count == 0:
        count = struct.unpack_from("<Q", data, 247)[0]
    scale = np.array(struct.unpack_from("<3d", data, 131))
    offset = np.array(struct.unpack_from("<3d", data, 155))
    records = np.frombuffer(data, dtype=np.uint8, count=count * record_length, offset=offset_to_points)
    xyz = records.reshape(count, record_length)[:, :12].copy().view("<i4").reshape(count, 3)
    return xyz * scale + offset


def run(args):
    result = subprocess.run(args, capture_output=True, text=True)
    if result.returncode != 0:
        raise SystemExit("FAIL: %s\n%s" % (" ".join(map(str, args)), result.stderr))
    return result.stdout


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--vola", required=True)
    parser.add_argument("--python-path", required=True)
    parser.add_argument("--shared-default", required=True)
    a = parser.parse_args()
    try:
        import pyproj
    except ImportError:
        skip("pyproj is not installed (apt-get install python3-pyproj)")
    sys.path.insert(0, a.python_path)
    import vola

    data = Path(os.environ.get("VOLA_SHARED", a.shared_default)) / "data" / "las"
    if not data.is_dir():
        skip("no shared data at %s (set VOLA_SHARED)" % data)
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        for name, target, voxel in CASES:
            las = data / name
            ours = tmp / ("%s.vol" % name)
            run([a.vola, "convert", las, ours, "--target-crs", target, "--voxel-size", str(voxel), "--no-attributes", "-q"])
            # The source CRS as vola states it (the input's WKT, or its code's).
            plain = tmp / ("%s.plain.vol" % name)
            run([a.vola, "convert", las, plain, "--voxel-size", "1", "--no-attributes", "--allow-geographic", "-q"])
            source = json.loads(run([a.vola, "info", "--json", plain]))["crs_wkt"]
            target_crs = pyproj.CRS.from_user_input(int(target) if target.isdigit() else target)
            transformer = pyproj.Transformer.from_crs(pyproj.CRS.from_wkt(source), target_crs, always_xy=True)
            xyz = las_points(las)
            x, y, z = transformer.transform(xyz[:, 0], xyz[:, 1], xyz[:, 2])
            npy = tmp / ("%s.npy" % name)
            np.save(npy, np.column_stack([x, y, z]).astype(np.float64))
            theirs = tmp / ("%s.pyproj.vol" % name)
            run([a.vola, "convert", npy, theirs, "--voxel-size", str(voxel), "-q"])
            t_ours, t_theirs = vola.open(str(ours)), vola.open(str(theirs))
            grid = lambda t: (t.depth, t.quantization, tuple(t.origin), t.voxel_size)
            if grid(t_ours) != grid(t_theirs):
                raise SystemExit("FAIL: %s: grids differ: %s vs %s" % (name, grid(t_ours), grid(t_theirs)))
            v_ours, v_theirs = t_ours.voxels(), t_theirs.voxels()
            if v_ours.shape != v_theirs.shape or not np.array_equal(v_ours, v_theirs):
                raise SystemExit("FAIL: %s -> %s: %d voxels from vola, %d from pyproj's points" %
                                 (name, target, len(v_ours), len(v_theirs)))
            info = json.loads(run([a.vola, "info", "--json", ours]))
            if info["crs_named"] is None or not pyproj.CRS.from_wkt(info["crs_wkt"]).equals(target_crs):
                raise SystemExit("FAIL: %s: the output does not carry the target CRS" % name)
            print("%s -> %s: %d voxels, identical to pyproj's points" % (name, target, len(v_ours)))


if __name__ == "__main__":
    main()
