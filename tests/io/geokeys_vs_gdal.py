#!/usr/bin/env python3
"""The CRS of a LAS file's GeoTIFF keys as vola reads it, against GDAL (python3-gdal).

LAS files state their CRS as a GeoTIFF key directory (LASF_Projection records 34735-34737).
GDAL reads those keys in GeoTIFFs, where a ProjLinearUnitsGeoKey beside a
ProjectedCSTypeGeoKey overrides the code's unit (pdal_mvk-thin.las: NAD83 / Mississippi
West, a metre CRS, with US survey feet; its coordinates are feet). For every shared
LAS and LAZ file whose keys state a projected CRS and which has no WKT record (the WKT
wins in vola, as the LAS 1.4 specification says), this test copies the three key records
into the tags of a 1 x 1 GeoTIFF, has GDAL read its CRS, and requires `vola info --json`
to give the same CRS name and linear unit.

Usage: geokeys_vs_gdal.py VOLA SHARED_DIR
Exit 77 (skip) without the shared data, unless CI is set (then 1).
"""
import json
import os
import struct
import subprocess
import sys
import tempfile
from pathlib import Path

from osgeo import gdal

gdal.UseExceptions()
gdal.PushErrorHandler("CPLQuietErrorHandler")  # GDAL warns that the unit differs from the code's


def skip(message):
    if os.environ.get("CI"):
        print("FAIL: " + message, file=sys.stderr)
        sys.exit(1)
    print("SKIP: " + message)
    sys.exit(77)


def projection_records(path):
    """{record id: bytes} of the LASF_Projection VLRs (LAS 1.0-1.4 headers)."""
    data = path.read_bytes()[: 1 << 20]
    header_size = struct.unpack_from("<H", data, 94)[0]
    count = struct.unpack_from("<I", data, 100)[0]
    records, at = {}, header_size
    for _ in range(count):
        if at + 54 > len(data):
            break
        user = data[at + 2 : at + 18].rstrip(b"\0")
        record_id, length = struct.unpack_from("<HH", data, at + 18)
        if user == b"LASF_Projection":
            records[record_id] = data[at + 54 : at + 54 + length]
        at += 54 + length
    return records


def geotiff_with_keys(records, out):
    """A 1 x 1 8-bit GeoTIFF whose GeoKey tags hold the LAS records' bytes."""
    tags = [(256, 3, 1, struct.pack("<H", 1)), (257, 3, 1, struct.pack("<H", 1)), (258, 3, 1, struct.pack("<H", 8)),
            (259, 3, 1, struct.pack("<H", 1)), (262, 3, 1, struct.pack("<H", 1)), (273, 4, 1, None),
            (277, 3, 1, struct.pack("<H", 1)), (278, 3, 1, struct.pack("<H", 1)), (279, 4, 1, struct.pack("<I", 1))]
    if 34735 in records:
        tags.append((34735, 3, len(records[34735]) // 2, records[34735]))
    if 34736 in records:
        tags.append((34736, 12, len(records[34736]) // 8, records[34736]))
    if 34737 in records:
        tags.append((34737, 2, len(records[34737]), records[34737]))
    data_at = 8 + 2 + 12 * len(tags) + 4
    blobs, entries = b"", []
    for tag, kind, count, value in tags:
        if value is not None and len(value) > 4:
            entries.append((tag, kind, count, struct.pack("<I", data_at + len(blobs))))
            blobs += value + b"\0" * (len(value) % 2)
        else:
            entries.append((tag, kind, count, value))
    pixel_at = data_at + len(blobs)
    ifd = struct.pack("<H", len(entries))
    for tag, kind, count, value in entries:
        value = struct.pack("<I", pixel_at) if value is None else value.ljust(4, b"\0")
        ifd += struct.pack("<HHI", tag, kind, count) + value
    out.write_bytes(b"II*\0" + struct.pack("<I", 8) + ifd + struct.pack("<I", 0) + blobs + b"\0")


def main():
    vola, shared = sys.argv[1], Path(sys.argv[2])
    data = Path(os.environ.get("VOLA_SHARED", shared)) / "data"
    files = sorted((data / "las").glob("*.las")) + sorted((data / "laz").glob("*.laz"))
    if not files:
        skip(f"no LAS files under {data}")
    checked, failures = 0, []
    with tempfile.TemporaryDirectory() as tmp:
        tiff = Path(tmp) / "keys.tif"
        for path in files:
            records = projection_records(path)
            if 34735 not in records or 2112 in records:
                continue
            geotiff_with_keys(records, tiff)
            srs = gdal.Open(str(tiff)).GetSpatialRef()
            if srs is None or not srs.IsProjected():
                continue
            info = json.loads(subprocess.run([vola, "info", "--json", str(path)], check=True, capture_output=True,
                                             text=True).stdout)
            crs = info.get("crs") or {}
            got = (crs.get("name"), crs.get("unit"))
            want = (srs.GetName(), srs.GetLinearUnitsName())
            print(f"{path.name}: GDAL {want}, vola {got}")
            checked += 1
            if got != want:
                failures.append(f"{path.name}: GDAL reads {want}, vola {got}")
    if checked < 3:
        failures.append(f"only {checked} files with projected GeoKeys and no WKT were found (expected at least 3)")
    if failures:
        print("FAIL:\n  " + "\n  ".join(failures), file=sys.stderr)
        sys.exit(1)
    print(f"OK: {checked} files")


if __name__ == "__main__":
    main()
