"""Writing, reading, parsing and memory-mapping .vol files; errors from bad bytes."""

import os
import shutil

import numpy as np
import pytest

import vola


@pytest.fixture()
def tree():
    rng = np.random.default_rng(2)
    points = rng.uniform(0, 50, size=(4000, 3))
    return vola.build(points, voxel_size=1.0, attributes={"z": points[:, 2]}, epsg=32610)


def same(a, b):
    np.testing.assert_array_equal(a.voxels(), b.voxels())
    assert a.attribute_names == b.attribute_names
    for name in a.attribute_names:
        np.testing.assert_array_equal(a.attribute(name), b.attribute(name))
    assert a.origin == b.origin and a.voxel_size == b.voxel_size and a.epsg == b.epsg


@pytest.mark.parametrize("dense,compress", [(False, False), (True, False), (False, True)])
def test_write_read_mapped_parse_agree(tree, tmp_path, dense, compress):
    if compress and not vola.compression_available():
        pytest.skip("built without zstd")
    path = tmp_path / "t.vol"
    tree.write(path, dense=dense, compress=compress)  # os.PathLike accepted
    read = vola.read(str(path))
    mapped = vola.open(path)
    same(tree, read)
    same(tree, mapped)
    same(tree, vola.parse(path.read_bytes(), name="t.vol"))
    assert path.read_bytes() == tree.to_bytes(dense=dense, compress=compress)
    assert mapped.is_mapped == (not dense and not compress) and not read.is_mapped


def test_a_file_cut_while_mapped_is_refused_not_read_as_zeros(tree, tmp_path):
    path = tmp_path / "t.vol"
    tree.write(path)
    mapped = vola.open(path)
    assert len(mapped.voxels()) == tree.voxel_count
    other = vola.build(np.zeros((1, 3)), voxel_size=1.0)
    os.truncate(path, 4096)  # another process cuts the file (or copies another over it)
    with pytest.raises(vola.IoError, match="was cut"):
        mapped.voxels()  # rows of [0 0 0] before
    with pytest.raises(vola.IoError, match="was cut"):
        mapped.write(tmp_path / "copy.vol")  # a file vola then refused
    assert not (tmp_path / "copy.vol").exists()
    with pytest.raises(vola.IoError, match="was cut"):
        vola.union(other, mapped)
    # Maps and distance fields built from it too (an empty map, distances at the cap before).
    with pytest.raises(vola.IoError, match="was cut"):
        vola.Map.from_tree(mapped)
    with pytest.raises(vola.IoError, match="was cut"):
        vola.DistanceField(mapped, 2.0, lo=(0, 0, 0), hi=(8, 8, 8))
    mapped.census  # an attribute lookup alone reads nothing
    with pytest.raises(vola.IoError, match="was cut"):
        mapped.check_mapped()


def test_a_file_copied_over_in_place_is_refused_not_read_past(tmp_path):
    # shutil.copyfile, like cp, truncates the file and writes the other's bytes: no read
    # fell in the moment it was short, so the mapping showed the larger file's words
    # under the small one's counts, and voxels() wrote past its array (heap corruption).
    rng = np.random.default_rng(0)
    path, big = tmp_path / "small.vol", tmp_path / "big.vol"
    vola.build(rng.uniform(0, 10, (1000, 3)), voxel_size=0.5).write(path)
    vola.build(rng.uniform(0, 100, (200000, 3)), voxel_size=0.5).write(big)
    mapped = vola.open(path)
    shutil.copyfile(big, path)
    with pytest.raises(vola.IoError, match="small.vol: the file was cut"):
        mapped.voxels()
    with pytest.raises(vola.IoError, match="was cut"):
        mapped.centers()


@pytest.mark.parametrize("call", ["level_of_detail", "downsample"])
def test_a_file_cut_before_its_first_read_is_an_io_error(tmp_path, call):
    # Cut before any page was read, the call itself meets the zeros: it failed with a
    # FormatError naming "<memory>"; the cut, naming the file, is what is raised.
    path = tmp_path / "t.vol"
    points = np.random.default_rng(3).uniform(0, 250, size=(20000, 3))
    vola.build(points, voxel_size=1.0).write(path)  # levels over many pages
    mapped = vola.open(path)
    os.truncate(path, 4096)
    with pytest.raises(vola.IoError, match="t.vol: the file was cut"):
        getattr(mapped, call)(max(1, mapped.depth - 1))


def test_mapped_levels_are_views_of_the_file(tree, tmp_path):
    path = tmp_path / "t.vol"
    tree.write(path)
    mapped = vola.open_mapped(path)
    words = [mapped.occupancy(level) for level in range(mapped.depth)]
    assert all(not w.flags.writeable and not w.flags.owndata for w in words)
    assert [len(w) for w in words] == [1] + [mapped.node_count(level) for level in range(mapped.depth - 1)]
    # The file holds the header, then level after level of little-endian words.
    raw = np.frombuffer(path.read_bytes(), dtype="<u8", offset=80, count=sum(len(w) for w in words))
    np.testing.assert_array_equal(np.concatenate(words), raw)
    # The views keep the mapping alive after the tree is gone.
    del mapped
    np.testing.assert_array_equal(np.concatenate(words), raw)
    assert sum(int(w).bit_count() for w in words[-1]) == len(tree)


def test_bad_files_raise_clear_errors(tmp_path):
    missing = tmp_path / "missing.vol"
    with pytest.raises(vola.IoError, match="missing.vol"):
        vola.read(missing)
    bad = tmp_path / "bad.vol"
    bad.write_bytes(b"not a vola file" * 3)
    for opener in (vola.read, vola.open_mapped):
        with pytest.raises(vola.FormatError, match=r"bad\.vol: byte \d+"):
            opener(bad)
    good = vola.build_from_voxels([[1, 2, 3], [4, 5, 6]], depth=3).to_bytes()
    with pytest.raises(vola.FormatError, match="cut.vol: byte"):
        vola.parse(good[: len(good) - 8], name="cut.vol")
    assert issubclass(vola.FormatError, vola.Error) and issubclass(vola.Error, RuntimeError)
    with pytest.raises(vola.IoError, match="no_dir"):
        vola.build_from_voxels([[0, 0, 0]], depth=1).write(tmp_path / "no_dir" / "x.vol")


def test_bad_arguments_raise():
    with pytest.raises(ValueError, match=r"shape \(N, 3\)"):
        vola.build(np.zeros((5, 2)), voxel_size=1.0)
    with pytest.raises(vola.InvalidArgument, match="depth 11"):
        vola.build_from_voxels([[0, 0, 0]], depth=11)
    with pytest.raises(vola.InvalidArgument, match="outside the depth-2 grid"):
        vola.build_from_voxels([[16, 0, 0]], depth=2)
    with pytest.raises(vola.InvalidArgument, match="one value per point"):
        vola.build(np.zeros((4, 3)), voxel_size=1.0, attributes={"a": np.zeros(3)})
    with pytest.raises(vola.InvalidArgument, match="reduction 'median'"):
        vola.build(np.zeros((4, 3)), voxel_size=1.0, attributes={"a": np.zeros(4)}, reductions={"a": "median"})
    with pytest.raises(vola.InvalidArgument, match="voxel_size or a depth"):
        vola.build(np.zeros((4, 3)))
    with pytest.raises(TypeError):
        vola.build(np.zeros((4, 3)), voxel_size=1.0, attributes={"s": np.array(["a"] * 4)})


def test_the_type_stubs_name_every_public_name():
    """export_csv was exported but missing from vola/__init__.pyi: type checkers and IDEs
    did not know it."""
    import re
    from pathlib import Path
    stub = (Path(vola.__file__).parent / "__init__.pyi").read_text()
    named = set(re.findall(r"\b(\w+) as \1\b", stub)) | set(re.findall(r"^def (\w+)", stub, re.M))
    assert set(vola.__all__) - named == set()
