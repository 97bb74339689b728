#!/usr/bin/env python3
"""One conversion, three front ends, the same bytes.

Every case is an input file from the shared real data plus a set of conversion options,
named once (the Python keyword names) and spelled for each front end by the table
FRONT_END_SPELLING below. The manifest (tests/convert_equivalence.sha256) holds the SHA-256
of the .vol that `vola convert` wrote for each case before the conversion pipeline was
consolidated; this script checks that today's CLI, Python's vola.convert and the C API's
vola_convert still write exactly those bytes. The three DEM cases with a voxel size were
recorded again on 2026-11-28, when a DEM's default grid origin began to follow the
raster's own cells (before, it snapped to multiples of the voxel size and moved the cells).
The two laspy_simple1_3.las cases were recorded again on 2026-11-28, when GeoTIFF keys that
define a CRS by its parts began to be read through GDAL: the file's keys (a projected model
type, no projection, a linear unit code GDAL does not know) now give GDAL's engineering CRS
in metres, and the .vol holds its WKT. The same file with its key record renamed away
still converts to the old bytes, so the voxels did not change. On 2026-11-29 the cases of
laspy_simple1_4.las (LAS 1.4 with GeoTIFF keys and a WKT record, global encoding bit 4
clear: the keys are the CRS, by the specification; the WKT record won before) and of
pdal_extrabytes.las (its extra-bytes field "Intensity" is now the column "Intensity_2",
apart from the record's intensity) were recorded again; their voxels and values are the
same (`vola voxels` and `vola info` of both builds' files compared). Later on 2026-11-29 the
four cases of trimesh_ballA.off and modelnet's bathtub_0001.off were recorded again, when
vola began to read OFF itself, in double precision, instead of through Assimp's 32-bit
floats: the header's bbox now holds the file's decimals (-10.9128, not -10.912799835...);
bathtub's voxels are the same, ballA's differ by one voxel of 306,792 at depth 4 (a
vertex on a cell boundary, checked by converting a copy of the file with its coordinates
rounded to 32-bit floats: the old voxels again). On 2026-11-29 (later) the binvox files' basic
cases became depth 3 (GRID_OPTIONS), when a voxel grid converted at a finer voxel size
began to fill each cell instead of setting one voxel at its centre (at depth 4 or 5 the
chairs' cells span tens of voxels: they came out perforated; filled, depth 5 is tens of
millions of voxels and refused), and the two of
pdal_autzen-utm.pcd, when its PointSourceId began to be reduced by majority, as an
identifier is from LAS, PLY and NPY (the PCD reader lower-cased the name before asking
whether it names one): their voxels are the same, that column's values are not.

  convert_equivalence.py --vola build/apps/vola/vola --c-tool build/tests/capi_convert_tool \
      --python-path build/python [--front-ends cli,python,c] [--write-manifest]

The shared data lives in $VOLA_SHARED (default ../shared beside the repository). A case
whose input is missing fails (the data is part of the test), it is never skipped.
"""
import argparse
import hashlib
import os
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
MANIFEST = Path(__file__).resolve().parent / "convert_equivalence.sha256"

# Every file of these kinds under data/ takes the two basic cases; the generic list keeps
# the test honest when the shared folder grows (a new file is a new case once the manifest
# is regenerated with --write-manifest from a trusted build).
GENERIC_PATTERNS = [
    "data/las/*.las", "data/las/permutations/*.las", "data/pcd/*.pcd", "data/ply/*.ply",
    "data/mesh/stl/*.stl", "data/mesh/obj/*.obj", "data/mesh/off/*.off",
    "data/kitti/*.bin", "data/kitti/object_training/velodyne/*.bin", "data/dem/*.tif",
    "data/bench/*_points_1e6.npy", "data/modelnet/off/bathtub_0001.off",
]
GENERIC_OPTIONS = [
    {"quantize": "toolkit", "depth": 4},
    # Some inputs are in degrees (EPSG:4326), refused as grid voxels unless allowed.
    {"quantize": "grid", "depth": 5, "allow_geographic": True},
]
# Voxel grids fill their cells on a finer grid: at depth 4 or 5 a 32-cell chair fills tens of
# millions of voxels (refused beyond 2^25), so they take the basic cases at depth 3.
GRID_PATTERNS = ["data/binvox/*.binvox"]
GRID_OPTIONS = [
    {"quantize": "toolkit", "depth": 3},
    {"quantize": "grid", "depth": 3},
]
# Options beyond the basics, each on a real file that exercises it.
SPECIFIC_CASES = [
    ("data/las/pdal_autzen_trim.las", {"voxel_size": 10.0}),
    ("data/las/pdal_autzen_trim.las",
     {"voxel_size": 10.0, "filters": ["where:Classification == 2 && z < 450", "crop:636100,848950,637000,849400"]}),
    ("data/las/pdal_autzen_trim.las", {"voxel_size": 5.0, "filters": ["smrf", "hag", "where:HeightAboveGround > 2"]}),
    ("data/las/pdal_autzen_trim.las", {"voxel_size": 10.0, "attributes": False, "compress": True}),
    ("data/las/pdal_autzen_trim.las", {"voxel_size": 20.0, "origin": [636000.0, 848000.0, 400.0]}),
    ("data/las/pdal_autzen_trim.las", {"quantize": "toolkit", "depth": 4, "nbits": 1}),
    ("data/las/pdal_autzen_trim.las", {"quantize": "toolkit", "depth": 5, "dense": True}),
    ("data/las/pdal_autzen_trim.las",
     {"quantize": "toolkit", "depth": 6, "bbox": [636500.0, 849000.0, 400.0, 638000.0, 851000.0, 600.0]}),
    ("data/las/pdal_1.2-with-color.las", {"voxel_size": 50.0, "epsg": 32615}),
    ("data/las/pdal_1.2-with-color.las", {"voxel_size": 50.0, "assign_crs": "EPSG:32615"}),
    ("data/las/pdal_epsg_4326.las", {"voxel_size": 0.001, "allow_geographic": True}),
    ("data/las/pdal_autzen_trim.las", {"voxel_size": 5.0, "target_crs": "EPSG:32610"}),
    ("data/las/pdal_epsg_4326.las", {"voxel_size": 1.0, "target_crs": "32615", "attributes": False}),
    ("data/las/pdal_extrabytes.las", {"voxel_size": 1.0}),
    ("data/las/laspy_test1_4.las", {"voxel_size": 5.0}),
    ("data/pcd/pcl_milk_color.pcd", {"voxel_size": 0.01}),
    ("data/ply/trimesh_bunny_ascii.ply", {"quantize": "toolkit", "depth": 5, "solid": True}),
    ("data/mesh/stl/trimesh_teapot_bin.stl", {"quantize": "toolkit", "depth": 5, "solid": True}),
    ("data/mesh/obj/ajc_spot.obj", {"voxel_size": 0.02}),
    ("data/binvox/trimesh_chair_model.binvox", {}),
    ("data/dem/pdal_gdal_int16_epsg26711.tif", {"voxel_size": 60.0, "dem_base": 0.0}),
    ("data/dem/pdal_gdal_int16_epsg26711.tif", {"voxel_size": 60.0, "dem_surface_only": True}),
    ("data/dem/pysheds_dem_int16_tiled_epsg4326.tif", {"voxel_size": 0.005, "allow_geographic": True}),
    ("data/bench/surface_points_1e6.npy", {"quantize": "toolkit", "depth": 5, "compress": True}),
    ("data/las/pdal_autzen_trim.las", {"voxel_size": 3.0, "attributes": False, "compress_max": True}),
    ("golden/d2_sparse_n1/input.txt", {"quantize": "toolkit", "depth": 2, "nbits": 1}),
    ("golden/d2_dense_n1/input.txt", {"quantize": "toolkit", "depth": 2, "nbits": 1, "dense": True}),
    ("golden/d2_sparse_n1/input.txt",
     {"quantize": "toolkit", "depth": 2, "nbits": 1, "payload_columns": [4, 5, 6]}),
    ("golden/fixed_bbox_clip/input.txt",
     {"quantize": "toolkit", "depth": 2, "bbox": [0.0, 0.0, 0.0, 15.0, 15.0, 15.0]}),
    ("golden/crs29902_sparse/input.txt", {"quantize": "toolkit", "depth": 3, "epsg": 29902}),
    ("golden/d4_sparse_random/input.txt", {"voxel_size": 0.5, "columns": [3, 2, 1]}),
    ("golden/d2_sparse_n1/input.txt",
     {"voxel_size": 0.5, "text_attributes": ["red=4:u8:max", "green=5:f32:mean", "class=10:u8:majority"]}),
    ("golden/d2_sparse_n1/input.txt", {"voxel_size": 0.5, "skip_lines": 2, "format": "text"}),
]


def shared_root(default):
    shared = Path(os.environ.get("VOLA_SHARED") or default or ROOT.parent / "shared").resolve()
    if not (shared / "data").is_dir():
        if os.environ.get("CI"):
            raise SystemExit(f"convert_equivalence: CI is set but the shared data is missing at {shared}")
        print(f"convert_equivalence: skipped, no shared data at {shared} (set VOLA_SHARED)")
        sys.exit(77)
    return shared


def all_cases(shared):
    cases = []
    for patterns, generic in ((GENERIC_PATTERNS, GENERIC_OPTIONS), (GRID_PATTERNS, GRID_OPTIONS)):
        for pattern in patterns:
            matches = sorted(shared.glob(pattern))
            if not matches:
                raise SystemExit(f"convert_equivalence: nothing matches {shared}/{pattern}: is the shared data there?")
            for path in matches:
                for options in generic:
                    cases.append((str(path.relative_to(shared)), options))
    cases.extend(SPECIFIC_CASES)
    return cases


def case_id(relpath, options):
    parts = [relpath] + [f"{k}={options[k]}" for k in sorted(options)]
    return " ".join(str(p).replace(" ", "") for p in parts)


# option name -> how each front end spells it. CLI: a function giving the flags.
def cli_flags(options):
    flags = []
    for key, value in options.items():
        if key == "attributes":
            if not value:
                flags.append("--no-attributes")
        elif key == "text_attributes":
            for spec in value:
                flags += ["--attribute", spec]
        elif key == "epsg":
            flags += ["--assign-crs", str(value)]
        elif key == "filters":
            for stage in value:
                flags += ["--filter", stage]
        elif isinstance(value, bool):
            if value:
                flags.append("--" + key.replace("_", "-"))
        elif isinstance(value, list):
            flags += ["--" + key.replace("_", "-")] + [repr(v) if isinstance(v, float) else str(v) for v in value]
        else:
            flags += ["--" + key.replace("_", "-"), repr(value) if isinstance(value, float) else str(value)]
    return flags


def c_arguments(options):
    """key=value pairs for tests/capi/convert_tool.c; lists as comma-separated values."""
    out = []
    for key, value in options.items():
        if isinstance(value, bool):
            value = int(value)
        if key == "filters":  # stages hold commas
            value = ";".join(value)
        elif isinstance(value, list):
            value = ",".join(repr(v) if isinstance(v, float) else str(v) for v in value)
        elif isinstance(value, float):
            value = repr(value)
        out.append(f"{key}={value}")
    return out


def sha256(path):
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


class FrontEnds:
    def __init__(self, args):
        self.vola = args.vola
        self.c_tool = args.c_tool
        self.python_module = None
        if "python" in args.front_ends:
            sys.path.insert(0, args.python_path)
            import vola  # noqa: E402  (the module under test, from the build tree)
            self.python_module = vola

    def run(self, front_end, source, options, out):
        if front_end == "cli":
            cmd = [self.vola, "convert", str(source), str(out), "--quiet"] + cli_flags(options)
            result = subprocess.run(cmd, capture_output=True, text=True)
            if result.returncode != 0:
                raise RuntimeError(" ".join(cmd) + "\n" + result.stderr)
        elif front_end == "python":
            self.python_module.convert(str(source), output=str(out), **options)
        elif front_end == "c":
            cmd = [self.c_tool, str(source), str(out)] + c_arguments(options)
            result = subprocess.run(cmd, capture_output=True, text=True)
            if result.returncode != 0:
                raise RuntimeError(" ".join(cmd) + "\n" + result.stderr)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--vola", required=True)
    parser.add_argument("--c-tool")
    parser.add_argument("--python-path")
    parser.add_argument("--front-ends", default="cli")
    parser.add_argument("--shared-default", help="the shared folder when VOLA_SHARED is not set")
    parser.add_argument("--write-manifest", action="store_true",
                        help="record the CLI's hashes as the manifest (only from a trusted build)")
    args = parser.parse_args()
    args.front_ends = args.front_ends.split(",")
    shared = shared_root(args.shared_default)
    cases = all_cases(shared)
    front_ends = FrontEnds(args)

    expected = {}
    if not args.write_manifest:
        for line in MANIFEST.read_text().splitlines():
            digest, ident = line.split("  ", 1)
            expected[ident] = digest

    failures, lines = [], []
    with tempfile.TemporaryDirectory() as tmp:
        for n, (relpath, options) in enumerate(cases):
            ident = case_id(relpath, options)
            source = shared / relpath
            if not source.exists():
                failures.append(f"{ident}: input missing at {source}")
                continue
            for front_end in (["cli"] if args.write_manifest else args.front_ends):
                out = Path(tmp) / f"case{n}_{front_end}.vol"
                try:
                    front_ends.run(front_end, source, options, out)
                except Exception as e:  # a front end that refuses a case the CLI took is a failure
                    failures.append(f"{ident} [{front_end}]: {e}")
                    continue
                digest = sha256(out)
                out.unlink()
                if args.write_manifest:
                    lines.append(f"{digest}  {ident}")
                elif ident not in expected:
                    failures.append(f"{ident}: not in the manifest (regenerate it from a trusted build)")
                elif digest != expected[ident]:
                    failures.append(f"{ident} [{front_end}]: sha256 {digest}, manifest {expected[ident]}")
    if args.write_manifest:
        MANIFEST.write_text("\n".join(lines) + "\n")
        print(f"convert_equivalence: wrote {len(lines)} hashes to {MANIFEST}")
    for f in failures:
        print("FAIL", f)
    print(f"convert_equivalence: {len(cases)} cases x {len(args.front_ends)} front ends, {len(failures)} failures")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
