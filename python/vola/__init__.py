"""vola: VOLA volumetric trees from Python, with numpy arrays in and out.

A VOLA tree stores 3D occupancy as levels of 64-bit words (one word per 4x4x4 block,
one bit per voxel); the .vol file is the memory layout, so files open by memory
mapping without a copy. Everything heavy runs in C++ without the GIL.

    >>> import numpy as np, vola
    >>> points = np.random.default_rng(0).uniform(0, 10, size=(1000, 3))
    >>> tree = vola.build(points, voxel_size=0.5)          # grid quantization
    >>> tree.contains(tree.voxels()[:3])                    # (M, 3) -> (M,) bool
    array([ True,  True,  True])
    >>> tree.write("points.vol"); mapped = vola.open_mapped("points.vol")

Coordinates: voxel (i, j, k) covers [origin + i*voxel_size, origin + (i+1)*voxel_size)
per axis. Arrays of voxels are (N, 3) in key order, which is also the row order of
attribute columns (a voxel's rank). Errors raise vola.Error subclasses: FormatError
(bad bytes: names the file and byte offset), IoError, InvalidArgument.

Robot maps: vola.Map(voxel_size, max_range=0) takes range scans as `vola map` does
(OctoMap's model: each point is a ray from the sensor origin, its end voxel hit, the voxels
it passes free):

    >>> m = vola.Map(0.2, max_range=40.0)
    >>> m.insert(points_in_world, origin=(x, y, z))         # one scan
    >>> m.state(queries)          # (N,) int8: vola.UNKNOWN 0, vola.FREE 1, vola.OCCUPIED 2
    >>> m.probability(queries)    # (N,) float64, NaN where unknown
    >>> m.save("map.vol")         # a state map, the bytes `vola map` writes

A state map file (tree.is_state_map) holds every known voxel with a state bit (occupied
or free) and a "log_odds" column. vola.open gives its occupied voxels, as the CLI reads
it; vola.open(path, states=True) gives the state map itself, which vola.state(tree,
points) and vola.probability(tree, points) query in world coordinates and
vola.occupied_tree(tree) and vola.free_tree(tree) split into plain trees (the analysis
methods count every voxel of the tree they are called on).

Every CLI subcommand that works on voxels is a call here, through the same library
function and with the same errors:

    >>> both = vola.union(a, b); shell = a - a.erode(1)        # vola union / diff / erode
    >>> inflated = tree.dilate(3, "sphere"); solid, n = tree.fill()
    >>> view = tree.render(eye, look_at, size=(640, 480))        # {'image', 'depth', 'hits'}
    >>> tree.collide_sphere(centres, 2.5)                         # (N,) bool, world units
    >>> dsm, geotransform = tree.raster("dsm", resolution=1.0)   # the GeoTIFF's grid
    >>> vola.export_raster(tree, "dsm.tif", "dsm"); vola.export_ply(tree, "v.ply", depth=6)
    >>> vola.tile(["a.las", "b.las"], "tiles", tile_size=512, depth=6)
    >>> kept = vola.filter_points(xyz, {"classification": c}, ["smrf", "hag"], crs="EPSG:32610")
    >>> vola.export(tree, "dsm.tif", raster="dsm"); vola.export(tree, "map.bt")  # by extension
    >>> vola.pipeline(["autzen.laz", {"type": "filters.smrf"}, "ground.laz"])    # vola pipeline

The export_* functions take the CLI's `vola export --depth K` as depth=K (the grid of the
tree's first K levels); a format that refuses a deep tree says so naming `depth`.
"""

from __future__ import annotations

import builtins
import functools
import json
import os
from typing import Any, Optional, Tuple, Union

from ._vola import (
    FREE,
    OCCUPIED,
    RASTER_NODATA,
    UNKNOWN,
    Error,
    FormatError,
    InvalidArgument,
    IoError,
    Map,
    TileSet,
    Tree,
    __version__,
    build,
    build_from_voxels,
    DistanceField,
    compression_available,
    convert,
    describe_crs,
    difference,
    export_binvox,
    export_csv,
    export_height_map,
    export_las,
    export_map,
    export_npy,
    export_occupancy_above,
    export_ply,
    export_raster,
    export_ros_map,
    export_slices,
    export_xyz,
    filter_points,
    free_tree,
    from_dense,
    input_formats,
    intersect,
    occupied_tree,
    open_mapped,
    open_tiles,
    parse,
    probability,
    read,
    state,
    tile,
    translate,
    union,
    _export_format,
    _run_pipeline,
)



def _refusing_cut_mappings(function):
    """`function` with every mapped Tree among its arguments checked before and after the
    call: a file cut by another process while mapped (truncated, or copied over in place)
    reads as zeros, and what a call read from it would mean nothing (voxels() gave rows of
    [0 0 0], write() wrote a file vola then refused)."""

    @functools.wraps(function)
    def call(*args, **kwargs):
        mapped = [a for a in (*args, *kwargs.values()) if isinstance(a, Tree) and a.is_mapped]
        for tree in mapped:
            tree._check_mapped_often()
        try:
            result = function(*args, **kwargs)
        except Error:
            # Cut during the call: the zeros it read made it fail ("<memory>: level 2 block 0
            # is empty ..."); the cut, naming the file, is what to report.
            for tree in mapped:
                try:
                    tree.check_mapped()
                except IoError as cut:
                    raise cut from None
            raise
        for tree in mapped:
            tree._check_mapped_often()
        return result

    return call


for _name, _member in list(vars(Tree).items()):
    if type(_member).__name__ == "instancemethod" and _name not in ("__repr__", "__len__", "__setstate__", "check_mapped", "_check_mapped_often"):
        setattr(Tree, _name, _refusing_cut_mappings(_member))
for _name in ("difference", "export_binvox", "export_csv", "export_height_map", "export_las", "export_map", "export_npy",
              "export_occupancy_above", "export_ply", "export_raster", "export_ros_map", "export_slices", "export_xyz", "free_tree",
              "intersect", "occupied_tree", "probability", "state", "union", "_export_format"):
    globals()[_name] = _refusing_cut_mappings(globals()[_name])
# Maps and distance fields built from a tree read it too (Map.from_tree, DistanceField(tree),
# DistanceField.update): a cut mapping gave an empty map or distances at the cap.
for _class in (Map, DistanceField):
    for _name, _member in list(vars(_class).items()):
        if isinstance(_member, staticmethod):
            setattr(_class, _name, staticmethod(_refusing_cut_mappings(_member.__func__)))
        elif type(_member).__name__ == "instancemethod" and (_name == "__init__" or not _name.startswith("__")):
            setattr(_class, _name, _refusing_cut_mappings(_member))
del _name, _member, _class

__all__ = [
    "FREE",
    "OCCUPIED",
    "RASTER_NODATA",
    "UNKNOWN",
    "Error",
    "FormatError",
    "InvalidArgument",
    "IoError",
    "Map",
    "TileSet",
    "Tree",
    "__version__",
    "build",
    "build_from_voxels",
    "DistanceField",
    "compression_available",
    "convert",
    "describe_crs",
    "difference",
    "export",
    "export_binvox",
    "export_csv",
    "export_height_map",
    "export_las",
    "export_map",
    "export_npy",
    "export_occupancy_above",
    "export_ply",
    "export_raster",
    "export_ros_map",
    "export_slices",
    "export_xyz",
    "filter_points",
    "free_tree",
    "from_dense",
    "input_formats",
    "intersect",
    "occupied_tree",
    "open",
    "open_mapped",
    "open_tiles",
    "parse",
    "pipeline",
    "probability",
    "read",
    "state",
    "tile",
    "translate",
    "union",
]


def open(path: Union[str, os.PathLike], mapped: bool = True, states: bool = False) -> Tree:  # noqa: A001 (vola.open, like io.open)
    """Opens a .vol file: memory-mapped by default (the level words stay in the page
    cache and numpy views of them read the mapping), or read into memory. A state map
    (`vola map`, Map.save: occupied, free and unknown voxels) opens as its occupied voxels,
    as every vola command reads it, so that contains, collide, plan, render and the rest
    see obstacles only; states=True keeps every known voxel, free ones too, for
    vola.state, vola.probability and vola.free_tree. (vola.read and vola.open_mapped give
    the file as it is.) When another process cuts a mapped file (truncates it, or copies
    another file over it in place), every Tree method and vola function given the tree
    raises vola.IoError instead of answering from the zeros the mapping then holds (a copy
    over it is found by the file's size and time, looked at at most once a millisecond)."""
    tree = open_mapped(path) if mapped else read(path)
    if tree.is_state_map and not states:
        return occupied_tree(tree)
    return tree


PathLike = Union[str, os.PathLike]


def pipeline(spec: Union[PathLike, list, dict]) -> list:
    """Runs a PDAL-style pipeline as `vola pipeline FILE.json` does (docs/FILTERS.md): a
    reader, point filters, writers. spec: the JSON file's path, the JSON text, or the same
    as Python lists and dicts, e.g. ["autzen.laz", {"type": "filters.smrf"},
    {"type": "filters.range", "limits": "Classification[2:2]"}, "ground.laz"] (a name without a
    type between the first and the last is another input to PDAL, and refused). Returns one
    dict per writer: input, output, voxels (a .vol written), voxel_count, filters (the
    conversion's filter lines), stages (per stage: spec, points_in, points_out, ground),
    warnings (what the user should know: a CRS relabelled, a CRS a PLY cannot keep)."""
    if isinstance(spec, (list, dict)):
        return _run_pipeline(json.dumps(spec), "<pipeline>")
    text = os.fspath(spec)
    if text.lstrip().startswith(("[", "{")):
        return _run_pipeline(text, "<pipeline>")
    try:
        with builtins.open(text, encoding="utf-8") as f:
            return _run_pipeline(f.read(), text)
    except OSError as e:
        raise IoError(f"{text}: cannot open ({e.strerror})") from None


def export(tree: Tree, path: PathLike, *, raster: Optional[str] = None, resolution: float = 0.0,
           map: bool = False, bits: int = 16, occupancy_above: Optional[int] = None,  # noqa: A002 (--map)
           slices: bool = False, ascii: bool = False, cubes: bool = False,  # noqa: A002 (--ascii)
           free: Optional[Tree] = None, band: Optional[Tuple[float, float]] = None, depth: int = 0,
           format: str = "auto") -> Any:  # noqa: A002 (--format)
    """`vola export TREE OUT` in one call: the format from path's extension (.ply, .xyz, .csv,
    .las, .laz, .binvox, .npy, .tif, .png, .bt, .ot, .vdb, .yaml), or format= one of 'ply', 'xyz',
    'csv', 'las', 'binvox', 'npy', 'png', 'tif', 'octomap', 'vdb', 'rosmap' for a path without one
    (`vola export --format`); options as the CLI's flags:
    raster='dsm'|'dtm'|'intensity'|'density'|'count' (+ resolution) for a GeoTIFF; map=True
    (+ bits) or occupancy_above=Z for a PNG, slices=True for a directory of PNGs; ascii/cubes
    for PLY; free= for maps; band=(zmin, zmax) for a ROS map (.yaml, the robot's height band).
    A state map (`vola map`, Map.save) keeps its free space in .bt, .ot, .vdb and .yaml only
    when opened with it: vola.open(path, states=True) or vola.read(path); vola.open(path)
    alone gives its occupied voxels, and the map written then has no free cells.
    Options that do not apply to the format are refused, as the CLI
    refuses them. Returns what the export_* function for the format returns."""
    fmt = _export_format(os.fspath(path), slices=slices, map=map, occupancy_above=occupancy_above is not None,
                         raster=raster is not None, resolution=bool(resolution), ascii=ascii, cubes=cubes,
                         bits=bits != 16, free=free is not None, band=band is not None, format=format)
    if fmt == "tif":
        return export_raster(tree, path, raster, resolution, depth)
    if fmt == "png":
        if slices:
            return export_slices(tree, path, True, depth)
        if map:
            return export_height_map(tree, path, bits, depth)
        return export_occupancy_above(tree, path, occupancy_above, depth)
    if fmt == "ply":
        return export_ply(tree, path, ascii, cubes, depth)
    if fmt in ("octomap", "vdb"):
        return export_map(tree, path, free, depth)
    if fmt == "rosmap":
        return export_ros_map(tree, path, tuple(band), free, depth)
    return {"xyz": export_xyz, "csv": export_csv, "las": export_las, "binvox": export_binvox,
            "npy": export_npy}[fmt](tree, path, depth)
