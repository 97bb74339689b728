"""vola.export_*: the files `vola export` writes, byte for byte (GeoTIFFs: the same
grid, geotransform and CRS read back through GDAL); Tree.raster against the max / min z
per cell computed here from the voxels."""
import filecmp
import subprocess

import numpy as np
import pytest

import vola


@pytest.fixture(scope="module")
def autzen(autzen_trim):
    return vola.convert(autzen_trim, voxel_size=3.0)


def cli_export(vola_cli, tree, tmp_path, out, *arguments):
    tree.write(tmp_path / "in.vol")
    subprocess.run([vola_cli, "export", str(tmp_path / "in.vol"), str(out), *arguments, "-q"], check=True)


def test_point_and_grid_files_match_the_cli(autzen, vola_cli, tmp_path):
    coarse = autzen.level_of_detail(4)  # dense formats: 256**3 cells
    runs = (
        ("a.ply", [], autzen, lambda t, p: vola.export_ply(t, p)),
        ("b.ply", ["--ascii", "--cubes", "--depth", "4"], autzen,
         lambda t, p: vola.export_ply(t, p, ascii=True, cubes=True, depth=4)),
        ("c.xyz", [], autzen, vola.export_xyz),
        ("c.csv", [], autzen, vola.export_csv),
        ("d.las", [], autzen, vola.export_las),
        ("e.laz", [], autzen, vola.export_las),
        ("f.binvox", ["--depth", "4"], coarse, vola.export_binvox),
        ("g.npy", ["--depth", "4"], autzen, lambda t, p: vola.export_npy(t, p, depth=4)),
        ("h.png", ["--map", "--bits", "8"], autzen, lambda t, p: vola.export_height_map(t, p, bits=8)),
        ("i.png", ["--occupancy-above", "20"], autzen, lambda t, p: vola.export_occupancy_above(t, p, 20)),
    )
    for name, arguments, tree, export in runs:
        (tmp_path / "cli").mkdir(exist_ok=True)
        (tmp_path / "py").mkdir(exist_ok=True)
        cli_export(vola_cli, autzen, tmp_path, tmp_path / "cli" / name, *arguments)
        export(tree, tmp_path / "py" / name)
        assert (tmp_path / "py" / name).read_bytes() == (tmp_path / "cli" / name).read_bytes(), name
        if name.endswith(".png"):
            world = name.replace(".png", ".pgw")
            assert (tmp_path / "py" / world).read_bytes() == (tmp_path / "cli" / world).read_bytes()
    assert vola.export_ply(autzen, tmp_path / "x.ply") == {"vertices": len(autzen), "faces": 0}
    report = vola.export_las(autzen, tmp_path / "x.las")
    assert report["has_crs"] and report["point_format"] in (6, 7)
    grid = np.load(tmp_path / "py" / "g.npy")
    np.testing.assert_array_equal(grid.astype(bool), coarse.to_dense())
    # Refusals name the keyword, as the CLI names its flag.
    deep = vola.build_from_voxels(np.array([[0, 0, 0], [1, 2, 3]]), depth=6)
    deep.write(tmp_path / "deep.vol")
    with pytest.raises(vola.InvalidArgument, match=r"^depth: a dense grid of depth 6 .*coarser copy \(depth K\)"):
        vola.export_npy(deep, tmp_path / "big.npy")
    refused = subprocess.run([vola_cli, "export", str(tmp_path / "deep.vol"), str(tmp_path / "big.npy")], capture_output=True,
                             text=True)
    assert refused.returncode == 1 and "coarser copy (--depth K)" in refused.stderr
    with pytest.raises(vola.InvalidArgument, match="^depth: depth 7 is not one of the tree's depths 1..6"):
        vola.export_xyz(deep, tmp_path / "x.xyz", depth=7)


def test_slices_match_the_cli(autzen, vola_cli, tmp_path):
    coarse = autzen.level_of_detail(4)
    cli_export(vola_cli, coarse, tmp_path, tmp_path / "cli", "--slices")
    assert vola.export_slices(coarse, tmp_path / "py") == coarse.side
    names = sorted(p.name for p in (tmp_path / "cli").iterdir())
    assert names == sorted(p.name for p in (tmp_path / "py").iterdir()) and len(names) == 2 * coarse.side
    match, mismatch, errors = filecmp.cmpfiles(tmp_path / "cli", tmp_path / "py", names, shallow=False)
    assert not mismatch and not errors


def reference_raster(tree, resolution, values, reduce):
    """Per cell of `resolution` (aligned with the grid origin), reduce(values) over the voxels
    whose column centre is in the cell; the grid cropped to the cells with a voxel."""
    centres = tree.centers()
    ox, oy, _ = tree.origin
    c = np.floor((centres[:, 0] - ox) / resolution).astype(np.int64)
    r = np.floor((centres[:, 1] - oy) / resolution).astype(np.int64)
    c -= c.min()
    r = r.max() - r  # row 0 the northernmost
    grid = np.full((r.max() + 1, c.max() + 1), vola.RASTER_NODATA, dtype=np.float64)
    for row, column, value in zip(r, c, values):
        grid[row, column] = value if grid[row, column] == vola.RASTER_NODATA else reduce(grid[row, column], value)
    return grid


def test_raster_is_the_max_or_min_z_per_cell(autzen):
    rng = np.random.default_rng(7)
    points = rng.uniform([500.0, 1000.0, 10.0], [560.0, 1040.0, 30.0], size=(5000, 3))
    plain = vola.build(points, voxel_size=0.5)  # no height column: the top face of the highest voxel
    values, gt = plain.raster("dsm", resolution=1.5)
    top = plain.origin[2] + (plain.voxels()[:, 2] + 1.0) * 0.5
    np.testing.assert_allclose(values, reference_raster(plain, 1.5, top, max).astype(np.float32))
    assert gt[1] == 1.5 and gt[5] == -1.5 and gt[2] == gt[4] == 0
    counts, _ = plain.raster("count", resolution=1.5)
    np.testing.assert_array_equal(counts[counts != vola.RASTER_NODATA].sum(), len(plain))
    # A survey: the height column's max (dsm), its min over the ground voxels (dtm).
    height = autzen.attribute("height")
    dsm, gt = autzen.raster("dsm", resolution=6.0)
    np.testing.assert_array_equal(dsm, reference_raster(autzen, 6.0, height, max).astype(np.float32))
    ground = autzen.attribute("classification") == 2
    assert 0 < ground.sum() < len(autzen)
    dtm, _ = autzen.raster("dtm", resolution=6.0)
    expected = reference_raster(autzen, 6.0, np.where(ground, height, np.inf), min)
    expected[np.isinf(expected)] = vola.RASTER_NODATA
    np.testing.assert_array_equal(dtm, expected.astype(np.float32))
    with pytest.raises(vola.InvalidArgument, match="finer than the voxels"):
        autzen.raster("dsm", resolution=1.0)
    with pytest.raises(vola.InvalidArgument, match="'dsm', 'dtm'"):
        autzen.raster("heights")


def test_geotiff_matches_the_cli_and_the_raster(autzen, vola_cli, tmp_path):
    gdal = pytest.importorskip("osgeo.gdal")
    cli_export(vola_cli, autzen, tmp_path, tmp_path / "cli.tif", "--raster", "dtm", "--resolution", "4")
    report = vola.export_raster(autzen, tmp_path / "py.tif", "dtm", resolution=4.0)
    values, gt = autzen.raster("dtm", resolution=4.0)
    assert report["has_crs"] and (report["height"], report["width"]) == values.shape
    for path in (tmp_path / "cli.tif", tmp_path / "py.tif"):
        data = gdal.Open(str(path))
        np.testing.assert_array_equal(data.GetRasterBand(1).ReadAsArray(), values)
        assert data.GetGeoTransform() == pytest.approx(gt)
        assert data.GetRasterBand(1).GetNoDataValue() == vola.RASTER_NODATA
    assert gdal.Open(str(tmp_path / "py.tif")).GetProjection() == gdal.Open(str(tmp_path / "cli.tif")).GetProjection() != ""


def test_export_by_extension_writes_what_the_cli_writes(autzen, vola_cli, tmp_path):
    # vola.export(tree, path, **flags) is `vola export IN path --flags`: the format from the
    # extension, the CLI's flags as keywords.
    runs = (
        ("a.ply", ["--ascii"], {"ascii": True}),
        ("b.xyz", [], {}),
        ("b.csv", [], {}),
        ("c.laz", [], {}),
        ("d.npy", ["--depth", "4"], {"depth": 4}),
        ("e.png", ["--map", "--bits", "8"], {"map": True, "bits": 8}),
        ("f.png", ["--occupancy-above", "20"], {"occupancy_above": 20}),
        ("g.tif", ["--raster", "dtm", "--resolution", "6"], {"raster": "dtm", "resolution": 6.0}),
        ("h.bt", [], {}),
    )
    (tmp_path / "cli").mkdir()
    (tmp_path / "py").mkdir()
    for name, arguments, keywords in runs:
        cli_export(vola_cli, autzen, tmp_path, tmp_path / "cli" / name, *arguments)
        vola.export(autzen, tmp_path / "py" / name, **keywords)
        if name.endswith(".tif"):  # GDAL stamps nothing variable, but compare what matters
            gdal = pytest.importorskip("osgeo.gdal")
            ours, theirs = (gdal.Open(str(tmp_path / d / name)) for d in ("py", "cli"))
            np.testing.assert_array_equal(ours.ReadAsArray(), theirs.ReadAsArray())
            assert ours.GetGeoTransform() == theirs.GetGeoTransform()
            assert ours.GetProjection() == theirs.GetProjection()
        else:
            assert (tmp_path / "py" / name).read_bytes() == (tmp_path / "cli" / name).read_bytes(), name
    assert vola.export(autzen, tmp_path / "x.PLY") == {"vertices": len(autzen), "faces": 0}
    assert vola.export(autzen, tmp_path / "slices", slices=True, depth=3) > 0
    # A path without an extension takes format=, as the error for it says (`vola export --format`).
    assert vola.export(autzen, tmp_path / "points", format="xyz") == vola.export(autzen, tmp_path / "points.xyz")
    assert (tmp_path / "points").read_bytes() == (tmp_path / "points.xyz").read_bytes()


def test_export_refuses_what_the_cli_refuses(autzen, tmp_path):
    refusals = (
        ("a.foo", {}, r"cannot tell the format from the extension '\.foo'"),
        ("a.tif", {}, r"GeoTIFF export needs raster dsm"),
        ("a.tif", {"map": True}, r"name it \.png; for a GeoTIFF of elevations use raster dsm"),
        ("a.png", {}, "PNG export needs slices"),
        ("a.ply", {"raster": "dsm"}, r"raster: writes a GeoTIFF: name the output \.tif, not .*a\.ply"),
        ("a.xyz", {"ascii": True}, "ascii and cubes apply to PLY export"),
        ("a.las", {"free": autzen}, r"free applies to \.bt, \.ot, \.vdb and ROS \(\.yaml\) maps"),
        ("a.png", {"map": True, "occupancy_above": 3}, "different images: give one"),
        ("a.png", {"bits": 8, "occupancy_above": 3}, "bits applies to map"),
    )
    for name, keywords, message in refusals:
        with pytest.raises(vola.InvalidArgument, match=message):
            vola.export(autzen, tmp_path / name, **keywords)
        assert not (tmp_path / name).exists()
