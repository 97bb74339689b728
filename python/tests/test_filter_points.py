"""vola.filter_points: the point filters on arrays give what `vola translate --filter`
gives on the file (points, classification, height above ground), and `where` keeps what
the same test in numpy keeps."""
import numpy as np
import pytest

import vola

PLY_TYPES = {"double": "<f8", "float": "<f4", "uchar": "u1", "char": "i1", "ushort": "<u2", "short": "<i2",
             "uint": "<u4", "int": "<i4"}


def read_ply(path):
    """The binary little-endian PLY `vola translate` writes: {'xyz': (N, 3), name: (N,)}."""
    data = path.read_bytes()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    fields, count = [], 0
    for line in data[:end].decode().splitlines():
        words = line.split()
        if words[:2] == ["element", "vertex"]:
            count = int(words[2])
        elif words[:1] == ["property"]:
            fields.append((words[2], PLY_TYPES[words[1]]))
    records = np.frombuffer(data, dtype=np.dtype(fields), count=count, offset=end)
    out = {name: records[name].copy() for name, _ in fields if name not in "xyz"}
    out["xyz"] = np.stack([records["x"], records["y"], records["z"]], axis=1)
    return out


@pytest.fixture(scope="module")
def autzen(shared_data, tmp_path_factory):
    path = shared_data / "las" / "pdal_autzen_trim.las"
    if not path.exists():
        pytest.skip(f"no {path}")
    ply = tmp_path_factory.mktemp("points") / "autzen.ply"
    vola.translate(path, ply)
    tree = vola.convert(path, voxel_size=50.0)
    return path, read_ply(ply), tree.crs_wkt


def test_smrf_and_hag_as_translate_writes_them(autzen, tmp_path):
    path, points, crs = autzen
    columns = {name: values for name, values in points.items() if name != "xyz"}
    ours = vola.filter_points(points["xyz"], columns, ["smrf", "hag", "where:HeightAboveGround < 30"], crs=crs)
    vola.translate(path, tmp_path / "cli.ply", filters=["smrf", "hag", "where:HeightAboveGround < 30"])
    theirs = read_ply(tmp_path / "cli.ply")
    np.testing.assert_array_equal(ours["points"], theirs["xyz"])
    for name in ("classification", "height_above_ground", "intensity"):
        np.testing.assert_array_equal(ours["attributes"][name], theirs[name])
        assert ours["attributes"][name].dtype == theirs[name].dtype
    kept = ours["kept"]
    np.testing.assert_array_equal(points["xyz"][kept], ours["points"])
    smrf, hag, where = ours["stages"]
    assert smrf["points_in"] == len(points["xyz"]) and 0 < smrf["ground"] < smrf["points_in"]
    assert where["points_out"] == len(kept) < where["points_in"]
    assert set(np.unique(ours["attributes"]["classification"])) == {1, 2}


def test_where_keeps_what_numpy_keeps(autzen):
    _, points, _ = autzen
    cls = points["classification"]
    ours = vola.filter_points(points["xyz"], {"classification": cls, "intensity": points["intensity"]},
                              ["where:Classification == 2 && (Intensity > 100 || z < 420)"])
    mask = (cls == 2) & ((points["intensity"] > 100) | (points["xyz"][:, 2] < 420))
    assert 0 < mask.sum() < len(mask)
    np.testing.assert_array_equal(ours["kept"], np.flatnonzero(mask))
    np.testing.assert_array_equal(ours["attributes"]["intensity"], points["intensity"][mask])


def test_bad_filters_raise_in_python_words(autzen):
    _, points, _ = autzen
    with pytest.raises(vola.InvalidArgument, match="^filters: .*no filter 'ground'"):
        vola.filter_points(points["xyz"], filters=["ground"])
    with pytest.raises(vola.InvalidArgument, match="no dimension 'Clasification'"):
        vola.filter_points(points["xyz"], {"classification": points["classification"]}, ["where:Clasification == 2"])
    with pytest.raises(vola.InvalidArgument, match="one value per point"):
        vola.filter_points(points["xyz"], {"classification": points["classification"][:5]})
    # A CRS PROJ does not know is refused (taken as none, SMRF read feet as metres).
    for crs in ("EPSG:29920", "feet"):
        with pytest.raises(vola.InvalidArgument, match="is not a CRS PROJ knows"):
            vola.filter_points(points["xyz"], filters=["smrf"], crs=crs)
    with pytest.raises(TypeError, match="column names"):
        vola.filter_points(points["xyz"], {1: points["classification"]})
