"""Building from points and voxels, queries and arrays, against numpy references."""

import warnings

import numpy as np
import pytest

import vola
from reference import coarsen, dense, grid_voxels, sorted_unique_voxels


@pytest.fixture()
def cloud():
    rng = np.random.default_rng(7)
    # Clustered points, so that voxels hold several points each and blocks are sparse.
    centres = rng.uniform(0, 30, size=(40, 3))
    return centres[rng.integers(0, 40, 5000)] + rng.normal(0, 0.8, size=(5000, 3))


def test_build_grid_matches_floor_reference(cloud):
    origin = (-5.0, -5.0, -5.0)
    tree = vola.build(cloud, voxel_size=0.5, origin=origin)
    expected = sorted_unique_voxels(grid_voxels(cloud, origin, 0.5), tree.depth)
    assert tree.quantization == "grid" and tree.voxel_size == 0.5 and tuple(tree.origin) == origin
    assert tree.side >= expected.max() + 1 and tree.side // 4 < expected.max() + 1  # smallest depth that fits
    np.testing.assert_array_equal(tree.voxels().astype(np.int64), expected)
    assert len(tree) == tree.voxel_count == len(expected)


def test_default_origin_snaps_below_the_points(cloud):
    tree = vola.build(cloud, voxel_size=0.25)
    origin = np.asarray(tree.origin)
    assert np.all(origin <= cloud.min(axis=0))
    np.testing.assert_allclose(origin / 0.25, np.round(origin / 0.25))
    expected = sorted_unique_voxels(grid_voxels(cloud, origin, 0.25), tree.depth)
    np.testing.assert_array_equal(tree.voxels().astype(np.int64), expected)


def test_toolkit_needs_depth_and_fits_the_bbox(cloud):
    tree = vola.build(cloud, depth=4, quantize="toolkit")
    assert tree.quantization == "toolkit" and tree.depth == 4
    v = tree.voxels()
    assert v.max() == 255 and v.min() == 0  # the longest bbox side spans the whole grid
    with pytest.raises(vola.InvalidArgument, match="depth"):
        vola.build(cloud, quantize="toolkit")


def test_contains_and_rank_against_dense_reference(cloud):
    tree = vola.build(cloud, voxel_size=1.0, origin=(-5.0, -5.0, -5.0))
    grid = dense(tree.voxels(), tree.side)
    rng = np.random.default_rng(1)
    queries = rng.integers(-3, tree.side + 3, size=(20000, 3))
    queries = np.vstack([queries, tree.voxels().astype(np.int64), [[2**40, 0, 0], [-(2**40), 1, 1]]])
    inside = np.all((queries >= 0) & (queries < tree.side), axis=1)
    expected = np.zeros(len(queries), dtype=bool)
    q = queries[inside]
    expected[inside] = grid[q[:, 0], q[:, 1], q[:, 2]]
    np.testing.assert_array_equal(tree.contains(queries), expected)
    # Other integer dtypes and a single row.
    np.testing.assert_array_equal(tree.contains(queries[inside].astype(np.uint16)), expected[inside])
    v0 = tree.voxels()[0]
    assert tree.contains(v0) is True and tree.contains([tree.side, 0, 0]) is False
    # rank: the row in voxels(), -1 when empty.
    ranks = tree.rank(queries)
    np.testing.assert_array_equal(ranks >= 0, expected)
    voxels = tree.voxels()
    np.testing.assert_array_equal(voxels[ranks[expected]].astype(np.int64), queries[expected])
    assert tree.rank(voxels[17]) == 17


def test_contains_refuses_coordinates_that_are_not_voxel_indices():
    tree = vola.build_from_voxels(np.array([[0, 281, 0], [63, 17, 10]]), depth=5)
    # Whole floats are indices; anything else was truncated (-0.5 -> voxel 0, 62.9 -> 62).
    assert tree.contains(np.array([[0.0, 281.0, 0.0], [63.0, 17.0, 10.0]])).tolist() == [True, True]
    for bad in ([[-0.5, 281, 0]], [[62.9, 16.9, 9.9]], [[np.nan, 0, 0]]):
        with pytest.raises(ValueError, match="expects voxel indices .*world_to_voxel"):
            tree.contains(np.array(bad))
    with pytest.raises(ValueError, match="expects voxel indices"):
        tree.rank(np.array([[0.5, 0.0, 0.0]]))
    with pytest.raises(vola.InvalidArgument, match="no world placement"):
        tree.world_to_voxel(np.array([[0.5, 281.5, 0.5]]))
    with pytest.raises(vola.InvalidArgument, match="no world placement"):
        tree.centers()
    placed = vola.build(np.array([[0.5, 281.5, 0.5], [63.5, 17.5, 10.5]]), voxel_size=1.0, origin=(0.0, 0.0, 0.0))
    voxels, inside = placed.world_to_voxel(np.array([[0.7, 281.2, 0.1]]))
    assert inside.all() and placed.contains(voxels).all()


def test_build_from_voxels_and_dense_round_trip():
    rng = np.random.default_rng(3)
    voxels = rng.integers(0, 64, size=(3000, 3))
    tree = vola.build_from_voxels(voxels, depth=3)
    np.testing.assert_array_equal(tree.voxels().astype(np.int64), sorted_unique_voxels(voxels, 3))
    grid = dense(voxels, 64)
    np.testing.assert_array_equal(tree.to_dense(), grid)
    back = vola.from_dense(grid)
    assert back.depth == 3
    np.testing.assert_array_equal(back.voxels(), tree.voxels())
    # A non-cubic int grid with a world frame: non-zero cells are voxels.
    small = np.zeros((5, 9, 3), dtype=np.int32)
    small[4, 8, 2] = 7
    small[0, 1, 0] = -1
    framed = vola.from_dense(small, origin=(10.0, 20.0, 30.0), voxel_size=2.0)
    assert framed.depth == 2 and framed.quantization == "grid" and framed.voxel_size == 2.0
    np.testing.assert_array_equal(framed.voxels(), [[0, 1, 0], [4, 8, 2]])
    np.testing.assert_allclose(framed.centers(), [[11.0, 23.0, 31.0], [19.0, 37.0, 35.0]])
    voxels_back, inside = framed.world_to_voxel(np.array([[19.5, 37.0, 35.9], [9.0, 20.0, 30.0]]))
    np.testing.assert_array_equal(voxels_back, [[4, 8, 2], [-1, -1, -1]])
    np.testing.assert_array_equal(inside, [True, False])
    # A frame vola's reader refuses is refused when it is made (the file was written, then
    # refused by vola.open: "frame origin is not finite").
    with pytest.raises(vola.InvalidArgument, match="origin: must be finite"):
        vola.from_dense(small, origin=(float("nan"), 0.0, 0.0))
    with pytest.raises(vola.InvalidArgument, match="voxel_size"):
        vola.from_dense(small, voxel_size=float("inf"))
    with pytest.raises(vola.InvalidArgument, match="max_cells"):
        vola.build_from_voxels([[0, 0, 0]], depth=8).to_dense()


def test_level_of_detail_is_any_over_4x4x4():
    rng = np.random.default_rng(5)
    voxels = rng.integers(0, 256, size=(5000, 3))
    tree = vola.build_from_voxels(voxels, depth=4)
    grid = dense(voxels, 256)
    for depth in (3, 2, 1):
        grid = coarsen(grid)
        coarse = tree.level_of_detail(depth)
        assert coarse.depth == depth
        np.testing.assert_array_equal(coarse.to_dense(), grid)
        np.testing.assert_array_equal(tree.voxels(level=depth - 1), coarse.voxels())
        np.testing.assert_array_equal(tree.to_dense(level=depth - 1), grid)
    with pytest.raises(vola.InvalidArgument):
        tree.level_of_detail(5)


def test_reductions_default_by_name_as_the_readers_do():
    # Three points in one voxel: classes and ids take the majority (the mean of classes 2,
    # 6 and 6 would be class 5, of trees 3, 5 and 5 a tree 4.33), number_of_returns the
    # maximum, a measurement the mean; a reduction given by name still wins.
    points = np.array([[0.1, 0.1, 0.1], [0.2, 0.2, 0.2], [0.3, 0.3, 0.3]])
    columns = {
        "classification": np.array([2, 6, 6], np.uint8),
        "treeID": np.array([3.0, 5.0, 5.0]),
        "NumberOfReturns": np.array([1, 3, 2], np.uint8),
        "geoid": np.array([1.0, 2.0, 6.0]),
    }
    tree = vola.build(points, voxel_size=1.0, attributes=columns)
    assert tree.attribute("classification")[0] == 6
    assert tree.attribute("treeID")[0] == 5.0
    assert tree.attribute("NumberOfReturns")[0] == 3
    assert tree.attribute("geoid")[0] == 3.0
    averaged = vola.build(points, voxel_size=1.0, attributes=columns, reductions={"classification": "mean"})
    assert averaged.attribute("classification")[0] == 5


def test_attributes_reduce_per_voxel_like_numpy(cloud):
    n = len(cloud)
    rng = np.random.default_rng(11)
    intensity = rng.integers(0, 60000, n).astype(np.uint16)
    height = cloud[:, 2].astype(np.float64)
    classification = rng.integers(1, 4, n).astype(np.uint8)
    tree = vola.build(
        cloud,
        voxel_size=2.0,
        origin=(-5.0, -5.0, -5.0),
        attributes={"intensity": intensity, "height": height, "classification": classification},
        reductions={"height": "max", "classification": "majority"},
    )
    assert sorted(tree.attribute_names) == ["classification", "height", "intensity"]
    columns = tree.attributes()
    assert columns["intensity"].dtype == np.uint16 and columns["height"].dtype == np.float64
    assert columns["classification"].dtype == np.uint8
    # Reference: group the points by the voxel they fall in, in rank order.
    rows = tree.rank(grid_voxels(cloud, (-5.0, -5.0, -5.0), 2.0))
    assert np.all(rows >= 0)
    count = np.bincount(rows, minlength=len(tree))
    mean = np.bincount(rows, weights=intensity, minlength=len(tree)) / count
    np.testing.assert_array_equal(columns["intensity"], np.clip(np.rint(mean), 0, 65535).astype(np.uint16))
    highest = np.full(len(tree), -np.inf)
    np.maximum.at(highest, rows, height)
    np.testing.assert_array_equal(columns["height"], highest)
    votes = np.zeros((len(tree), 4), dtype=np.int64)
    np.add.at(votes, (rows, classification), 1)
    majority = columns["classification"]
    assert np.all(votes[np.arange(len(tree)), majority] == votes.max(axis=1))
    # Views, not copies: read-only, and alive after the tree object is gone.
    view = tree.attribute("height")
    assert not view.flags.writeable and not view.flags.owndata
    del tree, columns
    np.testing.assert_array_equal(view, highest)
    with pytest.raises(KeyError, match="colour"):
        vola.build(cloud, voxel_size=1.0).attribute("colour")


def test_trees_pickle_with_their_attributes_and_crs(tmp_path):
    import pickle

    rng = np.random.default_rng(5)
    points = rng.uniform(0, 10, size=(500, 3))
    wkt = 'LOCAL_CS["site grid",UNIT["metre",1]]'
    tree = vola.build(points, voxel_size=1.0, attributes={"v": np.arange(500.0)}, crs_wkt=wkt)
    assert tree.crs_wkt == wkt  # a WKT given to build is kept, not dropped
    tree.write(str(tmp_path / "t.vol"))
    for t in (tree, vola.open_mapped(str(tmp_path / "t.vol"))):  # in memory, and mapped
        back = pickle.loads(pickle.dumps(t))
        assert np.array_equal(back.voxels(), tree.voxels())
        assert np.array_equal(back.attribute("v"), tree.attribute("v"))
        assert back.crs_wkt == wkt and back.voxel_size == tree.voxel_size


def test_levels_out_of_range_are_refused():
    """node_count read past the level counts (garbage, or a segfault for a large level)."""
    tree = vola.build_from_voxels(np.array([[0, 281, 0], [63, 17, 10]]), depth=5)
    assert [tree.node_count(level) for level in range(5)] == [2, 2, 2, 2, 2]  # cells, two apart at every level
    for bad in (5, 1000000, -1, -7):
        with pytest.raises(vola.InvalidArgument, match="outside 0..4"):
            tree.node_count(bad)
    assert tree.voxels(-1).tolist() == tree.voxels().tolist()  # -1: the voxels, as documented
    with pytest.raises(vola.InvalidArgument, match="outside 0..4"):
        tree.voxels(-2)
    with pytest.raises(vola.InvalidArgument, match="outside 0..4"):
        tree.occupancy(-1)


def test_build_records_the_crs_as_convert_does(las_file):
    """vola.build left epsg at 2000 for a WKT of a known code, lat_lon at (0, 0), accepted a
    code and a WKT of different CRSs; a union with a CRS on one side only lost it."""
    converted = vola.convert(str(las_file), voxel_size=10)
    centres = converted.centers()
    built = vola.build(centres, voxel_size=10, crs_wkt=converted.crs_wkt)
    assert built.epsg == converted.epsg == 26910
    assert built.lat_lon == pytest.approx(converted.lat_lon, abs=1e-3) and built.lat_lon[0] > 40
    with pytest.raises(vola.InvalidArgument, match="name different CRSs"):
        vola.build(centres, voxel_size=10, epsg=32610, crs_wkt=converted.crs_wkt)
    assert vola.build(centres, voxel_size=10, epsg=26910, crs_wkt=converted.crs_wkt).epsg == 26910
    bare = vola.build(centres, voxel_size=10, origin=converted.origin)
    placed = vola.build(centres, voxel_size=10, origin=converted.origin, crs_wkt=converted.crs_wkt)
    assert (bare | placed).crs_wkt == placed.crs_wkt and (placed | bare).crs_wkt == placed.crs_wkt


def test_a_bad_argument_is_a_value_error():
    """vola.InvalidArgument derives from ValueError too: `except ValueError` missed a bad voxel size."""
    assert issubclass(vola.InvalidArgument, ValueError) and issubclass(vola.InvalidArgument, vola.Error)
    with pytest.raises(ValueError, match="voxel_size"):
        vola.build(np.zeros((3, 3)), voxel_size=-1)
    # A reduction that is not a name was "RuntimeError: Unable to cast Python instance".
    with pytest.raises(TypeError, match=r"reductions\['i'\]: a reduction's name .*, not 3"):
        vola.build(np.zeros((3, 3)), voxel_size=1, attributes={"i": np.arange(3)}, reductions={"i": 3})


def test_a_crs_proj_does_not_know_is_refused_before_building():
    """vola.build wrote epsg=999999 and crs_wkt='garbage' into the tree; vola convert refuses both."""
    points = np.zeros((3, 3))
    with pytest.raises(vola.InvalidArgument, match="epsg=999999 is not a CRS PROJ knows"):
        vola.build(points, voxel_size=1, epsg=999999)
    with pytest.raises(vola.InvalidArgument, match="crs_wkt='garbage' is not a CRS PROJ knows"):
        vola.build(points, voxel_size=1, crs_wkt="garbage")
    assert vola.build(points, voxel_size=1, epsg=32610).epsg == 32610


def test_points_that_are_not_finite_are_left_out_with_a_warning():
    """A NaN point was dropped without a word (93 voxels for 94 points' worth, no count)."""
    points = np.arange(30, dtype=float).reshape(10, 3)
    points[3] = np.nan
    points[5, 2] = np.inf
    with pytest.warns(UserWarning, match="2 of the 10 points have a coordinate that is not finite"):
        tree = vola.build(points, voxel_size=1)
    assert tree.voxel_count == 8
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # finite points: no warning at all
        vola.build(points[[0, 1, 2]], voxel_size=1)


def test_64_bit_integers_a_double_cannot_hold_are_said():
    """Columns hold doubles: 2**53 + 1 came back as 2**53 without a word."""
    points = np.array([[0.0, 0.0, 0.0], [5.0, 5.0, 5.0]])
    ids = np.array([2**53 + 1, 7], dtype=np.int64)
    with pytest.warns(UserWarning, match="'id': 1 values are larger than 2\\^53"):
        tree = vola.build(points, voxel_size=1, attributes={"id": ids}, reductions={"id": "last"})
    assert tree.attribute("id")[0] == 2**53  # rounded, as the warning says
    with pytest.warns(UserWarning, match="'id': 1 values"):
        vola.build(points, voxel_size=1, attributes={"id": np.array([-(2**53) - 1, 0], dtype=np.int64)})
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # within 2^53 (and narrower types): nothing to say
        vola.build(points, voxel_size=1, attributes={"id": np.array([2**53, -(2**53)], dtype=np.int64)})
        vola.build(points, voxel_size=1, attributes={"id": np.array([2**53, 1], dtype=np.uint64)})


def test_one_point_placed_by_the_toolkit_holds_only_its_own_coordinates():
    """A toolkit tree of one point (or coincident ones) has a bbox of no extent: every
    world point, however far, was 'inside' voxel 0."""
    tree = vola.build(np.array([[10.0, 20.0, 30.0]] * 3), depth=3, quantize="toolkit")
    voxels, inside = tree.world_to_voxel(np.array([[10.0, 20.0, 30.0], [1000.0, -5.0, 3.0], [10.0, 20.0, 31.0]]))
    assert inside.tolist() == [True, False, False]
    assert voxels.tolist() == [[0, 0, 0], [-1, -1, -1], [-1, -1, -1]]
    assert tree.contains(voxels[inside]).all()


def test_no_room_for_a_converted_copy_is_a_memory_error(tmp_path):
    """pybind11's array ensure() swallowed numpy's MemoryError: from_dense and contains on
    a float array crashed, build said the array had the wrong shape."""
    import subprocess
    import sys
    script = tmp_path / "oom.py"
    script.write_text(
        "import resource, numpy as np, vola\n"
        "resource.setrlimit(resource.RLIMIT_AS, (3 << 30, 3 << 30))\n"
        "calls = {\n"
        "  'from_dense': lambda: vola.from_dense(np.broadcast_to(np.ones(1, bool), (1500, 1500, 1500))),\n"
        "  'contains': lambda: vola.build(np.zeros((1, 3)), voxel_size=1).contains(\n"
        "      np.broadcast_to(np.zeros(3, np.float32), (150_000_000, 3))),\n"
        "  'build': lambda: vola.build(np.broadcast_to(np.zeros(3), (150_000_000, 3)), voxel_size=1),\n"
        "}\n"
        "for name, call in calls.items():\n"
        "    try:\n"
        "        call()\n"
        "        print(name, 'returned')\n"
        "    except MemoryError:\n"
        "        print(name, 'MemoryError')\n"
        "    except Exception as e:\n"
        "        print(name, type(e).__name__, e)\n")
    run = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr
    assert run.stdout.split("\n")[:3] == ["from_dense MemoryError", "contains MemoryError", "build MemoryError"], run.stdout


def test_a_file_that_cannot_be_opened_is_an_os_error(tmp_path):
    """vola.IoError is an OSError too, with the system's reason, whatever reads the file."""
    assert issubclass(vola.IoError, OSError) and issubclass(vola.IoError, vola.Error)
    missing = str(tmp_path / "missing.las")
    for call in (lambda: vola.open(missing), lambda: vola.convert(missing, voxel_size=1)):
        with pytest.raises(OSError, match="missing.las: cannot open: No such file or directory"):
            call()
