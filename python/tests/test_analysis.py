"""Components, census, rays and paths through the module, against independent references."""

import numpy as np
import pytest

import vola
from reference import dense


def scene():
    """Two separate slabs and a diagonal chain of voxels touching only at corners."""
    voxels = [(x, y, z) for x in range(4, 12) for y in range(4, 12) for z in (2, 3)]
    voxels += [(x, y, 20) for x in range(30, 40) for y in range(30, 33)]
    voxels += [(50 + i, 50 + i, 50 + i) for i in range(5)]
    return vola.build_from_voxels(np.array(voxels), depth=3), np.array(voxels)


def test_components_match_scipy_partition():
    ndimage = pytest.importorskip("scipy.ndimage")
    tree, _ = scene()
    grid = tree.to_dense()
    voxels = tree.voxels()
    for connectivity, rank in ((6, 1), (18, 2), (26, 3)):
        result = tree.components(connectivity)
        labels, count = ndimage.label(grid, structure=ndimage.generate_binary_structure(3, rank))
        assert len(result["sizes"]) == count
        reference = labels[voxels[:, 0], voxels[:, 1], voxels[:, 2]]
        # Same partition: each of our labels maps to exactly one scipy label and back.
        pairs = set(zip(result["labels"].tolist(), reference.tolist()))
        assert len(pairs) == count
        np.testing.assert_array_equal(np.sort(result["sizes"]), np.sort(np.bincount(reference)[1:]))
        assert list(result["sizes"]) == sorted(result["sizes"], reverse=True)
    assert len(tree.components(6)["sizes"]) == 7 and len(tree.components(26)["sizes"]) == 3


def test_census_counts():
    rng = np.random.default_rng(4)
    points = rng.uniform(0, 20, size=(3000, 3))
    classification = rng.choice(np.array([2, 5, 6], dtype=np.uint8), 3000)
    tree = vola.build(points, voxel_size=2.0, origin=(0.0, 0.0, 0.0), attributes={"classification": classification},
                      reductions={"classification": "majority"})
    census = tree.census()
    assert census["voxels"] == len(tree) and census["depth"] == tree.depth
    assert [level["cells"] for level in census["levels"]] == [tree.node_count(i) for i in range(tree.depth)]
    assert census["voxel_size"] == 2.0 and census["volume"] == len(tree) * 8.0
    columns = {(int(x), int(y)) for x, y, _ in tree.voxels()}
    assert census["columns"] == len(columns)
    (classes,) = [a["classes"] for a in census["attributes"] if a["name"] == "classification"]
    codes, counts = np.unique(tree.attribute("classification"), return_counts=True)
    assert [(code, n) for code, _, n in classes] == list(zip(codes.tolist(), counts.tolist()))
    assert [name for _, name, _ in classes] == ["Ground", "High Vegetation", "Building"]
    assert census["heights"]["counts"].sum() == len(tree)


def test_raycast_along_axes_finds_the_first_voxel_in_the_row():
    rng = np.random.default_rng(8)
    voxels = rng.integers(0, 64, size=(2000, 3))
    tree = vola.build_from_voxels(voxels, depth=3)
    grid = dense(voxels, 64)
    ys, zs = np.meshgrid(np.arange(64), np.arange(64), indexing="ij")
    origins = np.stack([np.full(ys.size, -3.0), ys.ravel() + 0.5, zs.ravel() + 0.5], axis=1)
    result = tree.raycast(origins, np.tile([1.0, 0.0, 0.0], (ys.size, 1)))
    rows = grid[:, ys.ravel(), zs.ravel()].T  # (rays, x)
    any_hit = rows.any(axis=1)
    first = np.argmax(rows, axis=1)
    np.testing.assert_array_equal(result["hit"], any_hit)
    np.testing.assert_array_equal(result["voxel"][any_hit, 0], first[any_hit])
    np.testing.assert_array_equal(result["voxel"][any_hit, 1:], origins[any_hit, 1:].astype(np.int64))
    np.testing.assert_allclose(result["t"][any_hit], first[any_hit] + 3.0)
    np.testing.assert_array_equal(result["normal"][any_hit], np.tile([-1, 0, 0], (any_hit.sum(), 1)))
    assert np.all(result["voxel"][~any_hit] == -1) and np.all(np.isinf(result["t"][~any_hit]))
    # World coordinates: the same rays through a frame with origin and voxel size.
    framed = vola.from_dense(grid, origin=(100.0, 0.0, 0.0), voxel_size=0.5)
    world = framed.raycast(origins * 0.5 + [100.0, 0.0, 0.0], np.tile([2.0, 0.0, 0.0], (ys.size, 1)), world=True)
    np.testing.assert_array_equal(world["voxel"], result["voxel"])
    np.testing.assert_allclose(world["point"][any_hit, 0], 100.0 + first[any_hit] * 0.5)
    with pytest.raises(vola.InvalidArgument):
        tree.raycast([0.0, 0.0, 0.0], [[0.0, 0.0, 0.0]])


def test_plan_goes_around_a_wall():
    wall = np.array([(8, y, z) for y in range(0, 14) for z in range(16)])
    tree = vola.build_from_voxels(wall, depth=2)
    path = tree.plan((2.5, 2.5, 8.5), (13.5, 2.5, 8.5), radius=0.0)
    points = path["points"]
    np.testing.assert_allclose(points[0], (2.5, 2.5, 8.5))
    np.testing.assert_allclose(points[-1], (13.5, 2.5, 8.5))
    assert np.all(points[:, 1] >= 0)
    # Every path vertex is free and the path passes the wall's end at y >= 14.
    assert not np.any(tree.contains(np.floor(points).astype(np.int64)))
    assert points[:, 1].max() >= 14.0
    steps = np.linalg.norm(np.diff(points, axis=0), axis=1).sum()
    assert path["length"] == pytest.approx(steps) and path["cost"] >= 11.0
    with pytest.raises(vola.InvalidArgument):
        tree.plan((8.5, 2.5, 8.5), (13.5, 2.5, 8.5))


def test_plan_solid_ground_keeps_the_path_out_from_under_a_sheet():
    # A ground sheet at z = 4 over y < 12 and a wall across the grid from z = 4 to 13: the
    # short way past the wall is below z = 4, reached past the sheet's edge. With
    # solid_ground the wall's base and the sheet are ground, everything under them solid,
    # and the path goes over the wall instead.
    sheet = [(x, y, 4) for x in range(16) for y in range(12)]
    wall = [(8, y, z) for y in range(16) for z in range(4, 14)]
    tree = vola.build_from_voxels(np.array(sheet + wall), depth=2)
    def under(points):
        return np.sum((points[:, 2] < 4.0) & (points[:, 1] < 14.0))
    free = tree.plan((2.5, 8.5, 5.5), (13.5, 8.5, 5.5), smooth=False)
    solid = tree.plan((2.5, 8.5, 5.5), (13.5, 8.5, 5.5), smooth=False, solid_ground=True)
    assert under(free["points"]) > 0 and under(solid["points"]) == 0
    assert solid["cost"] > free["cost"]
    with pytest.raises(vola.InvalidArgument, match="or the ground"):
        tree.plan((2.5, 8.5, 1.5), (13.5, 8.5, 5.5), solid_ground=True)


def test_census_leaves_voxels_without_a_value_out():
    # NaN is a voxel without a value (a LAS no_data): numpy's figures over the others.
    tree = vola.build(np.array([[0.5, 0.5, 0.5], [1.5, 0.5, 0.5], [2.5, 0.5, 0.5], [3.5, 0.5, 0.5]]), voxel_size=1.0,
                      attributes={"deviation": np.array([1.0, np.nan, 3.0, 5.0])})
    column = tree.census(bins=4)["attributes"][0]
    assert (column["count"], column["without_value"], column["mean"]) == (3, 1, 3.0)
    assert list(column["histogram"]["counts"]) == list(np.histogram([1.0, 3.0, 5.0], bins=4)[0])
