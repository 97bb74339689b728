"""vola.convert against `vola convert` (the same readers and rules, so the same file)
and against what the input files are known to hold."""

import hashlib
import pathlib
import struct
import subprocess

import numpy as np
import pytest

import vola


def cli_convert(cli, source, out, *args):
    subprocess.run([cli, "convert", str(source), str(out), "--quiet", *args], check=True)
    return vola.read(out)


def assert_same_tree(ours, theirs):
    np.testing.assert_array_equal(ours.voxels(), theirs.voxels())
    assert ours.attribute_names == theirs.attribute_names
    for name in ours.attribute_names:
        np.testing.assert_array_equal(ours.attribute(name), theirs.attribute(name))
    assert (ours.quantization, ours.origin, ours.voxel_size, ours.epsg, ours.bbox) == (
        theirs.quantization, theirs.origin, theirs.voxel_size, theirs.epsg, theirs.bbox)


@pytest.mark.parametrize("args,kwargs", [(["--voxel-size", "5"], {"voxel_size": 5.0}),
                                         (["--quantize", "toolkit", "--depth", "6"], {"quantize": "toolkit", "depth": 6})])
def test_las_matches_the_cli(las_file, vola_cli, tmp_path, args, kwargs):
    ours = vola.convert(las_file, **kwargs)
    theirs = cli_convert(vola_cli, las_file, tmp_path / "cli.vol", *args)
    assert_same_tree(ours, theirs)
    assert ours.to_bytes() == (tmp_path / "cli.vol").read_bytes()


def test_las_holds_what_the_survey_holds(las_file):
    # pdal_autzen-utm.las (EXPECTED.txt): 1065 points, EPSG:26910, classes {1: 789, 2: 276},
    # bounds [493994.87, 4877429.62, 123.93] .. [494993.68, 4878817.02, 178.73].
    tree = vola.convert(las_file, voxel_size=0.01)  # small voxels: no two points share one
    assert len(tree) == 1065 and tree.epsg == 26910 and "26910" in tree.crs_wkt
    np.testing.assert_allclose(tree.bbox[0], (493994.87, 4877429.62, 123.93), atol=0.006)
    np.testing.assert_allclose(tree.bbox[1], (494993.68, 4878817.02, 178.73), atol=0.006)
    codes, counts = np.unique(tree.attribute("classification"), return_counts=True)
    assert dict(zip(codes.tolist(), counts.tolist())) == {1: 789, 2: 276}
    centers = tree.centers()
    assert np.all(centers >= np.asarray(tree.bbox[0]) - 0.01) and np.all(centers <= np.asarray(tree.bbox[1]) + 0.01)
    lat, lon = tree.lat_lon
    assert 44.0 < lat < 44.1 and -123.1 < lon < -123.0  # Autzen stadium, Eugene, Oregon


def test_voxel_grid_and_mesh_inputs_match_the_cli(shared_data, vola_cli, tmp_path):
    binvox = shared_data / "binvox" / "trimesh_chair_model.binvox"
    stl = shared_data / "mesh" / "stl" / "trimesh_featuretype_bin.stl"
    for path in (binvox, stl):
        if not path.exists():
            pytest.fail(f"{path} missing")
    assert_same_tree(vola.convert(binvox), cli_convert(vola_cli, binvox, tmp_path / "b.vol"))
    assert_same_tree(vola.convert(stl, voxel_size=1.0, solid=True),
                     cli_convert(vola_cli, stl, tmp_path / "s.vol", "--voxel-size", "1", "--solid"))


def test_convert_errors_name_the_problem(tmp_path, las_file):
    unknown = tmp_path / "points.unknown_ext"
    unknown.write_text("1 2 3\n")
    with pytest.raises(vola.InvalidArgument, match="unknown_ext"):
        vola.convert(unknown, voxel_size=1.0)
    with pytest.raises(vola.IoError, match="missing.las: cannot open: No such file"):  # before any format
        vola.convert(tmp_path / "missing.las", voxel_size=1.0)
    with pytest.raises(vola.InvalidArgument, match="toolkit quantization needs a depth"):
        vola.convert(las_file, quantize="toolkit")
    bad = tmp_path / "bad.las"
    bad.write_bytes(b"LASF" + bytes(50))
    with pytest.raises(vola.FormatError, match="bad.las"):
        vola.convert(bad, voxel_size=1.0)
    formats = dict(vola.input_formats())
    assert ".las" in formats["las"] and ".npy" in formats["npy"]


def test_convert_refuses_the_outputs_the_cli_refuses(tmp_path, las_file):
    # output= the input overwrote the survey with a .vol; a .las name got .vol bytes.
    survey = tmp_path / "survey.las"
    survey.write_bytes(pathlib.Path(las_file).read_bytes())
    before = survey.read_bytes()
    with pytest.raises(vola.InvalidArgument, match="is the input"):
        vola.convert(survey, voxel_size=4.0, output=survey)
    assert survey.read_bytes() == before
    with pytest.raises(vola.InvalidArgument, match="writes a .vol file, not las"):
        vola.convert(survey, voxel_size=4.0, output=tmp_path / "voxels.las")
    assert not (tmp_path / "voxels.las").exists()


def test_convert_warns_as_the_cli_does(tmp_path, shared_data):
    # autzen_trim states its own CRS (in feet): relabelling it is warned of, as `vola convert` warns.
    with pytest.warns(UserWarning, match="relabels its coordinates without moving them"):
        vola.convert(shared_data / "las" / "pdal_autzen_trim.las", voxel_size=10.0, assign_crs="EPSG:32610")
    # With a target CRS too: the points are reprojected from the label, which is said.
    with pytest.warns(UserWarning, match="`target_crs` reprojects them from that label"):
        vola.convert(shared_data / "las" / "pdal_autzen_trim.las", voxel_size=10.0, assign_crs="EPSG:26910",
                     target_crs="EPSG:32610")


def test_convert_warns_of_the_points_it_leaves_out(tmp_path):
    # The CLI's summary counts them ("points dropped: 10"); vola.build warns of the same points.
    points = np.random.default_rng(3).uniform(0, 10, (100, 3))
    points[:10] = np.nan
    np.save(tmp_path / "some_nan.npy", points)
    with pytest.warns(UserWarning, match="10 of its 100 points are left out"):
        tree = vola.convert(tmp_path / "some_nan.npy", voxel_size=1.0)
    assert tree.voxel_count == vola.build(points[10:], voxel_size=1.0).voxel_count
    # Nothing left at all is an empty tree, said as such.
    np.save(tmp_path / "all_nan.npy", np.full((5, 3), np.nan))
    with pytest.warns(UserWarning, match="every one of its 5 points was dropped"):
        assert vola.convert(tmp_path / "all_nan.npy", voxel_size=1.0).voxel_count == 0
    # x, y and z saved as rows: refused, not read as three points.
    np.save(tmp_path / "rows.npy", points[10:].T)
    with pytest.raises(vola.FormatError, match=r"points\.T"):
        vola.convert(tmp_path / "rows.npy", voxel_size=1.0)


def _las_records(path):
    """The point records of a LAS file: count x record length bytes after the offset."""
    data = pathlib.Path(path).read_bytes()
    offset, length = struct.unpack_from("<I", data, 96)[0], struct.unpack_from("<H", data, 105)[0]
    count = struct.unpack_from("<I", data, 107)[0] or struct.unpack_from("<Q", data, 247)[0]
    return data[offset:offset + count * length]


def test_translate_and_export_las_like_the_cli(tmp_path, shared_data, vola_cli):
    laz = shared_data / "laz" / "pdal_autzen_trim.laz"
    # LAZ -> LAS: the records laz-perf decoded (EXPECTED.txt), as the CLI writes them.
    vola.translate(laz, tmp_path / "py.las")
    subprocess.run([vola_cli, "translate", str(laz), str(tmp_path / "cli.las"), "-q"], check=True)
    line = next(l for l in (shared_data / "EXPECTED.txt").read_text().splitlines() if l.startswith(laz.name + ":"))
    expected = line.split("points_sha256=")[1].split()[0]
    assert hashlib.sha256(_las_records(tmp_path / "py.las")).hexdigest() == expected
    assert _las_records(tmp_path / "py.las") == _las_records(tmp_path / "cli.las")
    # A tree out as LAZ: the same records as its LAS export, back through translate.
    tree = vola.convert(laz, voxel_size=4.0)
    vola.export_las(tree, tmp_path / "tree.laz")
    vola.export_las(tree, tmp_path / "tree.las")
    vola.translate(tmp_path / "tree.laz", tmp_path / "tree_back.las")
    assert _las_records(tmp_path / "tree_back.las") == _las_records(tmp_path / "tree.las")
    with pytest.raises(vola.InvalidArgument, match="writes .las, .laz, .ply"):
        vola.translate(laz, tmp_path / "points.obj")


def test_translate_reads_by_the_format_named(tmp_path):
    # A Lyft sweep: five float32 a point under a plain .bin name, which KITTI cannot read.
    sweep = tmp_path / "host-a017_lidar1.bin"
    np.array([[1, 2, 3, 40, 1], [4, 5, 6, 80, 2]], dtype=np.float32).tofile(sweep)
    with pytest.raises(vola.FormatError, match="nuscenes"):
        vola.translate(sweep, tmp_path / "kitti.xyz")
    vola.translate(sweep, tmp_path / "sweep.xyz", format="nuscenes")
    rows = [line.split() for line in (tmp_path / "sweep.xyz").read_text().splitlines()[1:]]
    assert rows == [["1", "2", "3", "40", "1"], ["4", "5", "6", "80", "2"]]
