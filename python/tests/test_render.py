"""Tree.render: the images `vola render` writes (same pixels, same depth order), and a
depth checked against the geometry of a camera looking straight down at a slab."""
import subprocess

import numpy as np
import pytest

import vola

Image = pytest.importorskip("PIL.Image")


def depth_png(depth):
    """What `vola render` writes as OUT_depth.png: 16-bit, brighter where nearer, misses 0."""
    finite = np.isfinite(depth)
    near, far = depth[finite].min(), depth[finite].max()
    span = far - near if far > near else 1.0
    out = np.zeros(depth.shape, dtype=np.uint16)
    out[finite] = (65535.0 - 60000.0 * (depth[finite] - near) / span).astype(np.uint16)
    return out


def test_same_images_as_the_cli(autzen_trim, vola_cli, tmp_path):
    tree = vola.convert(autzen_trim, voxel_size=4.0)
    tree.write(tmp_path / "in.vol")
    (x0, y0, z0), (x1, y1, z1) = tree.bbox
    eye = (x0, y0, z1 + 300.0)
    look_at = ((x0 + x1) / 2, (y0 + y1) / 2, (z0 + z1) / 2)
    views = (
        ([], {}),  # the CLI's default view
        (["--camera", *map(repr, eye + look_at), "--fov", "45"], {"eye": eye, "look_at": look_at, "fov": 45.0}),
        (["--camera", *map(repr, eye + look_at), "--orbit", "4"], {"eye": eye, "look_at": look_at, "orbit": (1, 4)}),
    )
    for arguments, keywords in views:
        out = tmp_path / "view.png"
        subprocess.run([vola_cli, "render", str(tmp_path / "in.vol"), "-o", str(out), "--size", "80x60", *arguments, "-q"],
                       check=True)
        if "orbit" in keywords:
            out = tmp_path / "view_0001.png"
        ours = tree.render(size=(80, 60), **keywords)
        assert ours["image"].shape == (60, 80, 3) and ours["depth"].shape == (60, 80)
        np.testing.assert_array_equal(ours["image"], np.asarray(Image.open(out)))
        cli_depth = np.asarray(Image.open(str(out).replace(".png", "_depth.png"))).astype(np.int64)
        # World depths are voxel depths times the voxel size: the same order, within rounding.
        assert np.abs(depth_png(ours["depth"]).astype(np.int64) - cli_depth).max() <= 1
        assert ours["hits"] == np.isfinite(ours["depth"]).sum() > 400
        assert np.all(ours["image"][~np.isfinite(ours["depth"])] == 0)


def test_depth_straight_down_onto_a_slab():
    slab = np.zeros((16, 16, 16), dtype=bool)
    slab[:, :, 10] = True
    tree = vola.from_dense(slab, origin=(100.0, 200.0, 50.0), voxel_size=0.5)
    top = 50.0 + 11 * 0.5
    eye = (104.0, 204.0, 70.0)
    result = tree.render(eye=eye, look_at=(104.0, 204.0, 0.0), up=(0.0, 1.0, 0.0), size=(33, 33), fov=30.0)
    assert result["depth"][16, 16] == pytest.approx(70.0 - top)
    grid = tree.render(eye=(8.0, 8.0, 40.0), look_at=(8.0, 8.0, 0.0), up=(0.0, 1.0, 0.0), size=(33, 33), fov=30.0,
                       world=False)
    assert grid["depth"][16, 16] == pytest.approx(40.0 - 11)
    with pytest.raises(vola.InvalidArgument, match="parallel"):
        tree.render(eye=eye, look_at=(104.0, 204.0, 0.0))
    with pytest.raises(vola.InvalidArgument, match="together"):
        tree.render(eye=eye)
    with pytest.raises(vola.InvalidArgument, match="1..16384"):
        tree.render(size=(0, 10))


def test_tile_set_images_as_the_cli(autzen_trim, vola_cli, tmp_path):
    summary = vola.tile([autzen_trim], tmp_path / "tiles", tile_size=500.0, depth=4, overviews=False)
    tiles = vola.open_tiles(summary["index"])
    out = tmp_path / "tiles.png"
    subprocess.run([vola_cli, "render", summary["index"], "-o", str(out), "--size", "64x48", "-q"], check=True)
    ours = tiles.render(size=(64, 48))
    np.testing.assert_array_equal(ours["image"], np.asarray(Image.open(out)))
    np.testing.assert_array_equal(depth_png(ours["depth"]), np.asarray(Image.open(tmp_path / "tiles_depth.png")))
    assert ours["hits"] > 300 and tiles.tiles_opened > 1
    # The same place seen through the tiles and through one tree of the whole survey on their grid.
    tree = vola.convert(autzen_trim, voxel_size=summary["voxel_size"], origin=(0.0, 0.0, 0.0), attributes=False)
    (x0, y0, z0), (x1, y1, z1) = tree.bbox
    view = {"eye": (x0 - 100.0, y0 - 80.0, z1 + 200.0), "look_at": ((x0 + x1) / 2, (y0 + y1) / 2, z0), "size": (40, 30)}
    np.testing.assert_allclose(tiles.render(**view)["depth"], tree.render(**view)["depth"], rtol=1e-9)
