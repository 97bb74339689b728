"""vola.union / intersect / difference (and |, &, -) against numpy's set operations on
dense grids, and against the files `vola union | intersect | diff` write."""
import subprocess
import warnings

import numpy as np
import pytest

import vola
from reference import dense


def two_trees(seed=3):
    rng = np.random.default_rng(seed)
    a = rng.integers(0, 64, size=(3000, 3))
    b = np.concatenate([a[:1000], rng.integers(0, 64, size=(2000, 3))])
    return vola.build_from_voxels(a, depth=3), vola.build_from_voxels(b, depth=3), dense(a, 64), dense(b, 64)


def test_set_operations_match_numpy():
    a, b, ga, gb = two_trees()
    for result, expected in ((vola.union(a, b), ga | gb), (vola.intersect(a, b), ga & gb),
                             (vola.difference(a, b), ga & ~gb), (a | b, ga | gb), (a & b, ga & gb), (a - b, ga & ~gb)):
        np.testing.assert_array_equal(result.to_dense(), expected)
    assert 0 < len(a & b) < len(a) < len(a | b)


def test_grids_must_agree_as_the_cli_says():
    _, b, ga, _ = two_trees()
    moved = vola.from_dense(ga, origin=(10.0, 0.0, 0.0), voxel_size=1.0, depth=3)
    with pytest.raises(vola.InvalidArgument, match="grids differ") as refused:
        vola.union(moved, b)
    assert "--" not in str(refused.value)  # no CLI flags in Python
    with pytest.raises(vola.InvalidArgument, match="grids differ"):
        moved - b
    # ignore_frame combines the indices anyway and keeps a's frame.
    joined = vola.union(moved, b, ignore_frame=True)
    assert list(joined.origin) == [10.0, 0.0, 0.0]
    np.testing.assert_array_equal(joined.to_dense(), ga | b.to_dense())
    with pytest.raises(vola.InvalidArgument, match="depths differ"):
        vola.intersect(b, b.level_of_detail(2))


def test_same_files_as_the_cli(vola_cli, tmp_path):
    a, b, _, _ = two_trees(5)
    a.write(tmp_path / "a.vol")
    b.write(tmp_path / "b.vol")
    for command, ours in (("union", vola.union(a, b)), ("intersect", vola.intersect(a, b)), ("diff", vola.difference(a, b))):
        out = tmp_path / f"{command}.vol"
        subprocess.run([vola_cli, command, str(tmp_path / "a.vol"), str(tmp_path / "b.vol"), str(out), "-q"], check=True)
        assert ours.to_bytes() == out.read_bytes(), command


def test_crs_must_agree_as_the_cli_says(las_file):
    # One grid of one survey, labelled UTM metres and (relabelled) Oregon feet: the same
    # voxel indices are different places, so combining them is refused.
    grid = dict(voxel_size=2.0, origin=(493000.0, 4877000.0, 100.0))
    utm = vola.convert(str(las_file), **grid)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the relabelling's own warning
        feet = vola.convert(str(las_file), assign_crs="EPSG:2994", **grid)
    with pytest.raises(vola.InvalidArgument, match=r"a is in NAD83 / UTM zone 10N \(EPSG:26910\).*b in NAD83\(HARN\)"):
        vola.union(utm, feet)
    with pytest.raises(vola.InvalidArgument, match="different places"):
        utm & feet
    assert len(vola.union(utm, feet, ignore_frame=True)) == len(utm)
    assert len(utm | utm) == len(utm)


def test_grids_whole_voxels_apart_combine_in_world_space():
    """Maps of separate runs have origins that follow their data: the same voxel size with
    origins whole voxels apart is one lattice, combined where the voxels are in the world."""
    p = np.array([[0.5, 0.5, 0.5], [2.5, 2.5, 2.5], [7.5, 1.5, 0.5]])
    q = np.array([[2.5, 2.5, 2.5], [-3.5, 4.5, 1.5], [9.5, 0.5, 0.5]])
    a = vola.build(p, voxel_size=1.0, origin=(0.0, 0.0, 0.0))
    b = vola.build(q, voxel_size=1.0, origin=(-4.0, 0.0, 0.0))
    world = lambda t: {tuple(c) for c in np.floor(t.centers()).astype(int).tolist()}
    assert world(a | b) == world(a) | world(b)
    assert world(a & b) == world(a) & world(b) == {(2, 2, 2)}
    assert world(a - b) == world(a) - world(b)
    assert list((a | b).origin) == [-4.0, 0.0, 0.0]
    with pytest.raises(vola.InvalidArgument, match="grids differ"):
        a | vola.build(q, voxel_size=1.0, origin=(-4.5, 0.0, 0.0))
