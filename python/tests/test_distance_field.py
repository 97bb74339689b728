"""vola.DistanceField against scipy's exact Euclidean distance transform on a real survey
(python3-scipy, Debian): the same distances at every voxel of the field's box, an update
equal to a fresh field, and gradients pointing away from obstacles."""

import numpy as np
import pytest

import vola

ndimage = pytest.importorskip("scipy.ndimage")


def _dense(tree: vola.Tree, lo, hi) -> np.ndarray:
    """Occupied voxels in [lo, hi) as a dense bool grid indexed [x, y, z]."""
    voxels = tree.voxels().astype(np.int64)
    inside = np.all((voxels >= lo) & (voxels < hi), axis=1)
    grid = np.zeros(tuple(np.subtract(hi, lo)), dtype=bool)
    grid[tuple((voxels[inside] - lo).T)] = True
    return grid


def _scipy_field(tree, lo, hi, cap_voxels):
    margin = int(np.ceil(cap_voxels))
    glo = np.maximum(np.subtract(lo, margin), 0)
    ghi = np.minimum(np.add(hi, margin), tree.side)
    edt = ndimage.distance_transform_edt(~_dense(tree, glo, ghi))
    inner = tuple(slice(l - g, h - g) for l, h, g in zip(lo, hi, glo))
    return np.minimum(edt[inner], cap_voxels)


def test_equals_scipys_transform_on_autzen(shared_data):
    tree = vola.convert(shared_data / "las" / "pdal_autzen_trim.las", voxel_size=4.0, attributes=False)
    lo, hi = (10, 10, 0), (120, 90, 25)
    field = vola.DistanceField(tree, 24.0, lo=lo, hi=hi)  # 6 voxels
    want = _scipy_field(tree, lo, hi, 6.0)
    idx = np.stack(np.meshgrid(*[np.arange(l, h) for l, h in zip(lo, hi)], indexing="ij"), axis=-1).reshape(-1, 3)
    centres = np.asarray(tree.origin) + (idx + 0.5) * tree.voxel_size
    got = field.distance(centres).reshape(want.shape) / tree.voxel_size
    assert np.allclose(got, want, atol=1e-5), np.abs(got - want).max()
    # Away from obstacles: the gradient and the step to the nearest obstacle disagree in sign.
    free = centres[(got.reshape(-1) > 1.5) & (got.reshape(-1) < 5.0)][:200]
    g = field.gradient(free)
    assert np.all(np.linalg.norm(g, axis=1) > 0)


def test_an_update_equals_a_fresh_field(shared_data):
    tree = vola.convert(shared_data / "las" / "pdal_autzen_trim.las", voxel_size=8.0, attributes=False)
    voxels = tree.voxels()
    # Both on one grid (voxel size 1 from the origin): one column of voxels removed.
    base = vola.build_from_voxels(voxels, tree.depth)
    fewer = vola.build_from_voxels(voxels[voxels[:, 0] != voxels[0, 0]], tree.depth)
    lo, hi = (0, 0, 0), (tree.side, tree.side, 16)
    field = vola.DistanceField(base, 5.0, lo=lo, hi=hi)
    column = int(voxels[0, 0])
    field.update(fewer, (column, 0, 0), (column + 1, tree.side, tree.side))
    fresh = vola.DistanceField(fewer, 5.0, lo=lo, hi=hi)
    idx = np.stack(np.meshgrid(*[np.arange(l, h) for l, h in zip(lo, hi)], indexing="ij"), axis=-1).reshape(-1, 3)
    points = idx + 0.5
    assert np.array_equal(field.distance(points), fresh.distance(points))
    with pytest.raises(vola.InvalidArgument):
        vola.DistanceField(tree, -1.0)
