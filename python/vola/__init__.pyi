import os
from typing import Union

from ._vola import (
    Error as Error,
    FormatError as FormatError,
    InvalidArgument as InvalidArgument,
    IoError as IoError,
    TileSet as TileSet,
    Tree as Tree,
    __version__ as __version__,
    build as build,
    build_from_voxels as build_from_voxels,
    compression_available as compression_available,
    convert as convert,
    export_map as export_map,
    from_dense as from_dense,
    input_formats as input_formats,
    open_mapped as open_mapped,
    open_tiles as open_tiles,
    parse as parse,
    read as read,
)

def open(path: Union[str, os.PathLike], mapped: bool = True) -> Tree: ...
