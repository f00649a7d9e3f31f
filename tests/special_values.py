"""Configurations where users put arms, and the oracles that judge IK there (issue 23).

Joints are drawn from the values users hit (0, +-pi/2, pi, offsets of 1e-9, 1e-7
and 1e-6 from a wrist or elbow singularity, the limits) as often as from a uniform
range: home and ready poses, a straight wrist, a stretched elbow. Prismatic joints
take their limits, the middle of their stroke or a uniform value.

The oracles use only numpy and robokin's forward kinematics / Jacobian (whose own
tests check them against independent references):

* ``sigma_min``: the smallest singular value of the Jacobian with its position rows
  divided by the arm's size (numpy's SVD): the measure that classes a configuration
  as singular or not, independent of the arm's scale;
* ``pose_error``: position [m] and rotation [rad] error of FK against a target;
* ``angle_gap``: joint differences, angles compared modulo 2 pi.
"""

from __future__ import annotations

import math

import numpy as np
from hypothesis import strategies as st

SPECIAL_ANGLES = (0.0, math.pi / 2, -math.pi / 2, math.pi, 1e-9, -1e-9, 1e-7, -1e-7,
                  1e-6, -1e-6)


def arm_size(robot) -> float:
    """Sum of the distances between consecutive joint frames and the tool at zero [m]."""
    F = robot.fk_all(np.zeros(robot.n))
    p = np.concatenate([F[:, :3, 3], robot.fk(np.zeros(robot.n))[None, :3, 3]])
    return float(np.linalg.norm(np.diff(p, axis=0), axis=1).sum())


def _joint(lo: float, hi: float, revolute: bool) -> st.SearchStrategy[float]:
    if revolute:
        special = st.sampled_from(SPECIAL_ANGLES + (lo, hi))
        uniform = st.floats(max(lo, -math.pi), min(hi, math.pi))
    else:
        special = st.sampled_from((lo, hi, 0.5 * (lo + hi), lo + 1e-9, hi - 1e-9))
        uniform = st.floats(lo, hi)
    return st.one_of(special, uniform)


def configurations(robot) -> st.SearchStrategy[np.ndarray]:
    """Hypothesis strategy: one configuration (n,), each joint special or uniform."""
    lim = robot.limits
    joints = [_joint(float(lim[j, 0]), float(lim[j, 1]), bool(robot.is_revolute[j]))
              for j in range(robot.n)]
    return st.tuples(*joints).map(lambda t: np.array(t, dtype=np.float64))


def draw_configurations(robot, rng: np.random.Generator, size: int) -> np.ndarray:
    """The same distribution as ``configurations`` for a batch (size, n), numpy only."""
    lim = robot.limits
    q = np.empty((size, robot.n))
    for j in range(robot.n):
        lo, hi = lim[j]
        if robot.is_revolute[j]:
            special = np.array(SPECIAL_ANGLES + (lo, hi))
            uniform = rng.uniform(max(lo, -math.pi), min(hi, math.pi), size)
        else:
            special = np.array([lo, hi, 0.5 * (lo + hi), lo + 1e-9, hi - 1e-9])
            uniform = rng.uniform(lo, hi, size)
        pick = rng.random(size) < 0.5
        q[:, j] = np.where(pick, special[rng.integers(0, len(special), size)], uniform)
    return q


def sigma_min(robot, q: np.ndarray) -> np.ndarray:
    """Smallest singular value of the scale-free Jacobian (position rows / size), (...)."""
    J = robot.jacobian(q).copy()
    J[..., :3, :] /= arm_size(robot)
    return np.linalg.svd(J, compute_uv=False)[..., -1]


def pose_error(robot, q: np.ndarray, T: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Position [m] and rotation angle [rad] between FK(q) (..., n) and T (..., 4, 4)."""
    F = robot.fk(q)
    dp = np.linalg.norm(F[..., :3, 3] - T[..., :3, 3], axis=-1)
    R = np.swapaxes(F[..., :3, :3], -1, -2) @ T[..., :3, :3]
    c = np.clip((np.trace(R, axis1=-2, axis2=-1) - 1) / 2, -1, 1)
    s = np.linalg.norm(np.stack([R[..., 2, 1] - R[..., 1, 2], R[..., 0, 2] - R[..., 2, 0],
                                 R[..., 1, 0] - R[..., 0, 1]], -1), axis=-1) / 2
    return dp, np.arctan2(s, c)


def angle_gap(robot, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """|a - b| per joint, revolute joints modulo 2 pi (..., n)."""
    d = a - b
    return np.abs(np.where(robot.is_revolute, (d + np.pi) % (2 * np.pi) - np.pi, d))


def inside_limits(robot, q: np.ndarray) -> np.ndarray:
    """Every joint within its limits (the 1e-9 slack ``within_limits`` uses), (...)."""
    lim = robot.limits
    return ((q >= lim[:, 0] - 1e-9) & (q <= lim[:, 1] + 1e-9)).all(axis=-1)
