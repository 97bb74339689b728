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
"""

from __future__ import annotations

import os
from typing import Union

from ._vola import (
    Error,
    FormatError,
    InvalidArgument,
    IoError,
    TileSet,
    Tree,
    __version__,
    build,
    build_from_voxels,
    compression_available,
    convert,
    export_las,
    export_map,
    from_dense,
    input_formats,
    open_mapped,
    open_tiles,
    parse,
    read,
    translate,
)

__all__ = [
    "Error",
    "FormatError",
    "InvalidArgument",
    "IoError",
    "TileSet",
    "Tree",
    "__version__",
    "build",
    "build_from_voxels",
    "compression_available",
    "convert",
    "export_las",
    "export_map",
    "from_dense",
    "input_formats",
    "open",
    "open_mapped",
    "open_tiles",
    "parse",
    "read",
    "translate",
]


def open(path: Union[str, os.PathLike], mapped: bool = True) -> Tree:  # noqa: A001 (vola.open, like io.open)
    """Opens a .vol file: memory-mapped by default (the level words stay in the page
    cache and numpy views of them read the mapping), or read into memory."""
    return open_mapped(path) if mapped else read(path)
