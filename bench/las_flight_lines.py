#!/usr/bin/python3
"""Rewrites a LAS file's records in flight-line order (the header and VLRs unchanged).

`bench/las_survey.py` writes its generated survey with the points in random order, the
worst case for anything that visits voxels point by point. Airborne surveys come in
acquisition order: strips flown back and forth, each scanned across. This puts the same
records in that kind of order, strips of STRIP units along y (in the file's coordinate
units), x ascending in even strips and descending in odd ones, so that a conversion of
both files shows what the input order costs.

usage: bench/las_flight_lines.py IN.las OUT.las [--strip 50]
"""
import argparse
import struct

import numpy as np


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("input")
    parser.add_argument("output")
    parser.add_argument("--strip", type=float, default=50.0, help="strip width along y, file units (default 50)")
    args = parser.parse_args()
    with open(args.input, "rb") as f:
        data = f.read()
    if data[:4] != b"LASF":
        raise SystemExit(f"{args.input}: not a LAS file")
    offset = struct.unpack_from("<I", data, 96)[0]
    length = struct.unpack_from("<H", data, 105)[0]
    count = struct.unpack_from("<I", data, 107)[0]
    if data[25] >= 4 and count == 0:
        count = struct.unpack_from("<Q", data, 247)[0]
    if offset + count * length > len(data):
        raise SystemExit(f"{args.input}: {count} records of {length} bytes do not fit the file")
    y_scale = struct.unpack_from("<d", data, 139)[0]
    records = np.frombuffer(data, dtype=np.uint8, count=count * length, offset=offset).reshape(count, length)
    x = records[:, 0:4].copy().view("<i4").ravel().astype(np.int64)
    y = records[:, 4:8].copy().view("<i4").ravel().astype(np.int64)
    strip_units = max(1, int(round(args.strip / y_scale)))
    strip = (y - y.min()) // strip_units
    along = np.where(strip % 2 == 0, x, -x)
    order = np.lexsort((along, strip))
    with open(args.output, "wb") as f:
        f.write(data[:offset])
        f.write(records[order].tobytes())
        f.write(data[offset + count * length:])
    print(f"{args.output}: {count} records in {int(strip.max()) + 1} strips of {args.strip:g} units")


if __name__ == "__main__":
    main()
