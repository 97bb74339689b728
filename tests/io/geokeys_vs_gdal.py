#!/usr/bin/env python3
"""The CRS of a LAS file's GeoTIFF keys as vola reads it, against GDAL (python3-gdal).

LAS files state their CRS as a GeoTIFF key directory (LASF_Projection records 34735-34737).
GDAL reads those keys in GeoTIFFs, where a ProjLinearUnitsGeoKey beside a
ProjectedCSTypeGeoKey overrides the code's unit (pdal_mvk-thin.las: NAD83 / Mississippi
West, a metre CRS, with US survey feet; its coordinates are feet). For every shared
LAS and LAZ file whose keys state a projected CRS and which has no WKT record (the WKT
wins in vola, as the LAS 1.4 specification says), this test copies the three key records
into the tags of a 1 x 1 GeoTIFF, has GDAL read its CRS, and requires `vola info --json`
to give the same CRS name and linear unit. Then made-up key directories in a one-point
LAS file: a projected code with a linear unit key, and with a vertical unit key other than
the horizontal one (no vertical CRS named), where GDAL (asked to report compound CRSs,
GTIFF_REPORT_COMPD_CS) gives heights in the vertical key's unit and so must vola; and
user-defined projections (keys 32767 with their parameters), where vola's CRS must place
a point where pyproj places it with the PROJ definition the keys spell out.

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

from osgeo import gdal, osr

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
        if user == b"LASF_Projection" and record_id not in records:  # the first of each counts
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


def key_directory(keys):
    """A GeoKeyDirectory record of (key, value) pairs: a float value is (key, ("double",
    index into the doubles)), text (key, ("ascii", offset, length))."""
    directory = [1, 1, 0, len(keys)]
    for key, value in keys:
        if isinstance(value, tuple) and value[0] == "ascii":
            directory += [key, 34737, value[2], value[1]]
        elif isinstance(value, tuple):
            directory += [key, 34736, 1, value[1]]
        else:
            directory += [key, 0, 1, value]
    return struct.pack(f"<{len(directory)}H", *directory)


def las_with_keys(keys, out, doubles=(), ascii=b"", more_records=()):
    """A LAS 1.2 file of one point (format 0) whose VLRs are a GeoKeyDirectory of `keys`
    (key_directory), with `doubles` a GeoDoubleParams record, with `ascii` a GeoAsciiParams
    record, then `more_records` ((record id, bytes) pairs)."""
    records = [(34735, key_directory(keys))]
    if doubles:
        records.append((34736, struct.pack(f"<{len(doubles)}d", *doubles)))
    if ascii:
        records.append((34737, ascii))
    records += list(more_records)
    vlrs = b"".join(struct.pack("<H16sHH32s", 0, b"LASF_Projection", record, len(data), b"") + data
                    for record, data in records)
    header_size, record_length = 227, 20
    offset = header_size + len(vlrs)
    header = bytearray(header_size)
    header[0:4] = b"LASF"
    header[24], header[25] = 1, 2
    struct.pack_into("<H", header, 94, header_size)
    struct.pack_into("<IIBHI", header, 96, offset, len(records), 0, record_length, 1)
    struct.pack_into("<3d", header, 131, 0.01, 0.01, 0.01)
    struct.pack_into("<6d", header, 179, 500001.0, 500000.0, 5000001.0, 5000000.0, 101.0, 100.0)
    point = struct.pack("<3iH", 50000000, 500000000, 10000, 0) + bytes(6)
    out.write_bytes(bytes(header) + vlrs + point)


# Key directories that define a projected CRS by its parts (user-defined, 32767), with
# the PROJ definition the keys spell out (written here from the GeoTIFF specification's
# key meanings: false eastings in the linear unit's, angles in degrees). The second's
# geographic code NAD83 is only the base of its projection: reading it as the file's
# CRS would put feet in degrees.
US_FOOT = 1200 / 3937
USER_DEFINED = [
    ("transverse Mercator on the WGS 84 ellipsoid, metres",
     [(1024, 1), (2048, 32767), (2050, 32767), (2056, 7030), (3072, 32767), (3074, 32767), (3075, 1),
      (3076, 9001), (3080, ("double", 0)), (3081, ("double", 1)), (3092, ("double", 2)), (3082, ("double", 3)),
      (3083, ("double", 4))],
     (15.0, 0.0, 0.9999, 300000.0, 0.0),
     "+proj=tmerc +lat_0=0 +lon_0=15 +k=0.9999 +x_0=300000 +y_0=0 +ellps=WGS84 +units=m +no_defs",
     (16.0, 45.0)),
    ("Lambert conformal conic (2 parallels) on NAD83, US survey feet",
     [(1024, 1), (2048, 4269), (3072, 32767), (3074, 32767), (3075, 8), (3076, 9003),
      (3078, ("double", 0)), (3079, ("double", 1)), (3085, ("double", 2)), (3084, ("double", 3)),
      (3086, ("double", 4)), (3087, ("double", 5))],
     (45.0, 47.0, 44.0, -120.0, 600000.0 / US_FOOT, 0.0),
     "+proj=lcc +lat_1=45 +lat_2=47 +lat_0=44 +lon_0=-120 +x_0=600000 +y_0=0 +datum=NAD83 +units=us-ft +no_defs",
     (-119.5, 45.5)),
]


# Key directories where reading the codes alone, or writing the records into a GeoTIFF
# carelessly, went wrong: vola must read what GDAL reads from the same records.
TM_KEYS = [(1024, 1), (2048, 32767), (2050, 32767), (2056, 7030), (3072, 32767), (3074, 32767), (3075, 1),
           (3076, 9001), (3080, ("double", 0)), (3081, ("double", 1)), (3092, ("double", 2)), (3082, ("double", 3)),
           (3083, ("double", 4))]
TM_DOUBLES = (15.0, 0.0, 0.9999, 300000.0, 0.0)
AS_GDAL_READS = [
    # A citation of 3 bytes: TIFF keeps values of 4 bytes or less inside the tag entry.
    ("a 3-byte citation", TM_KEYS + [(3073, ("ascii", 0, 3))], TM_DOUBLES, b"ab|", ()),
    # A projected model with projected code 0 over a geographic code: not that code.
    ("projected code 0 over WGS 84", [(1024, 1), (2048, 4326), (3072, 0)], (), b"", ()),
    # A geocentric model over a geographic code (PDAL's lone-star.laz): that datum's
    # earth-centred CRS, not the geographic one (vola read EPSG:4326 degrees).
    ("geocentric model over WGS 84", [(1024, 3), (2048, 4326)], (), b"", ()),
    # Two key directories: the first one counts.
    ("two directories, user-defined first", TM_KEYS, TM_DOUBLES, b"",
     ((34735, key_directory([(1024, 1), (3072, 32617)])),)),
]


def keys_as_gdal_reads(vola, tmp, failures):
    checked = 0
    for what, keys, doubles, ascii, more in AS_GDAL_READS:
        las, tiff = Path(tmp) / "as_gdal.las", Path(tmp) / "as_gdal.tif"
        las_with_keys(keys, las, doubles, ascii, more)
        geotiff_with_keys(projection_records(las), tiff)
        srs = gdal.Open(str(tiff)).GetSpatialRef()
        crs = json.loads(subprocess.run([vola, "info", "--json", str(las)], check=True, capture_output=True,
                                        text=True).stdout).get("crs") or {}
        want = (srs.GetName(), srs.GetLinearUnitsName()) if srs else (None, None)
        got = (crs.get("name"), crs.get("unit"))
        # GDAL names a CRS it assembles from keys "unnamed"; where that CRS is an EPSG
        # code's, vola gives the code's name (EPSG:4978 is "WGS 84"), as GDAL names the code.
        if want[0] == "unnamed" and crs.get("epsg"):
            code = osr.SpatialReference()
            code.ImportFromEPSG(crs["epsg"])
            if srs.IsSame(code):
                want = (code.GetName(), want[1])
        print(f"{what}: GDAL {want}, vola {got}")
        checked += 1
        if got != want:
            failures.append(f"{what}: GDAL reads {want}, vola {got}")
    return checked


def user_defined_keys(vola, tmp, failures):
    """vola's CRS of each USER_DEFINED directory places a point where the PROJ definition
    the keys spell out (pyproj) places it, and has GDAL's name and unit."""
    from pyproj import CRS, Transformer
    checked = 0
    for what, keys, doubles, definition, lon_lat in USER_DEFINED:
        las, tiff = Path(tmp) / "user_defined.las", Path(tmp) / "user_defined.tif"
        las_with_keys(keys, las, doubles)
        geotiff_with_keys(projection_records(las), tiff)
        srs = gdal.Open(str(tiff)).GetSpatialRef()
        crs = json.loads(subprocess.run([vola, "info", "--json", str(las)], check=True, capture_output=True,
                                        text=True).stdout).get("crs") or {}
        checked += 1
        if not crs.get("wkt"):
            failures.append(f"{what}: vola reads no CRS from the keys (GDAL: {srs.GetName() if srs else None})")
            continue
        want = Transformer.from_crs("EPSG:4326", CRS.from_proj4(definition), always_xy=True).transform(*lon_lat)
        got = Transformer.from_crs("EPSG:4326", CRS.from_wkt(crs["wkt"]), always_xy=True).transform(*lon_lat)
        off = max(abs(a - b) for a, b in zip(want, got))
        print(f"{what}: vola {crs.get('name')!r} in {crs.get('unit')}, epsg {crs.get('epsg')}; "
              f"({lon_lat}) -> {got}, the keys' definition {want}, {off:.2e} apart")
        if off > 1e-3:
            failures.append(f"{what}: vola's CRS puts {lon_lat} at {got}, the keys' definition at {want}")
        if srs is None or (crs.get("name"), crs.get("unit")) != (srs.GetName(), srs.GetLinearUnitsName()):
            failures.append(f"{what}: GDAL reads {(srs.GetName(), srs.GetLinearUnitsName()) if srs else None}, "
                            f"vola {(crs.get('name'), crs.get('unit'))}")
    return checked


def made_up_keys(vola, tmp, failures):
    """Unit keys GDAL reads as units: (keys, what GDAL's reading must equal in vola's)."""
    checked = 0
    for keys in ([(1024, 1), (3072, 26995), (3076, 9003)],
                 [(1024, 1), (3072, 26910), (4099, 9003)],
                 [(1024, 1), (3072, 26910), (3076, 9002), (4099, 9003)],
                 # A geographic code with heights in feet: degrees have no metres, so only
                 # the heights' unit is compared (vola read it as 2D, heights taken as metres).
                 [(1024, 2), (2048, 4326), (4099, 9003)]):
        las, tiff = Path(tmp) / "keys.las", Path(tmp) / "made_up.tif"
        las_with_keys(keys, las)
        geotiff_with_keys({34735: las.read_bytes()[227 + 54:227 + 54 + 8 + 8 * len(keys)]}, tiff)
        gdal.SetConfigOption("GTIFF_REPORT_COMPD_CS", "YES")
        srs = gdal.Open(str(tiff)).GetSpatialRef()
        gdal.SetConfigOption("GTIFF_REPORT_COMPD_CS", None)
        geographic = (1024, 2) in keys
        horizontal = srs.GetLinearUnits()
        vertical = srs.GetTargetLinearUnits("VERT_CS") if srs.IsCompound() else horizontal
        crs = json.loads(subprocess.run([vola, "info", "--json", str(las)], check=True, capture_output=True,
                                        text=True).stdout).get("crs") or {}
        got_h = horizontal if geographic and crs.get("unit") == "degree" else METRES.get(crs.get("unit"))
        got_v = METRES.get(crs.get("vertical_unit") or crs.get("unit"))
        print(f"keys {keys}: GDAL metres per unit {horizontal:.10g} / {vertical:.10g}, vola {got_h} / {got_v}")
        checked += 1
        if got_h is None or got_v is None or abs(got_h - horizontal) > 1e-9 or abs(got_v - vertical) > 1e-9:
            failures.append(f"keys {keys}: GDAL reads units {horizontal} / {vertical} m, vola {crs.get('unit')} / "
                            f"{crs.get('vertical_unit')}")
    return checked


METRES = {"metre": 1.0, "foot": 0.3048, "US survey foot": 1200 / 3937}


def main():
    vola, shared = sys.argv[1], Path(sys.argv[2])
    data = Path(os.environ.get("VOLA_SHARED", shared)) / "data"
    files = sorted((data / "las").glob("*.las")) + sorted((data / "laz").glob("*.laz"))
    if not files:
        skip(f"no LAS files under {data}")
    checked, failures = 0, []
    # Reading keys goes through PROJ and GDAL, which print errors to stderr by default
    # (laspy_simple1_3.las names an EPSG CRS code as its linear unit); vola prints nothing
    # of theirs, only its own warnings (a label its bounds cannot fit: lone-star's).
    for path in files:
        run = subprocess.run([vola, "info", str(path)], capture_output=True, text=True)
        stray = [line for line in run.stderr.splitlines() if not line.startswith("vola: warning: ")]
        if run.returncode != 0 or stray:
            failures.append(f"{path.name}: vola info exits {run.returncode}, stderr {run.stderr.strip()!r}")
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
        made_up = (made_up_keys(vola, tmp, failures) + user_defined_keys(vola, tmp, failures) +
                   keys_as_gdal_reads(vola, tmp, failures))
    if checked < 3:
        failures.append(f"only {checked} files with projected GeoKeys and no WKT were found (expected at least 3)")
    if failures:
        print("FAIL:\n  " + "\n  ".join(failures), file=sys.stderr)
        sys.exit(1)
    print(f"OK: {checked} files, {made_up} made-up key directories")


if __name__ == "__main__":
    main()
