"""Post processors: how long a controller program takes to build, render and read back.

Run: ``python benchmarks/bench_posts.py [--targets 1000] [--rounds 5]``.

For each dialect, a process path of ``--targets`` poses on the UR5 (a joint move to
the start, then linear moves with configuration data) is turned into a program job
(controller joint values, frames, configuration flags: ``program_job``) and
rendered (``post.render``); medians over ``--rounds`` rounds, each round timing
every dialect back to back (the machine is shared). Correctness first: every
program's LIN targets are read back (the KRL .dat by regular expression) and must
equal the poses to the written precision.
"""

from __future__ import annotations

import argparse
import re
import statistics
import time
from dataclasses import dataclass

import numpy as np

import robokin
from robokin.trajectory.posts import get_post, post_names, program_job


@dataclass(frozen=True)
class _Path:
    q: np.ndarray
    feasible: bool = True


def _path(robot: robokin.Robot, n: int) -> _Path:
    """A smooth joint path of ``n`` configurations (its poses are what is written)."""
    s = np.linspace(0.0, 1.0, n)[:, None]
    q0 = np.array([0.3, -1.2, 1.4, -1.8, -1.5, 0.2])
    return _Path(q0 + s * np.array([0.8, 0.3, -0.4, 0.5, 0.2, 1.0]))


def main() -> None:
    """Check, then time every dialect."""
    ap = argparse.ArgumentParser()
    ap.add_argument("--targets", type=int, default=1000)
    ap.add_argument("--rounds", type=int, default=5)
    args = ap.parse_args()
    robot = robokin.load("ur5")
    path = _path(robot, args.targets)
    # correctness: KRL LIN targets are the poses to 1 um
    post = get_post("kuka_krl")
    job = program_job(robot, path, post, name="bench")
    dat = post.render(job)["bench.dat"]
    xyz = np.array([[float(v) for v in m.groups()] for m in re.finditer(
        r"DECL E6POS XP\d+=\{X (\S+),Y (\S+),Z (\S+),", dat)])
    want = robot.fk(path.q[1:])[:, :3, 3] * 1000.0
    err = np.abs(xyz - want).max()
    assert err <= 5e-4 + 1e-9, err
    print(f"check: {len(xyz)} KRL LIN targets within {err * 1000:.2f} um of the poses")
    times: dict[str, dict[str, list[float]]] = {d: {"job": [], "render": []}
                                                for d in post_names()}
    for _ in range(args.rounds):
        for d in post_names():
            p = get_post(d)
            t0 = time.perf_counter()
            job = program_job(robot, path, p, name="bench")
            t1 = time.perf_counter()
            p.render(job)
            t2 = time.perf_counter()
            times[d]["job"].append(t1 - t0)
            times[d]["render"].append(t2 - t1)
    print(f"{args.targets} targets, medians of {args.rounds} rounds [ms] "
          "(job: joint values, frames, flags; render: the text)")
    for d, t in times.items():
        job_ms = statistics.median(t["job"]) * 1000
        render_ms = statistics.median(t["render"]) * 1000
        print(f"  {d:16s} job {job_ms:7.1f}  render {render_ms:7.1f}  "
              f"({args.targets / ((job_ms + render_ms) / 1000):,.0f} targets/s)")


if __name__ == "__main__":
    main()
