"""Tree.dilate / erode / fill / crop / downsample against scipy.ndimage and numpy on dense
grids, and against the files `vola dilate | erode | fill | crop | downsample` write."""
import subprocess

import numpy as np
import pytest

import vola
from reference import dense


def ball(radius, element):
    r = np.arange(-radius, radius + 1)
    dx, dy, dz = np.meshgrid(r, r, r, indexing="ij")
    if element == "cube":
        return np.ones(dx.shape, dtype=bool)
    return dx * dx + dy * dy + dz * dz <= radius * radius


def scene():
    rng = np.random.default_rng(11)
    voxels = rng.integers(4, 60, size=(400, 3))
    box = np.array([(x, y, z) for x in range(20, 36) for y in range(20, 36) for z in range(20, 36)
                    if min(x, y, z) in (20, 35) or max(x, y, z) in (20, 35)])  # a hollow cube: one cavity
    voxels = np.concatenate([voxels, box, [(0, 0, 0), (63, 63, 63)]])  # and voxels on the grid's edge
    return vola.build_from_voxels(voxels, depth=3), dense(voxels, 64)


@pytest.mark.parametrize("element", ["sphere", "cube"])
def test_dilate_and_erode_match_scipy(element):
    ndimage = pytest.importorskip("scipy.ndimage")
    tree, grid = scene()
    for radius in (1, 2):
        structure = ball(radius, element)
        np.testing.assert_array_equal(tree.dilate(radius, element, keep_grid=True).to_dense(),
                                      ndimage.binary_dilation(grid, structure=structure))
        # Unclipped: the grid grows by the radius where the voxels reach its faces, and the
        # result is scipy's dilation of the grid padded by the radius, at the same world place.
        grown = tree.dilate(radius, element)
        padded = ndimage.binary_dilation(np.pad(grid, radius), structure=structure)
        assert grown.depth == 4 and np.allclose(grown.origin, np.array(tree.origin) - radius * tree.voxel_size)
        np.testing.assert_array_equal(grown.to_dense()[:padded.shape[0], :padded.shape[1], :padded.shape[2]], padded)
        assert grown.to_dense().sum() == padded.sum()
        solid = tree.dilate(3, element, keep_grid=True)
        np.testing.assert_array_equal(solid.erode(radius, element).to_dense(),
                                      ndimage.binary_erosion(solid.to_dense(), structure=structure, border_value=0))
    with pytest.raises(vola.InvalidArgument):
        tree.dilate(-1)
    with pytest.raises(vola.InvalidArgument, match="'sphere' or 'cube'"):
        tree.dilate(1, "diamond")


def test_fill_matches_scipy():
    ndimage = pytest.importorskip("scipy.ndimage")
    tree, grid = scene()
    filled, count = tree.fill()
    expected = ndimage.binary_fill_holes(grid)
    np.testing.assert_array_equal(filled.to_dense(), expected)
    assert count == expected.sum() - grid.sum() > 2000
    assert filled.to_dense()[21:35, 21:35, 21:35].all()  # the hollow cube's inside


def test_crop_and_downsample_match_numpy():
    tree, grid = scene()
    part = tree.crop((10, 20, 0), (40, 63, 30))
    expected = np.zeros_like(grid)
    expected[10:41, 20:64, 0:31] = grid[10:41, 20:64, 0:31]
    np.testing.assert_array_equal(part.to_dense(), expected)
    with pytest.raises(vola.InvalidArgument, match="not a voxel index"):
        tree.crop((-1, 0, 0), (5, 5, 5))
    counts = grid.reshape(16, 4, 16, 4, 16, 4).sum(axis=(1, 3, 5))
    for min_voxels in (1, 5):
        coarse = tree.downsample(2, min_voxels)
        np.testing.assert_array_equal(coarse.to_dense(), counts >= min_voxels)
        assert coarse.voxel_size == tree.voxel_size * 4
    with pytest.raises(vola.InvalidArgument):
        tree.downsample(4)


def test_same_files_as_the_cli(autzen_trim, vola_cli, tmp_path):
    tree = vola.convert(autzen_trim, voxel_size=6.0)
    thick = tree.dilate(2)
    lo = tree.voxels().min(axis=0)
    hi = lo + 40
    runs = (
        (tree, ["dilate", "--radius", "2"], thick),
        (tree, ["dilate", "--radius", "1", "--element", "cube"], tree.dilate(1, "cube")),
        (thick, ["erode", "--radius", "1"], thick.erode(1)),
        (thick, ["fill"], thick.fill()[0]),
        (tree, ["crop", "--min", ",".join(map(str, lo)), "--max", ",".join(map(str, hi))], tree.crop(tuple(lo), tuple(hi))),
        (tree, ["downsample", "--depth", str(tree.depth - 1), "--min-voxels", "3"], tree.downsample(tree.depth - 1, 3)),
    )
    for source, arguments, ours in runs:
        source.write(tmp_path / "in.vol")
        out = tmp_path / "out.vol"
        subprocess.run([vola_cli, arguments[0], str(tmp_path / "in.vol"), str(out), *arguments[1:], "-q"], check=True)
        assert ours.to_bytes() == out.read_bytes(), arguments
        assert len(ours) > 0 and ours.crs_wkt == tree.crs_wkt
