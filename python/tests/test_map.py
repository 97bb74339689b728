"""vola.Map: scans in, states out; its saved state map equals `vola map`'s bytes for the
same scans, and vola.state on the loaded file gives the map's own decisions."""

import pathlib
import subprocess

import numpy as np
import pytest

import vola


def _scans(seed: int):
    """Two scans of rays from two origins: known voxels of both states, unknown elsewhere."""
    rng = np.random.default_rng(seed)
    return [(rng.uniform(-3, 3, size=(400, 3)), np.array([0.05, 0.1, 0.15])),
            (rng.uniform(-3, 3, size=(400, 3)), np.array([1.05, -0.4, 0.3]))]


def _centres(m: vola.Map, lo: int, hi: int) -> np.ndarray:
    axis = (np.arange(lo, hi) + 0.5) * m.voxel_size
    return np.stack(np.meshgrid(axis, axis, axis, indexing="ij"), axis=-1).reshape(-1, 3)


def test_constants_and_states_of_a_hand_made_scan():
    assert (vola.UNKNOWN, vola.FREE, vola.OCCUPIED) == (0, 1, 2)
    m = vola.Map(0.5)
    report = m.insert(np.array([[2.2, 0.3, 0.3]]), origin=(0.1, 0.1, 0.1))
    assert report["points"] == 1 and report["hit_voxels"] == 1 and report["free_voxels"] == 4
    states = m.state(np.array([[2.2, 0.3, 0.3], [0.2, 0.2, 0.2], [1.2, 0.2, 0.2], [9.0, 9.0, 9.0]]))
    assert states.dtype == np.int8
    assert states.tolist() == [vola.OCCUPIED, vola.FREE, vola.FREE, vola.UNKNOWN]
    p = m.probability(np.array([[2.2, 0.3, 0.3], [0.2, 0.2, 0.2], [9.0, 9.0, 9.0]]))
    # Log-odds are 16-bit levels (within 3e-6 of OctoMap's floats after one update).
    assert p[0] == pytest.approx(0.7, abs=1e-5) and p[1] == pytest.approx(0.4, abs=1e-5) and np.isnan(p[2])
    with pytest.raises(vola.InvalidArgument):
        vola.Map(0.0)
    with pytest.raises(ValueError):
        m.insert(np.zeros((2, 2)), origin=(0, 0, 0))


def test_a_scan_in_another_frame_is_refused_before_any_work():
    # Points 1 km from an origin at 0 with 5 cm voxels: 20,000 rays of 20,000+ voxels each.
    m = vola.Map(0.05)
    far = np.column_stack([np.full(20000, 1000.0), np.linspace(0, 10, 20000), np.zeros(20000)])
    with pytest.raises(vola.InvalidArgument, match="max_ray_voxels"):
        m.insert(far, origin=(0, 0, 0))
    assert len(m) == 0
    # The same rays cut by the map's max_range, or a scan within the limit, are inserted.
    assert vola.Map(0.05, max_range=5.0).insert(far, origin=(0, 0, 0))["cut"] == 20000
    assert m.insert(far[::2000], origin=(0, 0, 0))["hit_voxels"] == 10
    with pytest.raises(vola.InvalidArgument, match="max_ray_voxels"):
        m.insert(far[::2000], origin=(0, 0, 0), max_ray_voxels=1000)
    with pytest.raises(vola.InvalidArgument):
        m.insert(far[::2000], origin=(0, 0, 0), max_ray_voxels=-1)


def test_a_saved_map_answers_as_the_map(tmp_path: pathlib.Path):
    m = vola.Map(0.25, max_range=2.5)
    for points, origin in _scans(3):
        m.insert(points, origin)
    path = tmp_path / "map.vol"
    m.save(path)
    tree = vola.open(path, states=True)
    assert tree.is_state_map and len(tree) == len(m)
    # Opened plainly, as every CLI command reads it: the obstacles alone. Free voxels were
    # obstacles to contains, collide, plan and render here.
    obstacles = vola.open(path)
    assert not obstacles.is_state_map
    assert len(obstacles) == len(vola.occupied_tree(tree)) < len(tree)
    free_voxels = vola.free_tree(tree).voxels()
    assert not obstacles.contains(free_voxels).any()
    queries = _centres(m, -14, 14)
    want = m.state(queries)
    assert set(np.unique(want).tolist()) == {vola.UNKNOWN, vola.FREE, vola.OCCUPIED}
    np.testing.assert_array_equal(vola.state(tree, queries), want)
    np.testing.assert_array_equal(vola.probability(tree, queries), m.probability(queries))
    occupied, free = vola.occupied_tree(tree), vola.free_tree(tree)
    assert not occupied.is_state_map
    assert len(occupied) == int((want == vola.OCCUPIED).sum())
    assert len(occupied) + len(free) == len(tree)
    # A plain tree: its voxels are occupied, the rest free.
    plain = vola.state(occupied, queries)
    np.testing.assert_array_equal(plain, np.where(want == vola.OCCUPIED, vola.OCCUPIED, vola.FREE))


def test_save_writes_the_bytes_vola_map_writes(tmp_path: pathlib.Path, vola_cli: str):
    lines = []
    m = vola.Map(0.25, max_range=2.5)
    for n, (points, origin) in enumerate(_scans(5)):
        # The CLI takes sensor-frame points and a pose; an identity rotation adds the
        # translation exactly, so both routes see the same world points.
        np.savetxt(tmp_path / f"scan{n}.xyz", points - origin, fmt="%.17g")
        lines.append(f"scan{n}.xyz {origin[0]!r} {origin[1]!r} {origin[2]!r} 0 0 0 1")
        m.insert((points - origin) + origin, origin)
    (tmp_path / "scans.txt").write_text("\n".join(lines) + "\n")
    subprocess.run([vola_cli, "map", str(tmp_path / "scans.txt"), "-o", str(tmp_path / "cli.vol"),
                    "--voxel-size", "0.25", "--max-range", "2.5", "-q"], check=True)
    m.save(tmp_path / "python.vol")
    assert (tmp_path / "python.vol").read_bytes() == (tmp_path / "cli.vol").read_bytes()


def test_a_saved_map_takes_more_scans_as_vola_map_from_does(tmp_path: pathlib.Path, vola_cli: str):
    """Incremental equals batch: Map.from_tree and `vola map --from` continue a saved map
    to the bytes of inserting every scan at once."""
    scans = _scans(7) + _scans(8)
    lists = {"all": [], "first": [], "rest": []}
    for n, (points, origin) in enumerate(scans):
        np.savetxt(tmp_path / f"scan{n}.xyz", points - origin, fmt="%.17g")
        line = f"scan{n}.xyz {origin[0]!r} {origin[1]!r} {origin[2]!r} 0 0 0 1"
        lists["all"].append(line)
        lists["first" if n < 2 else "rest"].append(line)
    for name, lines in lists.items():
        (tmp_path / f"{name}.txt").write_text("\n".join(lines) + "\n")
    run = lambda *args: subprocess.run([vola_cli, "map", *map(str, args), "--voxel-size", "0.25", "-q"], check=True)
    run(tmp_path / "all.txt", "-o", tmp_path / "all.vol")
    run(tmp_path / "first.txt", "-o", tmp_path / "resumed.vol")
    run(tmp_path / "rest.txt", "--from", tmp_path / "resumed.vol", "-o", tmp_path / "resumed.vol")
    assert (tmp_path / "resumed.vol").read_bytes() == (tmp_path / "all.vol").read_bytes()

    m = vola.Map.from_tree(vola.read(tmp_path / "resumed.vol"))
    assert len(m) == len(vola.Map.from_tree(vola.read(tmp_path / "all.vol")))
    first = vola.Map(0.25)
    for points, origin in scans[:2]:
        first.insert(points, origin)
    first.save(tmp_path / "first_py.vol")
    again = vola.Map.from_tree(vola.read(tmp_path / "first_py.vol"))
    for points, origin in scans[2:]:
        again.insert(points, origin)
    again.save(tmp_path / "again.vol")
    assert (tmp_path / "again.vol").read_bytes() == (tmp_path / "all.vol").read_bytes()
    with pytest.raises(vola.InvalidArgument):
        vola.Map.from_tree(vola.build_from_voxels(np.array([[1, 2, 3]]), 2))
    # A state map opened for its occupied voxels only: the message says how to read its states.
    with pytest.raises(vola.InvalidArgument, match=r"vola.open\('map.vol', states=True\)"):
        vola.Map.from_tree(vola.open(str(tmp_path / "all.vol")))
    assert len(vola.Map.from_tree(vola.open(str(tmp_path / "all.vol"), states=True))) == len(m)
    subprocess.run([vola_cli, "map", str(tmp_path / "rest.txt"), "--from", str(tmp_path / "all.vol"), "-o",
                    str(tmp_path / "x.vol"), "--voxel-size", "0.5", "-q"], check=False)
    assert not (tmp_path / "x.vol").exists(), "a voxel size other than the saved map's was accepted"


def test_threads_may_share_a_map():
    """insert() runs without the GIL: two threads inserting into one map, and one reading
    it meanwhile, crashed the interpreter. Inserts are exclusive; four scans of few points
    never reach the clamping bounds, so any order of them gives the serial map."""
    import threading
    scans = [(np.random.default_rng(seed).uniform(-4, 4, size=(3000, 3)), np.array([0.1 * seed, 0.0, 0.2]))
             for seed in range(4)]
    shared = vola.Map(0.1)
    errors = []

    def insert(part):
        try:
            for index in part:
                shared.insert(*scans[index])
        except Exception as e:  # noqa: BLE001 - reported below
            errors.append(e)

    def read():
        try:
            for _ in range(20):
                shared.state(scans[0][0])
                len(shared)
                shared.tree()
        except Exception as e:  # noqa: BLE001
            errors.append(e)

    threads = [threading.Thread(target=insert, args=((0, 2),)), threading.Thread(target=insert, args=((1, 3),)),
               threading.Thread(target=read)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors
    serial = vola.Map(0.1)
    for points, origin in scans:
        serial.insert(points, origin)
    assert shared.tree().voxels().tolist() == serial.tree().voxels().tolist()
    probe = np.concatenate([points for points, _ in scans])
    assert np.allclose(shared.probability(probe), serial.probability(probe), atol=1e-4, equal_nan=True)


def test_a_state_map_plans_and_collides_as_vola_plan_and_collide_do(tmp_path: pathlib.Path):
    """A state map read with its states made free voxels obstacles (collide_sphere said True in
    free space, plan found no start) and had no `unknown` option; vola.open alone planned
    through unknown space. Now obstacles are the occupied voxels and unknown space counts
    as one unless unknown='free', as in `vola plan`."""
    m = vola.Map(0.5)
    # A wall of hits at x = 5 seen from x = 0: free voxels along the rays, unknown beyond.
    ys, zs = np.meshgrid(np.arange(-2, 2.5, 0.5), np.arange(-2, 2.5, 0.5))
    wall = np.stack([np.full(ys.size, 5.2), ys.ravel() + 0.2, zs.ravel() + 0.2], axis=1)
    m.insert(wall, origin=(0.2, 0.2, 0.2))
    m.save(tmp_path / "map.vol")
    states = vola.open(str(tmp_path / "map.vol"), states=True)
    assert m.state(np.array([[1.2, 0.2, 0.2]])).tolist() == [vola.FREE]
    assert not states.collide_sphere([1.2, 0.2, 0.2], 0.1)  # free space is no obstacle
    assert states.collide_sphere([5.2, 0.2, 0.2], 0.1)     # the wall is
    # Known free from one end of the rays to the other: a path.
    path = states.plan([0.2, 0.2, 0.2], [4.2, 0.2, 0.2], world=True)
    assert len(path["points"]) >= 2
    # Into unknown space (behind the wall): refused unless unknown space is taken as free.
    with pytest.raises(vola.InvalidArgument):
        states.plan([0.2, 0.2, 0.2], [6.7, 0.2, 0.2], world=True)
    assert len(states.plan([0.2, 0.2, 0.2], [6.7, 0.2, 0.2], world=True, unknown="free")["points"]) >= 2
    with pytest.raises(vola.InvalidArgument, match="not a state map"):
        vola.open(str(tmp_path / "map.vol")).plan([0, 0, 0], [1, 1, 1], unknown="occupied")
    with pytest.raises(vola.InvalidArgument, match="'occupied' or 'free'"):
        states.plan([0, 0, 0], [1, 1, 1], unknown="maybe")


def test_a_state_map_raycasts_exports_and_answers_contains_by_its_occupied_voxels(tmp_path: pathlib.Path):
    """Map.tree() (and vola.read of a saved map) holds the free voxels too; raycast hit them at
    t = 0, contains said True for them and exports wrote them as points or cells, where
    collide_segment, plan and `vola export` already took only the occupied voxels."""
    m = vola.Map(0.5)
    ys, zs = np.meshgrid(np.arange(-2, 2.5, 0.5), np.arange(-2, 2.5, 0.5))
    wall = np.stack([np.full(ys.size, 5.2), ys.ravel() + 0.2, zs.ravel() + 0.2], axis=1)
    m.insert(wall, origin=(0.2, 0.2, 0.2))
    tree = m.tree()
    assert tree.is_state_map
    occupied = vola.occupied_tree(tree)
    hit = tree.raycast([[0.2, 0.2, 0.2]], [[1.0, 0.0, 0.0]], world=True)
    assert hit["hit"][0] and hit["point"][0][0] == pytest.approx(5.0)  # the wall, not the free voxel at the start
    start, inside = tree.world_to_voxel(np.array([[0.2, 0.2, 0.2]]))
    assert inside[0] and m.state(np.array([[0.2, 0.2, 0.2]])).tolist() == [vola.FREE]
    assert not tree.contains(start[0])
    assert tree.contains(occupied.voxels()).all()
    vola.export(tree, tmp_path / "map.ply")
    vola.export(occupied, tmp_path / "occupied.ply")
    assert (tmp_path / "map.ply").read_bytes() == (tmp_path / "occupied.ply").read_bytes()


def test_a_state_map_renders_its_occupied_voxels(tmp_path):
    # Rays pass through free space, as `vola render` of the file sees it (they stopped
    # at the first free voxel before).
    m = vola.Map(0.5)
    m.insert(np.array([[5.2, 0.3, 0.3], [5.2, 1.3, 0.3], [5.2, 0.3, 1.3]]), origin=(0.1, 0.1, 0.1))
    m.save(tmp_path / "m.vol")
    states = vola.read(tmp_path / "m.vol")
    occupied = vola.occupied_tree(states)
    camera = dict(eye=(-5.0, 0.5, 0.5), look_at=(5.0, 0.5, 0.5), size=(32, 24), world=True)
    got, want = states.render(**camera), occupied.render(**camera)
    assert got["hits"] == want["hits"] > 0
    np.testing.assert_array_equal(got["depth"], want["depth"])
