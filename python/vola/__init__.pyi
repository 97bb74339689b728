import os
from typing import Union

from ._vola import (
    FREE as FREE,
    OCCUPIED as OCCUPIED,
    UNKNOWN as UNKNOWN,
    Error as Error,
    FormatError as FormatError,
    InvalidArgument as InvalidArgument,
    IoError as IoError,
    Map as Map,
    TileSet as TileSet,
    Tree as Tree,
    __version__ as __version__,
    build as build,
    build_from_voxels as build_from_voxels,
    DistanceField as DistanceField,
    compression_available as compression_available,
    convert as convert,
    describe_crs as describe_crs,
    free_tree as free_tree,
    export_map as export_map,
    from_dense as from_dense,
    input_formats as input_formats,
    occupied_tree as occupied_tree,
    open_mapped as open_mapped,
    open_tiles as open_tiles,
    parse as parse,
    probability as probability,
    read as read,
    state as state,
)

def open(path: Union[str, os.PathLike], mapped: bool = True) -> Tree: ...
