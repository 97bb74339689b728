"""vola.open_tiles: a tile set written by `vola tile` from a real LAS survey, queried
in world coordinates. Checked against the tiles' own voxel centres (`Tree.centers`) and
against points far from any tile; a query opens only the tiles it touches."""

import json
import pathlib
import subprocess

import numpy as np
import pytest

import vola


@pytest.fixture(scope="module")
def tile_index(tmp_path_factory, shared_data, vola_cli) -> pathlib.Path:
    las = shared_data / "las" / "pdal_autzen_trim.las"
    if not las.exists():
        pytest.skip(f"{las} missing")
    out = tmp_path_factory.mktemp("tiles")
    subprocess.run([vola_cli, "tile", str(las), "--tile-size", "256", "--depth", "4", "-o", str(out), "-q"],
                   check=True)
    return out / "index.geojson"


def test_tile_set_opens_lazily_and_answers_in_world_coordinates(tile_index: pathlib.Path) -> None:
    tiles = vola.open_tiles(tile_index)
    index = json.loads(tile_index.read_text())
    assert len(tiles) == index["vola"]["tiles"] == len(tiles.tiles())
    assert repr(tiles).startswith(f"<vola.TileSet tiles={len(tiles)} tile_size=")
    assert tiles.tiles_opened == 0
    assert tiles.tile_size == 256.0 and tiles.depth == 4 and tiles.voxel_size == 1.0

    first = tiles.tiles()[0]
    tree = tiles.tile(*first["tile"])
    assert tree is not None and len(tree) == first["voxels"]
    assert tiles.tiles_opened == 1

    centres = tree.centers()
    assert tiles.contains(centres).all()
    assert tiles.tiles_opened == 1, "centres of one tile open no other tile"
    # Half a voxel up from every centre of the ground tile: occupied exactly where
    # the tile itself has the voxel above.
    above = centres + np.array([0.0, 0.0, 1.0])
    expected = tree.contains(tree.world_to_voxel(above)[0])
    inside = tree.world_to_voxel(above)[1]
    np.testing.assert_array_equal(tiles.contains(above)[inside], expected[inside])

    far = np.array([[0.0, 0.0, 0.0], [1e7, 1e7, 0.0]])
    assert not tiles.contains(far).any()
    assert tiles.tile(10**6, 0, 0) is None


def test_tile_set_reads_the_attribute_columns(tile_index: pathlib.Path, shared_data) -> None:
    tiles = vola.open_tiles(tile_index)
    assert tiles.attributes == ["red", "green", "blue", "intensity", "classification", "height",
                                "number_of_returns"]
    first = tiles.tiles()[0]
    tree = tiles.tile(*first["tile"])
    centres = tree.centers()
    for name in ("intensity", "classification", "height"):
        np.testing.assert_array_equal(tiles.values(centres, name), tree.attribute(name).astype(np.float64))
    # The tile's classification equals the majority of the survey's points in each voxel.
    survey = vola.convert(shared_data / "las" / "pdal_autzen_trim.las", voxel_size=1.0, origin=(0.0, 0.0, 0.0))
    in_survey = survey.world_to_voxel(centres)[0]
    rows = survey.rank(in_survey)
    np.testing.assert_array_equal(tiles.values(centres, "classification"), survey.attribute("classification")[rows])
    assert np.isnan(tiles.values([1e7, 1e7, 0.0], "intensity"))
    with pytest.raises(KeyError, match="has: red"):
        tiles.values(centres, "nope")


def test_bad_index_raises_format_error(tmp_path: pathlib.Path) -> None:
    bad = tmp_path / "index.geojson"
    bad.write_text('{"type": "FeatureCollection"}')
    with pytest.raises(vola.FormatError, match="vola"):
        vola.open_tiles(bad)
    with pytest.raises(vola.IoError, match="is a folder; open the tile set's index"):
        vola.open_tiles(tmp_path)  # a bare RuntimeError from the stream before
