"""Per-arm state lives and dies with its arm: robots built in a loop do not leak.

Oracle: the process's resident memory (``/proc/self/statm``) after a warm-up, and a
weak reference to every chain built. Each round builds a new robot with
``with_tool`` (a new chain), solves IK on it (which detects its closed-form family,
packs its parameters and builds its single-pose path, all kept in its ``Arm``) and
computes a small reach map (a batch of IK per voxel and orientation). On ``main``
before the ``Arm`` (caches keyed by ``id(chain)``, solvers closing over the chain)
2,000 such rounds kept every chain alive and grew RSS by 29-33 MB; the bound
here is 5 MB over the issue's 10,000 rounds.

A round costs about 2.6-3.4 ms of CPU (``with_tool`` 0.2 ms, the first IK of a new
chain 0.5 ms, the reach map's Dask round trip the rest), so the 10,000 rounds take
about 30 s of CPU time (RSS +1.6 MB measured). Checked to fail with a leak put
back: a module-level list of the chains (10,000 alive) or of each chain's packed
arrays (3.6 KB a round: RSS +37.6 MB). ``ROBOKIN_LEAK_ROUNDS`` sets another number
of rounds (``docs/conventions.md``, Per-arm state).
"""

import gc
import os
import sys
import weakref

import numpy as np
import pytest

import robokin
from robokin.cell.reach_map import reach_map

ROUNDS = int(os.environ.get("ROBOKIN_LEAK_ROUNDS", "10000"))
WARM_UP = 200
RSS_BOUND_MB = 5.0
REGION = [[0.3, -0.05, 0.3], [0.4, 0.05, 0.4]]  # 8 voxels of 5 cm


def _rss_mb() -> float:
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") / 2**20


def _round(robot, T, i):
    tool = np.eye(4)
    tool[2, 3] = 0.01 + 1e-6 * i  # a new chain every round
    r = robot.with_tool(tool)
    sols = r.ik(T)
    assert sols.valid.any()
    m = reach_map(r, region=REGION, voxel=0.05, orientations=2, manipulability=False)
    assert m.index.shape == (8,)  # 2 x 2 x 2 voxel centres
    return r


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc/self/statm")
def test_robots_built_in_a_loop_are_freed_and_memory_stays_flat():
    robot = robokin.load("ur5")
    T = robot.fk(np.array([0.1, -1.0, 1.2, 0.3, 0.5, -0.2]))
    for i in range(WARM_UP):
        _round(robot, T, i)
    gc.collect()
    before = _rss_mb()
    chains = []
    for i in range(ROUNDS):
        r = _round(robot, T, WARM_UP + i)
        chains.append(weakref.ref(r.chain))
        del r
    # no reference cycle: every chain is already freed by reference counting
    alive_without_gc = sum(c() is not None for c in chains)
    gc.collect()
    grown = _rss_mb() - before
    assert sum(c() is not None for c in chains) == 0
    assert alive_without_gc == 0
    assert grown <= RSS_BOUND_MB, f"RSS grew {grown:.1f} MB over {ROUNDS} rounds"


def test_the_derived_state_is_the_arms_and_goes_with_it():
    # the family, its single-pose path and the seed table are kept in robot.arm;
    # a robot of another tool has its own; dropping the robot frees them
    from robokin.kinematics.ik.analytic.detect import FAMILY
    from robokin.kinematics.ik.restart_seeds import SEED_TABLE, seed_table

    robot = robokin.load("ur5").with_tool(np.eye(4))
    T = robot.fk(np.zeros(6))
    assert FAMILY not in robot.arm.state and SEED_TABLE not in robot.arm.state
    robot.ik(T)
    tab = seed_table(robot)
    fam = robot.arm.state[FAMILY]
    assert fam.single is not None and robot.arm.state[SEED_TABLE] is tab
    assert seed_table(robot) is tab and robokin.ik.family(robot) is fam
    other = robot.with_tool(np.eye(4))
    other.ik(T)
    assert other.arm.derived(FAMILY) is not fam
    ref = weakref.ref(fam)
    del robot, fam, tab
    assert ref() is None


def test_a_kind_of_derived_state_is_built_once_per_arm():
    # oracle: a counting build function; the value is kept per Arm, not shared
    from robokin.kinematics.arm import Arm, Derived

    calls = []

    def build(arm):
        calls.append(arm)
        return [arm.n]

    kind = Derived("test state", build)
    chain = robokin.load("ur5").chain
    a, b = Arm(chain), Arm(chain)
    first = a.derived(kind)
    assert a.derived(kind) is first and calls == [a]
    assert b.derived(kind) is not first and calls == [a, b]
    assert a.state == {kind: [6]} and repr(kind) == "Derived('test state')"
