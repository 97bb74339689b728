"""vola.tile writes the tile set `vola tile` writes (every file byte for byte), reports
what it did, and refuses what the CLI refuses, in Python's words."""
import subprocess

import numpy as np
import pytest

import vola


@pytest.fixture(scope="module")
def autzen(shared_data):
    path = shared_data / "las" / "pdal_autzen_trim.las"
    if not path.exists():
        pytest.skip(f"no {path}")
    return path


def files(folder):
    return {p.relative_to(folder).as_posix(): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def test_same_tiles_as_the_cli(autzen, vola_cli, tmp_path):
    summary = vola.tile([autzen], tmp_path / "py", tile_size=1000.0, depth=4, memory_budget=64 << 20, threads=1)
    subprocess.run([vola_cli, "tile", str(autzen), "-o", str(tmp_path / "cli"), "--tile-size", "1000", "--depth", "4",
                    "--memory", "64M", "--threads", "1", "-q"], check=True)
    ours, theirs = files(tmp_path / "py"), files(tmp_path / "cli")
    assert ours.keys() == theirs.keys()
    for name in ours:  # tiles, overviews, index.geojson and index.gpkg
        assert ours[name] == theirs[name], name
    tiles = [name for name in ours if name.split("/")[-1].startswith("tile_") and "overviews" not in name]
    assert summary["tiles"] == len(tiles) > 1 and summary["overview_files"] > 0
    assert summary["points_in"] == summary["points"] > 100000 and summary["points_outside"] == 0
    assert summary["voxel_size"] == 1000.0 / 4**4 and summary["crs_wkt"] and not summary["warnings"]
    assert "classification" in summary["attributes"]
    # Read back: the voxels of the survey on the tiles' grid are the tiles' voxels.
    tree = vola.convert(autzen, voxel_size=summary["voxel_size"], origin=(0.0, 0.0, 0.0))
    tile_set = vola.open_tiles(summary["index"])
    assert len(tile_set) == summary["tiles"] and summary["voxels"] == len(tree)
    assert tile_set.contains(tree.centers()).all()
    assert not tile_set.contains(tree.centers() + [0.0, 0.0, 200.0]).any()


def test_refusals_and_warnings_in_python_words(autzen, shared_data, tmp_path):
    with pytest.raises(vola.InvalidArgument, match="^inputs: no input: give point files or generate_survey N"):
        vola.tile([], tmp_path / "none", tile_size=100.0, depth=3)
    geographic = shared_data / "las" / "pdal_epsg_4326.las"
    with pytest.raises(vola.InvalidArgument, match="pdal_epsg_4326.las is in WGS 84, a geographic CRS.*give target_crs .*allow_geographic"):
        vola.tile([geographic], tmp_path / "deg", tile_size=1.0, depth=3)
    with pytest.raises(vola.InvalidArgument, match="not a regular file"):
        vola.tile([tmp_path], tmp_path / "dir", tile_size=100.0, depth=3)
    with pytest.raises(vola.IoError, match="missing.las: cannot open: No such file"):  # as vola.convert says it
        vola.tile([tmp_path / "missing.las"], tmp_path / "gone", tile_size=100.0, depth=3)
    relabelled = vola.tile([autzen], tmp_path / "relabel", tile_size=2000.0, depth=3, assign_crs="32610", overviews=False)
    (warning,) = relabelled["warnings"]
    assert "assign_crs 32610 relabels its coordinates" in warning and "--" not in warning
    assert relabelled["epsg"] == 32610 and relabelled["overview_files"] == 0
    summary = vola.tile([], tmp_path / "generated", tile_size=400.0, depth=3, generate_survey=20000, seed=3,
                        assign_crs="EPSG:32633")
    assert summary["points_in"] == 20000 and summary["tiles"] > 0 and summary["epsg"] == 32633
    assert np.isclose(summary["voxel_size"], 400.0 / 64)


def test_per_point_filters_as_the_cli(autzen, vola_cli, tmp_path):
    """filters= runs vola tile's --where chunk by chunk: the same files as the CLI's."""
    vola.tile([autzen], tmp_path / "py", tile_size=1000.0, depth=4, threads=1, chunk_points=7000,
              filters=["where:Classification == 2"])
    subprocess.run([vola_cli, "tile", str(autzen), "-o", str(tmp_path / "cli"), "--tile-size", "1000", "--depth", "4",
                    "--threads", "1", "--where", "Classification == 2", "-q"], check=True)
    assert files(tmp_path / "py") == files(tmp_path / "cli")
    with pytest.raises(vola.InvalidArgument, match="neighbours"):
        vola.tile([autzen], tmp_path / "smrf", tile_size=1000.0, depth=4, filters=["smrf"])
