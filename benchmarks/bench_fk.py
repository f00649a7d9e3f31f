"""Forward kinematics: robokin vs pinocchio vs roboticstoolbox-python, in one run.

Run: ``python benchmarks/bench_fk.py`` (needs ``pip install -e '.[bench]'``).
Checks all three agree to 1e-9 on the same configurations, then times single-
configuration latency (median of many calls, validation included) and batch
throughput on 100,000 configurations. Prints a table with ratios.
"""

from __future__ import annotations

import statistics
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))

from peers import pinocchio_model, rtb_ets  # noqa: E402

import robokin  # noqa: E402
import robokin._native  # noqa: E402
from robokin._native import _base  # noqa: E402


def _median_call(fn, repeats=2000, inner=20):
    samples = []
    for _ in range(repeats // inner):
        t = time.perf_counter()
        for _ in range(inner):
            fn()
        samples.append((time.perf_counter() - t) / inner)
    return statistics.median(samples)


def _median_kernel(robot, q, copy=None):
    """The compiled single-configuration FK call alone (no argument checks).

    ``copy`` None: the copy robot.fk(q) uses; otherwise the baseline (non-AVX2) one.
    """
    from robokin import _native

    kernels = _native.single if copy is None else copy
    packed = robot.chain.arrays.packed
    return _median_call(lambda: kernels.fk1(q, packed))


def _best(fn, repeats=3):
    best = np.inf
    for _ in range(repeats):
        t = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t)
    return best


def main(n_batch: int = 100_000) -> None:
    import pinocchio as pin

    rng = np.random.default_rng(0)
    rows = []
    for name in ("ur5", "panda"):
        robot = robokin.load(name)
        lim = np.clip(robot.limits, -np.pi, np.pi)
        Q = rng.uniform(lim[:, 0], lim[:, 1], (n_batch, robot.n))
        ets = rtb_ets(robot)
        model, data, fid = pinocchio_model(robot)

        def pin_pose(q):
            pin.forwardKinematics(model, data, q)
            return pin.updateFramePlacement(model, data, fid).homogeneous

        # agreement first
        ours = robot.fk(Q[:200])
        np.testing.assert_allclose(ets.eval(Q[:200]), ours, atol=1e-9)
        np.testing.assert_allclose(
            np.array([pin_pose(q) for q in Q[:200]]), ours, atol=1e-9
        )

        q0 = Q[0].copy()
        robot.fk(q0)
        single = {
            "robokin fk(q)": _median_call(lambda: robot.fk(q0)),
            "robokin kernel call alone": _median_kernel(robot, q0),
            "robokin kernel call alone, baseline copy": _median_kernel(
                robot, q0, _base
            ),
            "pinocchio forwardKinematics+frame": _median_call(lambda: pin_pose(q0)),
            "pinocchio forwardKinematics only": _median_call(
                lambda: pin.forwardKinematics(model, data, q0)
            ),
            "rtb ets.eval(q)": _median_call(lambda: ets.eval(q0)),
        }
        robot.fk(Q[:5000])
        threads = robokin._native.num_threads()
        robokin._native.set_num_threads(1)
        one_thread = _best(lambda: robot.fk(Q))
        robokin._native.set_num_threads(threads)
        batch = {
            "robokin fk(Q) batch": _best(lambda: robot.fk(Q)),
            "robokin fk(Q) batch, one thread": one_thread,
            "pinocchio loop": _best(lambda: [pin_pose(q) for q in Q], repeats=1),
            "rtb ets.eval(Q) batch": _best(lambda: ets.eval(Q)),
        }
        for k, v in single.items():
            rows.append(
                (
                    name,
                    "single",
                    k,
                    v * 1e6,
                    "us/call",
                    single["robokin fk(q)"] and v / single["robokin fk(q)"],
                )
            )
        for k, v in batch.items():
            rows.append(
                (
                    name,
                    f"batch {n_batch}",
                    k,
                    n_batch / v / 1e6,
                    "M configs/s",
                    batch[k] and v / batch["robokin fk(Q) batch"],
                )
            )
    print(
        f"{'robot':6} {'case':13} {'library':42} {'value':>10} {'unit':12} {'robokin x':>9}"
    )
    for r in rows:
        print(f"{r[0]:6} {r[1]:13} {r[2]:42} {r[3]:10.3f} {r[4]:12} {r[5]:9.2f}")
    print("('robokin x' = how many times faster robokin is; time ratio peer / robokin)")


if __name__ == "__main__":
    main()
