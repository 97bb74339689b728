"""Occupancy maps from Python: vola.export_map (OctoMap .bt/.ot, OpenVDB .vdb) and
vola.convert reading them back, through the same C++ functions as `vola export` and
`vola convert`; the CLI writes the same files."""

import subprocess

import numpy as np
import pytest

import vola


def _map(seed: int, size: float, count: int, log_odds_range):
    rng = np.random.default_rng(seed)
    cells = np.unique(rng.integers(-300, 300, size=(count, 3)), axis=0)
    points = (cells + 0.5) * size
    values = rng.uniform(*log_odds_range, size=len(cells)).astype(np.float32)
    origin = cells.min(axis=0) * size  # a multiple of the voxel size, as `vola map` writes
    tree = vola.build(points, voxel_size=size, origin=tuple(origin), attributes={"log_odds": values},
                      reductions={"log_odds": "last"})
    return tree, cells, values


def _world_cells(tree: vola.Tree, size: float) -> set:
    return {tuple(c) for c in np.floor(tree.centers() / size).astype(np.int64)}


def test_export_map_and_convert_back(tmp_path):
    size = 0.25
    tree, cells, values = _map(1, size, 3000, (0.0, 3.4))
    expected = {tuple(c) for c in cells}
    for name in ("m.bt", "m.ot", "m.vdb"):
        report = vola.export_map(tree, tmp_path / name)
        assert report["occupied"] == len(cells) and report["warnings"] == []
        back = vola.convert(tmp_path / name)
        assert _world_cells(back, size) == expected, name
        if name != "m.bt":  # a .bt holds occupancy only
            by_cell = dict(zip(map(tuple, np.floor(back.centers() / size).astype(np.int64)), back.attribute("log_odds")))
            assert all(by_cell[tuple(c)] == v for c, v in zip(cells, values)), name
    assert vola.export_map(tree, tmp_path / "v.vdb")["grids"] == ["log_odds"]
    with pytest.raises(vola.InvalidArgument, match="voxel_size: is 0.5, but .* is a map of 0.25 cells"):
        vola.convert(tmp_path / "m.bt", voxel_size=0.5)
    with pytest.raises(vola.FormatError, match="its grids: 'log_odds'"):
        vola.convert(tmp_path / "m.vdb", grid="density")


def test_free_voxels_and_the_cli_agree(tmp_path, vola_cli):
    size = 0.5
    occupied, _, _ = _map(2, size, 500, (0.1, 3.4))
    free, free_cells, _ = _map(3, size, 500, (-1.9, -0.1))
    # The free tree must not share cells with the occupied one.
    occupied_cells = _world_cells(occupied, size)
    keep = np.array([tuple(c) not in occupied_cells for c in free_cells])
    free = vola.build((free_cells[keep] + 0.5) * size, voxel_size=size,
                      origin=tuple(free_cells[keep].min(axis=0) * size))
    report = vola.export_map(occupied, tmp_path / "py.vdb", free=free)
    assert report["grids"] == ["log_odds", "free"] and report["free"] == int(keep.sum())
    assert _world_cells(vola.convert(tmp_path / "py.vdb", grid="free"), size) == {tuple(c) for c in free_cells[keep]}
    # The CLI writes the same .bt bytes from the same trees.
    occupied.write(tmp_path / "occupied.vol")
    free.write(tmp_path / "free.vol")
    vola.export_map(occupied, tmp_path / "py.bt", free=free)
    subprocess.run([vola_cli, "export", str(tmp_path / "occupied.vol"), str(tmp_path / "cli.bt"), "--free",
                    str(tmp_path / "free.vol"), "-q"], check=True)
    assert (tmp_path / "py.bt").read_bytes() == (tmp_path / "cli.bt").read_bytes()


def test_a_state_map_exports_its_occupied_and_free_voxels(tmp_path):
    m = vola.Map(0.25)
    rng = np.random.default_rng(4)
    m.insert(rng.uniform(-3, 3, size=(300, 3)), origin=(0.05, 0.1, 0.15))
    m.save(tmp_path / "map.vol")
    state = vola.read(tmp_path / "map.vol")  # the file as it is: every known voxel
    occupied, free = vola.occupied_tree(state), vola.free_tree(state)
    assert occupied.voxel_count > 0 and free.voxel_count > 0
    report = vola.export_map(state, tmp_path / "s.ot")
    assert (report["occupied"], report["free"]) == (occupied.voxel_count, free.voxel_count)  # was (all known, 0)
    with pytest.raises(vola.InvalidArgument, match="holds its free voxels"):
        vola.export_map(state, tmp_path / "t.ot", free=free)


def test_a_ros_map_from_python_is_the_cli_s(tmp_path, vola_cli):
    m = vola.Map(0.25)
    rng = np.random.default_rng(5)
    m.insert(rng.uniform(-3, 3, size=(400, 3)), origin=(0.05, 0.1, 0.15))
    m.save(tmp_path / "map.vol")
    state = vola.read(tmp_path / "map.vol")
    report = vola.export(state, tmp_path / "py.yaml", band=(-0.5, 0.5))
    assert report["free_from_ground"] is False and report["occupied"] > 0 and report["free"] > 0
    assert report["occupied"] + report["free"] + report["unknown"] == report["width"] * report["height"]
    subprocess.run([vola_cli, "export", str(tmp_path / "map.vol"), str(tmp_path / "cli.yaml"), "--band", "-0.5:0.5", "-q"],
                   check=True)
    assert (tmp_path / "py.pgm").read_bytes() == (tmp_path / "cli.pgm").read_bytes()
    assert (tmp_path / "py.yaml").read_text() == (tmp_path / "cli.yaml").read_text().replace("cli.pgm", "py.pgm")
    with pytest.raises(vola.InvalidArgument, match="band: a ROS map needs the height band"):
        vola.export(state, tmp_path / "x.yaml")
    with pytest.raises(vola.InvalidArgument, match="band: band applies to a ROS map"):
        vola.export(state, tmp_path / "x.ply", band=(0, 1))


def test_a_ros_map_reads_back_as_columns(tmp_path):
    m = vola.Map(0.25)
    rng = np.random.default_rng(6)
    m.insert(rng.uniform(-3, 3, size=(400, 3)), origin=(0.05, 0.1, 0.15))
    m.save(tmp_path / "map.vol")
    report = vola.export(vola.read(tmp_path / "map.vol"), tmp_path / "m.yaml", band=(-0.5, 0.5))
    one = vola.convert(tmp_path / "m.yaml")
    three = vola.convert(tmp_path / "m.yaml", map_height=0.6)  # 0.6 / 0.25: three voxels a column
    assert one.voxel_count == report["occupied"]
    assert three.voxel_count == 3 * report["occupied"]
    (tmp_path / "p.xyz").write_text("0 0 0\n1 1 1\n")
    with pytest.raises(vola.InvalidArgument, match="map_height: applies to ROS map input only"):
        vola.convert(tmp_path / "p.xyz", voxel_size=1.0, map_height=1.0)
