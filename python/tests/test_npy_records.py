"""NumPy record arrays written by numpy itself (an aligned dtype, so with padding, as
laspy's points.array or PDAL's numpy writer give them) read by the CLI as points: the
x/y/z fields as coordinates, the other numeric fields as columns, text skipped."""
import subprocess

import numpy as np


def test_numpy_record_arrays_are_points_with_their_fields(tmp_path, vola_cli):
    dtype = np.dtype([("X", "<f8"), ("Y", "<f8"), ("Z", "<f4"), ("Intensity", "<u2"), ("classification", "u1"),
                      ("rgb", "u1", (3,)), ("label", "S3"), ("GpsTime", ">f8")], align=True)
    assert dtype.itemsize > sum(dtype.fields[n][0].itemsize for n in dtype.names)  # padding between fields
    rng = np.random.default_rng(7)
    points = np.zeros(64, dtype=dtype)
    points["X"] = rng.uniform(500000, 500100, 64)
    points["Y"] = rng.uniform(4e6, 4e6 + 100, 64)
    points["Z"] = rng.uniform(100, 120, 64).astype(np.float32)
    points["Intensity"] = rng.integers(0, 65535, 64)
    points["classification"] = rng.integers(1, 7, 64)
    points["rgb"] = rng.integers(0, 255, (64, 3))
    points["label"] = b"abc"
    points["GpsTime"] = rng.uniform(0, 1e6, 64)
    np.save(tmp_path / "records.npy", points)
    subprocess.run([vola_cli, "translate", str(tmp_path / "records.npy"), str(tmp_path / "out.xyz"), "-q"], check=True)
    lines = (tmp_path / "out.xyz").read_text().splitlines()
    header = lines[0].lstrip("# ").split()
    assert header == ["x", "y", "z", "intensity", "classification", "rgb_0", "rgb_1", "rgb_2", "gps_time"]
    got = np.array([[float(v) for v in line.split()] for line in lines[1:]])
    assert got.shape == (64, 9)
    np.testing.assert_allclose(got[:, 0], points["X"], rtol=0, atol=1e-6)
    np.testing.assert_allclose(got[:, 1], points["Y"], rtol=0, atol=1e-6)
    np.testing.assert_allclose(got[:, 2], points["Z"].astype(np.float64), rtol=0, atol=1e-5)
    np.testing.assert_array_equal(got[:, 3], points["Intensity"])
    np.testing.assert_array_equal(got[:, 4], points["classification"])
    np.testing.assert_array_equal(got[:, 5:8], points["rgb"])
    np.testing.assert_allclose(got[:, 8], points["GpsTime"], rtol=1e-12)
