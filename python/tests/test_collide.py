"""Tree.collide_segment / collide_sphere / collide_box against brute force over every
voxel, and against `vola collide`'s answers (exit status 3 hit, 0 free)."""
import subprocess

import numpy as np
import pytest

import vola


def scene():
    rng = np.random.default_rng(21)
    voxels = rng.integers(0, 64, size=(300, 3))
    return vola.build_from_voxels(voxels, depth=3), np.unique(voxels, axis=0).astype(float)


def test_spheres_and_boxes_match_brute_force():
    tree, v = scene()
    rng = np.random.default_rng(1)
    centres = rng.uniform(-5, 69, size=(400, 3))
    radii = rng.uniform(0, 6, size=400)
    nearest = np.clip(centres[:, None, :], v[None], v[None] + 1)  # closest point of each voxel cube
    within = (np.linalg.norm(nearest - centres[:, None, :], axis=2) <= radii[:, None]).any(axis=1)
    hits = tree.collide_sphere(centres, radii, world=False)
    np.testing.assert_array_equal(hits, within)
    assert 0 < hits.sum() < len(hits)
    assert tree.collide_sphere(centres[0], radii[0], world=False) == within[0]
    lo = rng.uniform(-5, 64, size=(400, 3))
    boxes = np.concatenate([lo, lo + rng.uniform(0, 8, size=(400, 3))], axis=1)
    overlap = ((v[None] < boxes[:, None, 3:]) & (v[None] + 1 > boxes[:, None, :3])).all(axis=2).any(axis=1)
    np.testing.assert_array_equal(tree.collide_box(boxes, world=False), overlap)
    assert 0 < overlap.sum() < len(overlap)
    with pytest.raises(vola.InvalidArgument, match="box 0: box: min and max"):
        tree.collide_box([[1, 1, 1, 0, 2, 2], [0, 0, 0, 1, 1, 1]], world=False)
    with pytest.raises(vola.InvalidArgument, match="radius must be finite and >= 0"):
        tree.collide_sphere([1.0, 1.0, 1.0], -1.0, world=False)


def test_segments_match_brute_force():
    tree, v = scene()
    rng = np.random.default_rng(2)
    a = rng.uniform(-5, 69, size=(300, 3))
    b = rng.uniform(-5, 69, size=(300, 3))
    d = b - a
    with np.errstate(divide="ignore", invalid="ignore"):
        t0 = (v[None] - a[:, None]) / d[:, None]
        t1 = (v[None] + 1 - a[:, None]) / d[:, None]
    enter = np.maximum(np.minimum(t0, t1).max(axis=2), 0.0)
    leave = np.minimum(np.maximum(t0, t1).min(axis=2), 1.0)
    crosses = enter <= leave
    first = np.where(crosses, enter, np.inf).min(axis=1)
    result = tree.collide_segment(a, b, world=False)
    np.testing.assert_array_equal(result["hit"], np.isfinite(first))
    hit = result["hit"]
    assert 0 < hit.sum() < len(hit)
    np.testing.assert_allclose(result["t"][hit], first[hit], atol=1e-9)
    np.testing.assert_allclose(result["point"][hit], a[hit] + first[hit, None] * d[hit], atol=1e-9)
    np.testing.assert_allclose(result["distance"][hit], first[hit] * np.linalg.norm(d[hit], axis=1), atol=1e-9)
    # The voxel named is occupied and holds the entry point.
    assert tree.contains(result["voxel"][hit]).all()
    inside = (result["point"][hit] >= result["voxel"][hit] - 1e-9) & (result["point"][hit] <= result["voxel"][hit] + 1 + 1e-9)
    assert inside.all()
    assert np.all(result["voxel"][~hit] == -1) and np.all(np.isinf(result["t"][~hit]))
    # A segment of no length (a robot standing still) is its point: the voxel holding it.
    occupied = tree.voxels()[0] + 0.5
    still = tree.collide_segment([occupied, occupied + 0.25], [occupied, [-5.0, -5.0, -5.0]], world=False)
    assert still["hit"][0] and still["t"][0] == 0 and (still["voxel"][0] == occupied - 0.5).all()
    assert not tree.collide_segment([-3.0, -3.0, -3.0], [-3.0, -3.0, -3.0], world=False)["hit"][0]


def test_same_answers_as_the_cli(autzen_trim, vola_cli, tmp_path):
    tree = vola.convert(autzen_trim, voxel_size=3.0)
    tree.write(tmp_path / "in.vol")
    (x0, y0, z0), (x1, y1, z1) = tree.bbox
    rng = np.random.default_rng(5)
    low = np.array([x0, y0, z0 - 5])
    high = np.array([x1, y1, z1 + 5])
    starts = rng.uniform(low, high, size=(6, 3))
    ends = rng.uniform(low, high, size=(6, 3))
    centres = rng.uniform(low, high, size=(6, 3))
    segments = tree.collide_segment(starts, ends)
    spheres = tree.collide_sphere(centres, 8.0)
    boxes = tree.collide_box(np.concatenate([centres - 6, centres + 6], axis=1))

    def cli(query, *numbers):
        status = subprocess.run([vola_cli, "collide", str(tmp_path / "in.vol"), query, *(repr(float(n)) for n in numbers),
                                 "-q"]).returncode
        assert status in (0, 3)
        return status == 3

    for i in range(6):
        assert cli("--segment", *starts[i], *ends[i]) == segments["hit"][i]
        assert cli("--sphere", *centres[i], 8.0) == spheres[i]
        assert cli("--box", *(centres[i] - 6), *(centres[i] + 6)) == boxes[i]
    assert 0 < segments["hit"].sum() + spheres.sum() + boxes.sum() < 18


def test_unknown_space_a_free_query_reaches_matches_brute_force(tmp_path):
    """A state map's free spheres and boxes (and segments) count the voxels they reach that the
    map has not seen, as `vola collide` says of them; brute force over every voxel's state."""
    m = vola.Map(0.5)
    rng = np.random.default_rng(9)
    m.insert(rng.uniform(-3, 3, size=(300, 3)), origin=(0.05, 0.1, 0.15))
    m.save(tmp_path / "map.vol")
    tree = vola.read(tmp_path / "map.vol")
    assert tree.is_state_map
    side, size, origin = tree.side, tree.voxel_size, np.array(tree.origin)
    cells = np.stack(np.meshgrid(*[np.arange(-5, side + 5)] * 3, indexing="ij"), axis=-1).reshape(-1, 3)  # every cell a query reaches
    inside = ((cells >= 0) & (cells < side)).all(axis=1)
    unknown_cell = ~inside
    unknown_cell[inside] = vola.state(tree, origin + (cells[inside] + 0.5) * size) == vola.UNKNOWN
    centres = rng.uniform(-2, side + 2, size=(200, 3))
    radii = rng.uniform(0, 2.5, size=200)
    answer = tree.collide_sphere(centres, radii, world=False, unknown=True)
    nearest = np.clip(centres[:, None, :], cells[None], cells[None] + 1)
    reached = np.linalg.norm(nearest - centres[:, None, :], axis=2) <= radii[:, None]
    expected = (reached & unknown_cell[None]).sum(axis=1)
    free = ~answer["hit"]
    np.testing.assert_array_equal(answer["hit"], tree.collide_sphere(centres, radii, world=False))
    np.testing.assert_array_equal(answer["unknown"][free], expected[free])
    assert (answer["unknown"][~free] == 0).all() and 0 < (answer["unknown"][free] > 0).sum() < free.sum()
    lo = rng.uniform(-2, side + 1, size=(200, 3))
    boxes = np.concatenate([lo, lo + rng.uniform(0, 3, size=(200, 3))], axis=1)
    answer = tree.collide_box(boxes, world=False, unknown=True)
    overlap = ((cells[None] < boxes[:, None, 3:]) & (cells[None] + 1 > boxes[:, None, :3])).all(axis=2)
    free = ~answer["hit"]
    np.testing.assert_array_equal(answer["unknown"][free], (overlap & unknown_cell[None]).sum(axis=1)[free])
    # One query given as one row answers with plain numbers; a plain tree has no unknown space.
    one = tree.collide_sphere(centres[0], radii[0], world=False, unknown=True)
    assert isinstance(one["hit"], bool) and isinstance(one["unknown"], int)
    plain = vola.build_from_voxels(tree.voxels(), depth=tree.depth)
    assert (plain.collide_box(boxes, world=False, unknown=True)["unknown"] == 0).all()
    # Segments: the same count `vola collide --segment` prints.
    segment = tree.collide_segment(centres[:20], centres[20:40], world=False)
    assert segment["unknown"].dtype == np.int64 and (segment["unknown"][segment["hit"]] == 0).all()
    assert (segment["unknown"][~segment["hit"]] > 0).any()
