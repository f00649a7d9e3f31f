"""Maps and placements on a real Dask cluster (``distributed.LocalCluster``, two worker
processes): bit-identical to local runs, and complete when a worker dies mid-run
(issue 16). No mocks: real scheduler, real workers, real kills."""

import os
import signal

import numpy as np
import pytest

import robokin
from robokin import cell
from robokin.exceptions import InputError

distributed = pytest.importorskip("distributed")

REGION = [[-0.6, -0.6, -0.3], [0.6, 0.6, 0.9]]
MAP = dict(region=REGION, voxel=0.15, orientations=12, rolls=2)
FIELDS = ("counts", "index", "solutions", "manipulability")


def assert_same(x, y, what):
    """Equal bit for bit (NaN where NaN)."""
    assert x.dtype == y.dtype and np.array_equal(x, y, equal_nan=x.dtype.kind == "f"), what


@pytest.fixture(scope="module")
def client():
    # not the default client: an address must work without one (as from the CLI)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as lc, \
            distributed.Client(lc, set_as_default=False) as c:
        yield c


@pytest.fixture(scope="module")
def ur5():
    return robokin.load("ur5")


@pytest.fixture(scope="module")
def local_map(ur5):
    return cell.reach_map(ur5, **MAP)


def assert_maps_equal(a, b):
    for f in FIELDS:
        x, y = np.asarray(getattr(a, f)[...]), np.asarray(getattr(b, f)[...])
        assert x.dtype == y.dtype and np.array_equal(x, y), f


@pytest.mark.parametrize("chunk", [13, 64])
def test_a_local_cluster_map_equals_the_local_one_bit_for_bit(ur5, local_map, client, chunk):
    m = cell.reach_map(ur5, scheduler=client, chunk=chunk, **MAP)
    assert_maps_equal(m, local_map)


def test_the_scheduler_can_be_given_by_address(ur5, local_map, client):
    m = cell.reach_map(ur5, scheduler=client.scheduler.address, **MAP)
    assert_maps_equal(m, local_map)


def test_a_cluster_streams_into_a_store(ur5, local_map, client, tmp_path):
    m = cell.reach_map(ur5, scheduler=client, store=tmp_path / "m.zarr", chunk=30, **MAP)
    assert_maps_equal(m, local_map)
    assert_maps_equal(cell.ReachMap.load(tmp_path / "m.zarr"), local_map)


def test_a_worker_killed_mid_run_leaves_the_map_complete_and_equal(ur5, local_map, client):
    killed = []

    def kill_one_worker(done, total):
        if done == 2 and not killed:
            address = sorted(client.scheduler_info()["workers"])[0]
            pid = client.run(os.getpid, workers=[address])[address]
            os.kill(pid, signal.SIGKILL)  # its nanny starts a new one
            killed.append(address)

    m = cell.reach_map(ur5, scheduler=client, chunk=8, progress=kill_one_worker, **MAP)
    assert killed
    assert_maps_equal(m, local_map)
    client.wait_for_workers(2, timeout=60)


def test_a_placement_on_the_cluster_equals_the_local_one(client):
    aubo = robokin.load("aubo_i5")
    task = np.array([aubo.fk(np.radians(q)) for q in
                     ([0, -10, 80, 0, 90, 0], [10, -5, 85, 5, 85, 5], [20, 0, 90, 10, 80, 10])])
    cand = cell.base_grid([-0.1, 0.0, 0.1], [-0.1, 0.0, 0.1], yaw=[0.0, 0.5])
    local = cell.place(aubo, task, cand)
    remote = cell.place(aubo, task, cand, scheduler=client, chunk=4)
    for f in ("feasible", "score", "reachable", "clearance", "manipulability", "branch"):
        assert_same(getattr(local, f), getattr(remote, f), f)
    assert list(local.reason) == list(remote.reason)
    assert local.best_index == remote.best_index


def test_an_unreachable_scheduler_is_an_input_error(ur5, monkeypatch):
    from robokin.cell import _scheduler

    monkeypatch.setattr(_scheduler, "CONNECT_TIMEOUT", 1.0)
    with pytest.raises(InputError, match="argument 'scheduler'.*cannot reach"):
        cell.reach_map(ur5, scheduler="tcp://127.0.0.1:9", **MAP)
