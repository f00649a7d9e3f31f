"""Reachability maps: agreement with direct IK, chunking, Zarr, plots, bad input (issue 16)."""

import math

import numpy as np
import pytest

import robokin
from robokin import cell
from robokin.exceptions import InputError

pytest.importorskip("dask")
pytest.importorskip("zarr")

REGION = [[-0.6, -0.6, -0.3], [0.6, 0.6, 0.9]]
FIELDS = ("counts", "index", "solutions", "manipulability")


@pytest.fixture(scope="module")
def ur5():
    return robokin.load("ur5")


@pytest.fixture(scope="module")
def small_map(ur5):
    return cell.reach_map(ur5, region=REGION, voxel=0.15, orientations=12, rolls=2)


def assert_maps_equal(a, b):
    for f in FIELDS:
        x, y = np.asarray(getattr(a, f)[...]), np.asarray(getattr(b, f)[...])
        assert x.dtype == y.dtype and np.array_equal(x, y), f
    assert np.array_equal(a.orientations, b.orientations)
    assert np.array_equal(a.centers, b.centers)


def test_the_map_has_the_contract_shapes(small_map):
    m = small_map
    V, K = m.size, 24
    assert m.centers.shape == (V, 3) and m.orientations.shape == (K, 3, 3)
    assert m.reachable.shape == (V, K) and m.reachable.dtype == bool
    assert m.index.shape == (V,)
    np.testing.assert_array_equal(m.index, m.reachable.mean(axis=-1))
    np.testing.assert_array_equal(m.solutions, m.counts.sum(axis=-1))
    assert m.method == "analytic:three_parallel"
    assert 0 < m.summary()["reachable_voxels"] <= V


def test_random_voxels_and_orientations_agree_with_direct_ik(ur5, small_map, rng):
    m = small_map
    for v in rng.choice(m.size, 25, replace=False):
        best = 0.0
        for k in range(m.orientations.shape[0]):
            T = np.eye(4)
            T[:3, :3] = m.orientations[k]
            T[:3, 3] = m.centers[v]
            sols = ur5.ik(T)
            inside = sols.within_limits
            assert m.counts[v, k] == inside.sum()
            assert m.reachable[v, k] == inside.any()
            if inside.any():
                best = max(best, float(ur5.manipulability(sols.q[inside]).max()))
        assert m.manipulability[v] == pytest.approx(best, rel=1e-9, abs=1e-12)


@pytest.mark.parametrize(("chunk", "scheduler"), [(1, "synchronous"), (7, None),
                                                  (50, "threads")])
def test_chunking_and_local_schedulers_change_no_bit(ur5, small_map, chunk, scheduler):
    m = cell.reach_map(ur5, region=REGION, voxel=0.15, orientations=12, rolls=2,
                       chunk=chunk, scheduler=scheduler)
    assert_maps_equal(m, small_map)


def test_processes_scheduler_changes_no_bit(ur5, small_map):
    m = cell.reach_map(ur5, region=REGION, voxel=0.15, orientations=12, rolls=2,
                       chunk=40, scheduler="processes")
    assert_maps_equal(m, small_map)


def test_a_numeric_arm_maps_with_one_solution_per_target(rng):
    # method="numeric": the numeric sample alone (the default on a 7-axis arm also
    # searches the self-motion manifold: tests/cell/test_manifold.py)
    panda = robokin.load("panda")
    m = cell.reach_map(panda, region=[[0.2, -0.3, 0.2], [0.7, 0.3, 0.6]], voxel=0.2,
                       orientations=6, chunk=5, method="numeric")
    assert m.method == "numeric" and m.counts.max() <= 1
    assert m.index.sum() > 0
    from robokin.kinematics.ik.numeric import solve

    v = rng.choice(m.size, 4, replace=False)
    T = np.zeros((4, 6, 4, 4))
    T[:, :, :3, :3] = m.orientations
    T[:, :, :3, 3] = m.centers[v][:, None]
    T[:, :, 3, 3] = 1
    res = solve(panda, T, max_restarts=4)
    ok = res.success & panda.within_limits(res.q)
    np.testing.assert_array_equal(m.reachable[v], ok)
    again = cell.reach_map(panda, region=[[0.2, -0.3, 0.2], [0.7, 0.3, 0.6]], voxel=0.2,
                           orientations=6, chunk=2, method="numeric")
    assert_maps_equal(m, again)


def test_a_scene_removes_solutions_that_collide():
    pytest.importorskip("coal")
    from robokin.collision import Scene, check

    aubo = robokin.load("aubo_i5")
    scene = Scene("wall")
    wall = np.eye(4)
    wall[:3, 3] = (0.45, 0.0, 0.4)
    scene.add_box("wall", (0.1, 1.2, 0.8), wall)
    kw = dict(region=[[0.25, -0.2, 0.2], [0.65, 0.2, 0.6]], voxel=0.2, orientations=4)
    free = cell.reach_map(aubo, **kw)
    walled = cell.reach_map(aubo, scene=scene, **kw)
    assert walled.scene == "wall"
    assert (walled.counts <= free.counts).all() and walled.counts.sum() < free.counts.sum()
    # one voxel re-checked: each closed-form solution counted iff it touches nothing
    v = int(np.argmax(free.counts.sum(axis=1) - walled.counts.sum(axis=1)))
    for k in range(4):
        T = np.eye(4)
        T[:3, :3], T[:3, 3] = walled.orientations[k], walled.centers[v]
        sols = aubo.ik(T)
        q = sols.q[sols.within_limits]
        n_free = sum(not check(aubo, scene, qi[None], subdivide=False).collides for qi in q)
        assert walled.counts[v, k] == n_free


def test_zarr_round_trip(small_map, tmp_path):
    path = small_map.save(tmp_path / "map.zarr")
    back = cell.ReachMap.load(path)
    assert_maps_equal(back, small_map)
    assert back.robot_name == "ur5" and back.method == small_map.method
    np.testing.assert_array_equal(back.base, small_map.base)
    lazy = cell.ReachMap.load(path, lazy=True)
    assert not isinstance(lazy.counts, np.ndarray)
    assert_maps_equal(lazy, small_map)
    with pytest.raises(InputError, match="argument 'path'.*exists"):
        small_map.save(path)
    small_map.save(path, overwrite=True)
    assert [p.name for p in tmp_path.iterdir()] == ["map.zarr"]  # no temporary left
    with pytest.raises(InputError, match="is not a reachability map"):
        cell.ReachMap.load(tmp_path)


def test_streaming_into_a_store_resumes_and_refuses_another_map(ur5, small_map, tmp_path):
    import zarr

    store = tmp_path / "stream.zarr"
    kw = dict(region=REGION, voxel=0.15, orientations=12, rolls=2, chunk=20)
    m = cell.reach_map(ur5, store=store, **kw)
    assert m.path == store.resolve() and not isinstance(m.counts, np.ndarray)
    assert_maps_equal(m, small_map)
    # a run that stopped part-way: some chunks not marked done
    g = zarr.open_group(str(store), mode="r+")
    done = g["done"][:]
    done[2:5] = False
    g["done"][:] = done
    g.attrs["complete"] = False
    with pytest.raises(InputError, match="incomplete map \\(.* chunks written\\)"):
        cell.ReachMap.load(store)
    calls = []
    resumed = cell.reach_map(ur5, store=store, progress=lambda d, t: calls.append(t), **kw)
    assert calls and calls[-1] == 3  # only the three missing chunks ran
    assert_maps_equal(resumed, small_map)
    with pytest.raises(InputError, match="argument 'store'.*holds a different map"):
        cell.reach_map(ur5, store=store, **{**kw, "voxel": 0.2})
    other = cell.reach_map(ur5, store=store, overwrite=True, **{**kw, "voxel": 0.3})
    assert other.grid.voxel == 0.3


def test_sections_are_heatmaps_of_the_map(small_map, tmp_path):
    fig = small_map.plot_sections(path=tmp_path / "sections.png")
    assert (tmp_path / "sections.png").stat().st_size > 10_000
    assert len(fig.axes) == 3  # two sections and a colour bar
    small_map.plot_sections(path=tmp_path / "w.png", quantity="manipulability",
                            sections=[("x", 0.0)])
    values, extent = small_map.section("z", 0.3)
    assert values.shape == small_map.grid.shape[:2]
    np.testing.assert_allclose(extent[0], small_map.grid.origin[:2])
    with pytest.raises(InputError, match="argument 'quantity'"):
        small_map.section("z", 0.3, "speed")
    with pytest.raises(InputError, match="argument 'axis'"):
        small_map.section("w", 0.3)


@pytest.mark.parametrize(("kwargs", "argument", "match"), [
    ({"region": [[0, 0, 0], [1, 1, 0]]}, "region", "is empty"),
    ({"region": [[0, 0, 0], [-1, 1, 1]]}, "region", "is empty"),
    ({"voxel": 0}, "voxel", "> 0"),
    ({"voxel": -0.1}, "voxel", "> 0"),
    ({"orientations": 0}, "orientations", ">= 1"),
    ({"orientations": np.ones((2, 3, 3))}, "orientations", ""),
    ({"orientations": np.zeros((0, 3, 3))}, "orientations", "K >= 1"),
    ({"scheduler": "cluster please"}, "scheduler", "expected None"),
    ({"method": "magic"}, "method", "expected 'auto'"),
    ({"chunk": 0}, "chunk", ">= 1"),
])
def test_bad_input_names_the_argument(ur5, kwargs, argument, match):
    args = {"region": REGION, "voxel": 0.3, "orientations": 4, **kwargs}
    with pytest.raises(InputError, match=f"argument '{argument}'.*{match}"):
        cell.reach_map(ur5, **args)


def test_analytic_is_refused_for_an_arm_without_a_closed_form():
    with pytest.raises(InputError, match="argument 'method'.*no closed form"):
        cell.reach_map(robokin.load("panda"), region=REGION, voxel=0.5, method="analytic")


def test_the_default_region_covers_the_workspace(ur5):
    m = cell.reach_map(ur5, voxel=0.4, orientations=2, manipulability=False)
    lo, hi = m.grid.bounds
    assert (lo[:2] < -0.85).all() and (hi[:2] > 0.85).all()  # the UR5 reaches 0.85 m
    assert m.manipulability is None
    assert m.index.max() > 0 and m.index[0] == 0  # a corner of the box is out of reach
    assert math.isclose(m.volume(), np.count_nonzero(m.index) * 0.4**3)


def test_a_map_too_large_for_memory_asks_for_a_store(ur5, monkeypatch, tmp_path):
    import importlib

    rm = importlib.import_module("robokin.cell.reach_map")  # the module, not the function

    def never(*args, **kwargs):
        raise AssertionError("the in-memory map was allocated")

    with monkeypatch.context() as mp:
        mp.setattr(rm, "_run_in_memory", never)
        # 10^9 voxels x 32 orientations: 48.4 GiB of arrays
        with pytest.raises(InputError, match=r"argument 'store': the map \(1,000,000,000 "
                           r"voxels x 32 orientations\) needs 48\.4 GiB in memory, more "
                           r"than the 2 GiB limit; pass store= a folder"):
            cell.reach_map(ur5, region=[[-0.5, -0.5, 0.0], [0.5, 0.5, 1.0]], voxel=0.001)
    # the cap counts V x K bytes of counts and 20 (12) bytes per voxel
    kw = dict(region=REGION, voxel=0.3, orientations=4)
    V, K = 4 * 4 * 4, 4
    monkeypatch.setattr(rm, "MAX_IN_MEMORY_BYTES", V * K + 20 * V)
    assert cell.reach_map(ur5, **kw).size == V
    monkeypatch.setattr(rm, "MAX_IN_MEMORY_BYTES", V * K + 20 * V - 1)
    with pytest.raises(InputError, match="argument 'store'.*more than the"):
        cell.reach_map(ur5, **kw)
    assert cell.reach_map(ur5, manipulability=False, **kw).manipulability is None
    assert cell.reach_map(ur5, store=tmp_path / "m.zarr", **kw).size == V


@pytest.mark.parametrize(("at", "match"), [
    (math.nan, "got nan"),
    (math.inf, "got inf"),
    ("a", "got 'a'"),
    (True, "got True"),
    (1j, "got 1j"),
    ([0.1, 0.2], r"got \[0.1, 0.2\]"),
])
def test_a_section_needs_a_finite_coordinate(small_map, at, match):
    with pytest.raises(InputError, match=f"argument 'at': expected a finite number, {match}"):
        small_map.section("x", at)
    with pytest.raises(InputError, match="argument 'sections': expected a finite number"):
        small_map.plot_sections(sections=[("z", at)])


def test_section_coordinates_may_be_any_real_number(small_map):
    ref, _ = small_map.section("z", 0.3)
    for at in (np.float32(0.3), np.array(0.3), 0.3):
        np.testing.assert_array_equal(small_map.section("z", at)[0], ref)
    np.testing.assert_array_equal(small_map.section("z", 0)[0], small_map.section("z", 0.0)[0])
    with pytest.raises(InputError, match=r"argument 'sections': expected \(axis, at \[m\]\) "
                       r"pairs, got \('z',\)"):
        small_map.plot_sections(sections=[("z",)])


def test_as_grid_needs_one_value_per_voxel(small_map):
    V = small_map.size
    cube = small_map.as_grid(np.arange(V))
    assert cube.shape == small_map.grid.shape and cube[0, 0, 1] == 1
    assert small_map.as_grid(np.zeros((V, 2))).shape == small_map.grid.shape + (2,)
    for bad, shape in (([1, 2, 3], r"\(3,\)"), (5, r"\(\)"), (np.zeros(V + 1), rf"\({V + 1},\)")):
        with pytest.raises(InputError, match=rf"argument 'values': expected one value per "
                           rf"voxel, shape \({V}, ...\), got shape {shape}"):
            small_map.as_grid(bad)


def test_the_map_agrees_with_the_workspace_volume(ur5):
    # Issue 25: `robokin workspace` and `robokin reach` measure the same set, the
    # position workspace (any orientation). Oracle for the map's voxels: the
    # position-only IK membership test at the very same centres.
    from scipy.spatial import cKDTree

    from robokin.kinematics.workspace import position_reachable, sample_workspace

    ws = sample_workspace(ur5, 200_000, rng=np.random.default_rng(0), keep_q=True,
                          manipulability_samples=0)
    m = cell.reach_map(ur5, voxel=0.1, orientations=32, manipulability=False)
    in_map = np.asarray(m.index) > 0
    seeds = ws.q[cKDTree(ws.points).query(m.centers)[1]]
    reached = position_reachable(ur5, m.centers, seeds=seeds)
    # every centre the map reaches in some orientation is reached by position IK
    assert not (in_map & ~reached).any()
    # the map misses only boundary voxels whose few good orientations fall between
    # its 32 (here 11 of 3,593)
    assert (reached & ~in_map).sum() <= 0.01 * in_map.sum()
    # and its volume (count x voxel^3: midpoint cubature at 100 mm) agrees with the
    # Monte-Carlo estimate to 1 %: 3.582 vs 3.593 +- 0.012 m^3
    assert abs(m.volume() - ws.volume) <= 0.01 * ws.volume


def test_solving_a_task_in_batches_changes_no_bit(ur5, small_map, monkeypatch):
    # a task solves SOLVE_BATCH targets at a time (issue 25: bounded temporaries);
    # batches of 7 targets (rounded to whole voxels) give the same map bit for bit
    import robokin.cell._evaluate as ev

    monkeypatch.setattr(ev, "SOLVE_BATCH", 7)
    again = cell.reach_map(ur5, region=REGION, voxel=0.15, orientations=12, rolls=2,
                           scheduler="synchronous")
    assert_maps_equal(small_map, again)


def test_the_fused_kernel_gives_the_map_of_the_solution_sets(ur5, small_map, monkeypatch):
    # issue 25: the closed form's counts and best manipulability come from one
    # compiled pass (reach.c); the oracle is the unfused path (robot.ik's solution
    # sets, then the manipulability kernel, reduced in numpy): the same map, bit
    # for bit
    import robokin.cell._evaluate as ev

    job = ev.ReachJob(ur5, None, None, small_map.grid, small_map.orientations, False, True)
    assert ev.fused_params(job) is not None
    monkeypatch.setattr(ev, "fused_params", lambda job: None)
    unfused = cell.reach_map(ur5, region=REGION, voxel=0.15, orientations=12, rolls=2,
                             scheduler="synchronous")
    assert_maps_equal(small_map, unfused)
    assert np.asarray(small_map.manipulability).max() > 0
