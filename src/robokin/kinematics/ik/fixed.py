"""IK with some joints given: every solution of the remaining chain.

A 7R arm such as the Panda has infinitely many solutions for a pose; with one joint
held at a chosen value the remaining 6R chain has finitely many, and the general 6R
solver finds them all. ``robot.ik(T, fixed={"joint7": 0.3})`` does that; an array
of values (broadcasting with the poses) sweeps the redundancy parameter, e.g. the
self-motion manifold of one pose as a batch.

When the held joint is the first or the last of a chain without dependent joints,
the remaining chain does not depend on its value: one reduced chain (value 0)
serves every value, the targets moving instead
(``T' = T C_n^{-1} J(-s v) C_n`` for the last joint, ``C_0 J(-s v) C_0^{-1} T`` for
the first). Otherwise each distinct value gets its own reduced chain (cached).
"""

from __future__ import annotations

from collections import OrderedDict
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from robokin._validation import (
    _real_array,
    check_broadcasts,
    check_finite,
    check_joints,
    check_poses_fast,
)
from robokin.exceptions import InputError
from robokin.kinematics.ik.solutions import SolutionSet
from robokin.kinematics.per_chain import cached
from robokin.model.chain import joint_motion
from robokin.spatial import invert

if TYPE_CHECKING:
    from robokin.kinematics.robot_like import RobotLike

__all__ = ["solve_fixed"]


def solve_fixed(
    robot: RobotLike,
    T: npt.ArrayLike,
    fixed: Mapping[str, npt.ArrayLike],
    *,
    q_near: npt.ArrayLike | None = None,
    method: str = "auto",
    **options: Any,
) -> SolutionSet:
    """Every solution for poses ``T`` with the joints named in ``fixed`` held.

    Args:
        robot: The :class:`~robokin.robot.Robot`.
        T: Target poses (..., 4, 4) [m].
        fixed: Joint name -> value [rad or m]: a number, or an array broadcasting
            with the poses' leading shape (a sweep).
        q_near: Current configuration (..., n) of the whole arm, optional.
        method: As in ``Robot.ik``, for the remaining chain.
        **options: Passed to the solver of the remaining chain.

    Returns:
        A :class:`SolutionSet` of the whole arm (the held joints' columns hold their
        values), of the poses and values' broadcast leading shape; ``method`` says
        what solved the remaining chain and which joints were held.

    Raises:
        InputError: an unknown joint name (the message lists them), a non-finite
            value, values that do not broadcast with the poses, or every joint held.
    """
    names = list(robot.joint_names)
    if not isinstance(fixed, Mapping) or not fixed:
        raise InputError("fixed", f"expected a mapping of joint names to values, e.g. "
                                  f"{{{names[-1]!r}: 0.0}}, got {fixed!r:.60}")
    idx = []
    for name in fixed:
        if name not in names:
            raise InputError("fixed", f"unknown joint {name!r}; joints: {', '.join(names)}")
        idx.append(names.index(name))
    if len(idx) == robot.n:
        raise InputError("fixed", "every joint is held: nothing left to solve for")
    T = check_poses_fast(T, "T")
    values = [check_finite(_real_array(v, f"fixed[{name!r}]", "a number or numbers"),
                           f"fixed[{name!r}]") for name, v in fixed.items()]
    try:
        lead = np.broadcast_shapes(T.shape[:-2], *(v.shape for v in values))
    except ValueError as exc:
        raise InputError("fixed", f"value shapes {[v.shape for v in values]} do not "
                                  f"broadcast with the poses' {T.shape[:-2]}") from exc
    Tb = np.broadcast_to(T, lead + (4, 4)).reshape(-1, 4, 4)
    V = np.stack([np.broadcast_to(v, lead).ravel() for v in values], axis=-1)  # (N, f)
    keep = [j for j in range(robot.n) if j not in idx]
    qn = None
    if q_near is not None:
        qc = check_finite(check_joints(q_near, robot.n, "q_near"), "q_near")
        check_broadcasts(qc, lead + (robot.n,), "q_near", "the poses' and values'")
        qn = np.broadcast_to(qc, lead + (robot.n,)).reshape(-1, robot.n)[:, keep]
    end = _end_joint(robot, idx)
    if end is not None:
        reduced = _reduced(robot, idx, (0.0,))
        Tm = _moved_targets(robot, end, Tb, V[:, 0])
        sols = reduced.ik(Tm, q_near=qn, method=method, **options)
        parts = [(np.arange(len(Tb)), sols)]
    else:
        parts = []
        uniq, inverse = np.unique(V, axis=0, return_inverse=True)
        for g, vals in enumerate(uniq):
            rows = np.flatnonzero(inverse.ravel() == g)
            reduced = _reduced(robot, idx, tuple(float(x) for x in vals))
            sols = reduced.ik(Tb[rows], q_near=None if qn is None else qn[rows],
                              method=method, **options)
            parts.append((rows, sols))
    return _assemble(robot, lead, idx, keep, V, parts, dict(zip(fixed, values)))


def _end_joint(robot: RobotLike, idx: list[int]) -> str | None:
    """"first" / "last" when one held coordinate is the chain's first / last joint."""
    chain = robot.chain
    if len(idx) != 1 or not chain.coupling.is_identity:
        return None
    if idx[0] == chain.n - 1:
        return "last"
    if idx[0] == 0:
        return "first"
    return None


def _moved_targets(robot: RobotLike, end: str, T: np.ndarray, v: np.ndarray) -> np.ndarray:
    """The targets of the reduced chain (held value 0) that equal T at value v."""
    C = robot.chain.arrays.consts
    if end == "last":
        j = robot.n - 1
        Cn = C[-1]
        return T @ invert(Cn) @ joint_motion(robot.chain.joints[j].kind, -robot.chain.joints[j].sign * v) @ Cn
    C0 = C[0]
    return C0 @ joint_motion(robot.chain.joints[0].kind, -robot.chain.joints[0].sign * v) @ invert(C0) @ T


#: Reduced robots kept per chain: a sweep of a middle joint builds one per value
#: (a general-6R set-up each); the most recently used ones are kept, not all.
_REDUCED_KEPT = 16


def _reduced(robot: RobotLike, idx: list[int], values: tuple[float, ...]) -> Any:
    """The robot of the remaining coordinates (the last few kept per chain)."""
    key = (tuple(idx), values)
    kept: OrderedDict[Any, Any] = cached(robot.chain, "fixed", OrderedDict)
    if key in kept:
        kept.move_to_end(key)
        return kept[key]

    def build() -> Any:
        held = ", ".join(f"{robot.joint_names[j]}={v:g}" for j, v in zip(idx, values,
                                                                          strict=True))
        chain = robot.chain.with_fixed(dict(zip(idx, values, strict=True)))
        # a bare robot of the same class: the chain and a name, nothing per link or
        # per joint of the whole arm (geometry, actuators, dynamics, rate limits)
        make: Any = type(robot)
        return make(chain, name=f"{robot.name} ({held} held)")

    value = kept[key] = build()
    while len(kept) > _REDUCED_KEPT:
        kept.popitem(last=False)
    return value


def _assemble(robot: RobotLike, lead: tuple[int, ...], idx: list[int], keep: list[int],
              V: np.ndarray, parts: list[tuple[np.ndarray, SolutionSet]],
              fixed: dict[str, np.ndarray]) -> SolutionSet:
    N = V.shape[0]
    k = max((s.q.shape[-2] for _, s in parts), default=0)
    n = robot.n
    q = np.full((N, k, n), np.nan)
    valid = np.zeros((N, k), dtype=bool)
    singular = np.zeros((N, k), dtype=bool)
    status = np.empty(N, dtype=object)
    methods = set()
    for rows, s in parts:
        kk = s.q.shape[-2]
        sq = s.q.reshape(-1, kk, len(keep))
        q[rows[:, None, None], np.arange(kk)[None, :, None], np.array(keep)] = sq
        for c, j in enumerate(idx):
            q[rows, :kk, j] = V[rows, c][:, None]
        valid[rows, :kk] = s.valid.reshape(-1, kk)
        singular[rows, :kk] = s.singular.reshape(-1, kk)
        status[rows] = s.status.reshape(-1)
        methods.add(s.method)
    held = ", ".join(fixed)
    method = f"{'/'.join(sorted(methods))} ({held} held)"
    return SolutionSet(
        q.reshape(lead + (k, n)), valid.reshape(lead + (k,)), robot.is_revolute,
        robot.limits, flags={"singular": singular.reshape(lead + (k,))},
        status=status.reshape(lead), method=method,
        info={"held": {name: v for name, v in fixed.items()}},
    )
