"""IK with some joints given: every solution of the remaining chain.

A 7R arm such as the Panda has infinitely many solutions for a pose; with one joint
held at a chosen value the remaining 6R chain has finitely many.
``robot.ik(T, fixed={"joint7": 0.3})`` finds them all; an array of values
(broadcasting with the poses) sweeps the redundancy parameter, e.g. the self-motion
manifold of one pose as a batch.

When three consecutive axes of the six joints left meet in a point (the Panda with
joint 4, 5, 6 or 7 held, an SRS arm with any joint held: with the elbow held
both triples meet and the six joints move in a swivel family) the
``pieper`` closed form solves them (``analytic/pieper.py``): its compiled kernel
takes the held value with each pose and builds the remaining chain itself, so one
set-up per (chain, held joint) serves every value, and a single pose with a number
held takes a hot path (one compiled call). Otherwise the remaining chain is built
and solved by ``Robot.ik`` (the general 6R solver for a 6R chain):

When the held joint is the first or the last of a chain without dependent joints,
the remaining chain does not depend on its value: one reduced chain (value 0)
serves every value, the targets moving instead
(``T' = T C_n^{-1} J(-s v) C_n`` for the last joint, ``C_0 J(-s v) C_0^{-1} T`` for
the first). Otherwise each distinct value gets its own reduced chain (cached).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np
import numpy.typing as npt

from robokin import _native
from robokin._validation import (
    _real_array,
    check_broadcasts,
    check_finite,
    check_joints,
    check_rigid,
)
from robokin.exceptions import InputError
from robokin.kinematics.arm import Arm, ArmSource, Derived, arm_of
from robokin.kinematics.ik import coincident as _co
from robokin.kinematics.ik import near_coincident as _nco
from robokin.kinematics.ik.analytic import general_6r as _g6
from robokin.kinematics.ik.analytic import pieper as _pk
from robokin.kinematics.ik.analytic._common import STATUS_TEXT
from robokin.kinematics.ik.analytic.detect import FAMILY
from robokin.kinematics.ik.solutions import SolutionSet
from robokin.model.chain import joint_motion
from robokin.spatial import invert, wrap_angle

__all__ = ["held_complete", "solve_fixed", "sweep_end"]


def solve_fixed(
    robot: ArmSource,
    T: npt.ArrayLike,
    fixed: Mapping[str, npt.ArrayLike],
    *,
    dispatch: Dispatch,
    q_near: npt.ArrayLike | None = None,
    method: str = "auto",
    **options: Any,
) -> SolutionSet:
    """Every solution for poses ``T`` with the joints named in ``fixed`` held.

    Args:
        robot: The arm (an :class:`~robokin.kinematics.arm.Arm` or a Robot).
        T: Target poses (..., 4, 4) [m].
        fixed: Joint name -> value [rad or m]: a number, or an array broadcasting
            with the poses' leading shape (a sweep).
        dispatch: ``dispatch.solve``: solves the remaining chain.
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
    robot = arm_of(robot)
    if q_near is None and not options and method != "numeric":
        out = solve_held_single(robot, T, fixed)
        if out is not None:
            return out
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
    T = check_rigid(T, "T")  # the held closed form needs a rigid pose
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
    held = _held_solvers(robot).get(next(iter(fixed))) if len(idx) == 1 else None
    if held is not None and method != "numeric" and set(options) <= {"compute_error"}:
        qf = None if q_near is None else np.broadcast_to(qc, lead + (robot.n,))
        return held.solve(robot, Tb.reshape(lead + (4, 4)), qf, V[:, 0].reshape(lead),
                          **options)
    parts: list[tuple[np.ndarray, SolutionSet]] = []
    rest = np.arange(len(Tb))
    if len(idx) == 1 and method != "numeric" and not options:
        qf = None if q_near is None else np.broadcast_to(qc, lead + (robot.n,)).reshape(
            -1, robot.n)
        rest = _coincident_parts(robot, idx[0], Tb, V[:, 0], qf, keep, dispatch, parts)
    end = _end_joint(robot, idx)
    if end is not None and len(rest):
        reduced = _reduced(robot, idx, (0.0,))
        Tm = _moved_targets(robot, end, Tb[rest], V[rest, 0])
        sols = dispatch(reduced, Tm, q_near=None if qn is None else qn[rest],
                        method=method, **options)
        parts.append((rest, sols))
    elif len(rest):
        uniq, inverse = np.unique(V[rest], axis=0, return_inverse=True)
        for g, vals in enumerate(uniq):
            rows = rest[np.flatnonzero(inverse.ravel() == g)]
            reduced = _reduced(robot, idx, tuple(float(x) for x in vals))
            sols = dispatch(reduced, Tb[rows], q_near=None if qn is None else qn[rows],
                            method=method, **options)
            parts.append((rows, sols))
    out = _assemble(robot, lead, idx, keep, V, parts, dict(zip(fixed, values)))
    if len(idx) == 1 and method != "numeric" and not options:
        out = _into_limits(robot, idx[0], Tb, V[:, 0], out)
    return out


#: [rad, m] A held middle joint's value that puts no two axes on one line (generic).
_GENERIC = 0.6180339887498949


def held_complete(robot: Arm, j: int) -> bool:
    """True when :func:`solve_fixed` with joint j held returns every solution.

    A held-joint closed form, or a remaining chain with a closed form or the general
    6R solver; False where the numeric solver samples it (two prismatic joints
    left). An end joint's chain is the same for every value (solved at 0, the value
    moved into the target); a middle joint's is judged at a generic value (at 0 the
    Panda's joint 2 puts axes 1 and 3 on one line: no 6R solver there).
    """
    if robot.joint_names[j] in _held_solvers(robot):
        return True
    value = 0.0 if _end_joint(robot, [j]) is not None else _GENERIC
    return _reduced(robot, [j], (value,)).derived(FAMILY).solver is not None


def solve_held_single(robot: Arm, T: object, fixed: object) -> SolutionSet | None:
    """The hot path of ``robot.ik(T, fixed={name: x})``: one pose, one joint at a number.

    One compiled call (it checks T's type, shape and rigidity, and that the value is
    finite) where the arm has a closed form with that joint held; no copy of the
    arguments, no ``q_near``, default options (the caller checks those).

    Args:
        robot: The arm.
        T: The pose (4, 4) [m], if it is one.
        fixed: ``{joint name: value}`` [rad], if it is one.

    Returns:
        The set, or None where this path does not apply (anything else: not a
        float64 (4, 4) rigid pose, a value that is not a finite number, a joint
        without a held closed form; or no solution for a rotation off SO(3) by
        rounding, which :func:`solve_fixed` projects and solves): the caller then
        takes :func:`solve_fixed`, which raises the detailed error.
    """
    if type(fixed) is not dict or len(fixed) != 1 or type(T) is not np.ndarray:
        return None
    ((name, value),) = fixed.items()
    if type(value) not in _NUMBERS:
        return None
    held = robot.derived(HELD_SOLVERS).get(name)
    out: SolutionSet | None
    if held is not None:
        out = held.single(T, value, None)
    else:  # next to aligned axes, else a held end joint without a closed form
        out = _near_single(robot, T, name, float(value))
        if out is None:
            out = _end_single(robot, T, name, float(value))
        if out is not None and T.shape == (4, 4) and T.dtype == np.float64:
            out = _into_limits(robot, robot.derived(JOINT_INDEX)[name], T,
                               np.array([float(value)]), out)
    # "ok" has rows (read first: counting them costs a numpy reduction); no row for a
    # rotation off SO(3) by rounding: None, and solve_fixed projects it and solves
    if out is not None and (out.status.item() == "ok" or len(out)
                            or check_rigid(T, "T") is T):
        return out
    return None


def _end_single(robot: Arm, T: np.ndarray, name: str, value: float) -> SolutionSet | None:
    """The first or last joint at a number, no held closed form: one compiled call.

    The reduced chain (the joint at 0) solved at the moved target by its own
    single-pose hot path (``FAMILY.single``: the general 6R solver on a general 7R
    arm; issue 29) and the held column put in: the set ``solve_fixed`` assembles,
    without its per-call validation and batching (~210 -> ~80 us per call, the
    kernel ~40-45 of it). None where this does not apply (a middle joint, a value
    putting two axes on one line, a pose that is not float64 (4, 4), a non-finite
    value, a reduced chain without a single-pose path).
    """
    if T.shape != (4, 4) or T.dtype != np.float64 or not math.isfinite(value):
        return None
    table = robot.derived(END_HELD)
    if name not in table:
        table[name] = _end_held(robot, name)
    e = table[name]
    if e is None:  # (an end joint puts no pair on one line: no coincident path)
        return None
    Tm = _move(T, value, e.last, e.C, e.C_inv, e.kind, e.sign)
    sub = e.single(Tm, np.nan)
    if sub is None:
        return None
    k, j = sub.q.shape[0], e.j
    q = np.empty((k, robot.n))
    q[:, :j], q[:, j], q[:, j + 1:] = sub.q[:, :j], value, sub.q[:, j:]
    q[~sub.valid] = np.nan  # as SolutionSet does with rows that are not valid
    inside = sub.flags["within_limits"] & (e.lo - 1e-9 <= value <= e.hi + 1e-9)
    return SolutionSet._trusted(
        q, sub.valid, e.is_revolute, robot.limits,
        {"singular": sub.flags["singular"], "within_limits": inside}, {}, sub.status,
        f"{sub.method} ({name} held)", None, {"held": {name: np.array(value)}})


@dataclass(frozen=True, eq=False)
class EndHeld:
    """The first or last joint held, solved by the reduced chain's single-pose path.

    Attributes:
        j: The joint's index.
        last: True for the last joint (the target moves on the right), else the first.
        single: The reduced chain's ``FAMILY.single`` (the joint at 0).
        C, C_inv: The chain's constant next to the joint (``consts[-1]`` / ``[0]``)
            and its inverse (4, 4).
        kind: The joint's kind; sign: its chain sign.
        lo, hi: Its limits.
        is_revolute: The arm's ``is_revolute`` (n,), read-only (every set shares it).
    """

    j: int
    last: bool
    single: Any
    C: np.ndarray
    C_inv: np.ndarray
    kind: Any
    sign: float
    lo: float
    hi: float
    is_revolute: np.ndarray


def _end_held(robot: Arm, name: str) -> EndHeld | None:
    """:class:`EndHeld` of joint ``name``, or None (not an end joint, no single path)."""
    names = robot.joint_names
    if name not in names:
        return None
    j = names.index(name)
    end = _end_joint(robot, [j])
    if end is None:
        return None
    single = _reduced(robot, [j], (0.0,)).derived(FAMILY).single
    if single is None:
        return None
    C = robot.chain.arrays.consts[-1 if end == "last" else 0]
    joint = robot.chain.joints[j]
    lo, hi = (float(x) for x in robot.limits[j])
    is_rev = np.array(robot.is_revolute, dtype=bool)
    is_rev.setflags(write=False)
    return EndHeld(j, end == "last", single, np.array(C), invert(C), joint.kind,
                   float(joint.sign), lo, hi, is_rev)


#: Per arm: joint name -> its index (``Arm.joint_names`` builds its tuple per call).
JOINT_INDEX: Derived[dict[str, int]] = Derived(
    "joint indices", lambda arm: {n: i for i, n in enumerate(arm.joint_names)})


#: Per arm: joint name -> :class:`EndHeld` (or None), filled on first use of each.
END_HELD: Derived[dict[str, EndHeld | None]] = Derived("end-joint held solvers",
                                                       lambda arm: {})


#: Per arm: held joint index -> ``pieper.limit_params`` (or None), filled on first use
LIMIT_PARAMS: Derived[dict[int, np.ndarray | None]] = Derived("held-joint limit params",
                                                              lambda arm: {})


#: Rows per pose ``pieper_limit_rows`` takes (its argument check).
_LIMIT_ROWS = 1024


def _into_limits(robot: Arm, j: int, T: np.ndarray, x: np.ndarray,
                 sols: SolutionSet) -> SolutionSet:
    """Singular rows of a held 7R arm moved into the limits where no row is inside.

    The general 6R path (and ``coincident``/``near_coincident``) returns exact rows
    on a one-parameter family next to a singular configuration; the one it finds
    can lie just past a limit (1e-8 to 1e-5 rad: the Panda with joint 1, 2 or 3
    held, a joint at its limit and q5 or q2 at 1e-6) while other members are inside.
    The held closed form's last resorts (``pieper_limit_rows``: ``pk_walk`` along
    the family, else ``pk_pin`` at the limit passed) move them, exactly (4e-13).
    Only poses with a valid singular row and no valid in-limit row are touched.

    Args:
        robot: The arm (7R).
        j: The held joint's index.
        T: The poses (N, 4, 4) [m], as ``sols``'s leading shape flattened.
        x: The held values (N,) [rad].
        sols: The assembled set (leading shape flattening to N).

    Returns:
        ``sols``, or a new set with those rows and their ``within_limits`` updated.
    """
    valid = sols.valid
    inside = sols.within_limits
    need = (valid & sols.singular).any(axis=-1) & ~inside.any(axis=-1)
    if not need.any() or robot.n != 7:
        return sols
    table = robot.derived(LIMIT_PARAMS)
    if j not in table:
        table[j] = _pk.limit_params(robot.chain, j)
    P = table[j]
    if P is None:
        return sols
    k = valid.shape[-1]
    rows = np.flatnonzero(need.reshape(-1))
    q = np.array(sols.q, dtype=np.float64).reshape(-1, k, 7)
    within = np.array(inside).reshape(-1, k)
    Tr = np.ascontiguousarray(T.reshape(-1, 4, 4)[rows])
    xr = np.ascontiguousarray(x.reshape(-1)[rows], dtype=np.float64)
    # the kernel takes at most _LIMIT_ROWS rows a pose (the near-coincident path can
    # return ~80): in column blocks, each walked while none of its rows is inside
    for c in range(0, k, _LIMIT_ROWS):
        cols = slice(c, min(c + _LIMIT_ROWS, k))
        Q = np.ascontiguousarray(q[rows, cols])
        ins = np.ascontiguousarray(within[rows, cols])
        _native.kernels.pieper_limit_rows(
            P, Tr, xr, Q, np.ascontiguousarray(valid.reshape(-1, k)[rows, cols]),
            np.ascontiguousarray(sols.singular.reshape(-1, k)[rows, cols]), ins)
        q[rows, cols], within[rows, cols] = Q, ins
    flags = dict(sols.flags)
    flags["within_limits"] = within.reshape(valid.shape)
    return SolutionSet._trusted(q.reshape(sols.q.shape), valid, sols.is_revolute, sols.limits,
                                flags, sols.branches, sols.status, sols.method, sols.error,
                                sols.info)


def _coincident_parts(robot: Arm, j: int, T: np.ndarray, v: np.ndarray,
                      q_near: np.ndarray | None, keep: list[int], dispatch: Dispatch,
                      parts: list[tuple[np.ndarray, SolutionSet]]) -> np.ndarray:
    """Solve the poses whose held value puts two axes on one line (``coincident``).

    Appends (rows, set of the remaining coordinates) to ``parts`` per such value;
    returns the rows left for the other paths.
    """
    if not 0 < j < robot.n - 1:  # an end joint puts no pair on one line (coincident_pair)
        return np.arange(len(T))
    uniq, inverse = np.unique(v, return_inverse=True)
    rest = np.ones(len(T), bool)
    name = robot.joint_names
    for g, x in enumerate(uniq):
        pair = _co.coincident_pair(robot, j, float(x))
        near = None if pair is not None else _nco.near_coincident_pair(robot, j, float(x))
        if pair is None and near is None:
            continue
        rows = np.flatnonzero(inverse.ravel() == g)

        def helper(a: int, c: float, Ts: np.ndarray) -> SolutionSet:
            fast = _end_general_6r(robot, a, c, Ts)
            return fast if fast is not None else solve_fixed(robot, Ts, {name[a]: c},
                                                             dispatch=dispatch)

        if near is not None:  # next to aligned: exact rows from the aligned families
            sols = _nco.solve_near_coincident(robot, T[rows], near[0], near[1], float(x),
                                              helper)
        else:
            assert pair is not None
            sols = _co.solve_coincident(robot, T[rows], pair, float(x),
                                        None if q_near is None else q_near[rows], helper)
        parts.append((rows, SolutionSet(
            sols.q[..., keep], sols.valid, robot.is_revolute[keep], robot.limits[keep],
            flags={"singular": sols.singular}, status=sols.status, method=sols.method)))
        rest[rows] = False
    return np.flatnonzero(rest)


def _end_general_6r(robot: Arm, a: int, c: float, T: np.ndarray) -> SolutionSet | None:
    """``solve_fixed(robot, T, {joint a: c})`` by the compiled general 6R solver directly.

    Where joint ``a`` is an end joint without a held closed form and the reduced
    chain's family is general 6R, the path :func:`solve_fixed` takes (moved
    targets, one reduced chain), the same rows, without its checks and two set
    assemblies: the coincident paths' helper problems (two per call, ~0.3 ms of
    overhead each through ``solve_fixed``). None where that path does not apply.

    Args:
        robot: The arm.
        a: The held joint's index.
        c: Its value [rad].
        T: Validated poses (N, 4, 4) [m].
    """
    end = _end_joint(robot, [a])
    name = robot.joint_names[a]
    if end is None or _held_solvers(robot).get(name) is not None:
        return None
    reduced = _reduced(robot, [a], (0.0,))
    params = _g6.setup(reduced).params if reduced.derived(FAMILY).name == _g6.NAME else None
    if params is None:
        return None
    Tm = np.ascontiguousarray(_moved_targets(robot, end, T, np.full(len(T), c)))
    Q, valid, _, sigma, status, _, _ = _g6.raw_solve(reduced.chain, params, Tm)
    q = np.empty(Q.shape[:-1] + (robot.n,))
    q[..., [j for j in range(robot.n) if j != a]] = Q
    q[..., a] = c
    return SolutionSet._trusted(
        q, valid, robot.is_revolute, robot.limits,
        {"singular": (sigma < 1e-6) & valid}, {},
        np.asarray(STATUS_TEXT[_g6._STATUS[status]], dtype=object),
        f"{_g6.NAME} ({name} held)", None, {"held": {name: np.full(len(T), c)}})


def solve_held_one(robot: Arm, T: np.ndarray, j: int, value: float, *,
                   dispatch: Dispatch) -> SolutionSet:
    """``solve_fixed(robot, T, {joint j: value}, dispatch=dispatch)``'s rows, lean.

    The self-motion's exact points solve the pose with each joint at its limits and
    aligned values (issue 29): a middle joint without a held closed form took the
    whole :func:`solve_fixed` path (its checks, a reduced chain looked up, the
    dispatcher, two set assemblies: ~0.4 ms of Python around a ~0.15 ms general 6R
    solve). Here such a joint, at a value putting no pair of axes on or next to one
    line, is solved by the reduced chain's general 6R kernel directly
    (:class:`MidHeld`, kept per arm and value) and assembled as that path does (the
    rows, ``valid``, ``singular``, ``within_limits``, then :func:`_into_limits`);
    every other case is :func:`solve_held_single`, else :func:`solve_fixed`. The
    set's ``status``, ``method`` and ``info`` are not filled in on the lean path.

    Args:
        robot: The arm (7R).
        T: One pose (4, 4) [m], float64, rigid (:func:`check_rigid`'s output).
        j: The held joint's index.
        value: Its value [rad], finite.
        dispatch: ``dispatch.solve`` (:func:`solve_fixed`'s, where it is taken).

    Returns:
        A set of shape (k, n) whose ``q``, ``valid``, ``singular`` and
        ``within_limits`` are :func:`solve_fixed`'s.
    """
    name = robot.joint_names[j]
    out = solve_held_single(robot, T, {name: value})
    if out is not None:
        return out
    table = robot.derived(MID_HELD)
    key = (j, value)
    if key not in table:
        if len(table) >= _MID_KEPT:
            table.clear()
        table[key] = MidHeld.of(robot, j, value)
    mid = table[key]
    if mid is None or T.shape != (4, 4) or T.dtype != np.float64:
        return solve_fixed(robot, T, {name: value}, dispatch=dispatch)
    return mid.solve(robot, T)  # (rigid: solve_fixed's check_rigid would return T itself)


#: Middle-joint set-ups kept per arm (:class:`MidHeld`; the self-motion asks for
#: each joint's limits and aligned values only): the table is emptied past this.
_MID_KEPT = 64


@dataclass(frozen=True, eq=False)
class MidHeld:
    """A middle joint held at one value, its reduced chain solved by general 6R directly.

    Attributes:
        j: The joint's index.
        value: Its value [rad].
        reduced: The reduced chain's arm (the joint at ``value``).
        params: Its general 6R parameters.
        keep: The whole arm's columns of the reduced chain's joints.
    """

    j: int
    value: float
    reduced: Arm
    params: np.ndarray
    keep: list[int]

    @classmethod
    def of(cls, robot: Arm, j: int, value: float) -> MidHeld | None:
        """The set-up, or None where :func:`solve_fixed` takes another path.

        (An end joint, a held closed form, a value putting a pair of axes on or next
        to one line (``coincident``, ``near_coincident``), a reduced chain whose
        family is not general 6R.)
        """
        name = robot.joint_names[j]
        if (not 0 < j < robot.n - 1 or _held_solvers(robot).get(name) is not None
                or robot.n != 7 or not math.isfinite(value)
                or _co.coincident_pair(robot, j, value) is not None
                or _nco.near_coincident_pair(robot, j, value) is not None):
            return None
        reduced = _reduced(robot, [j], (value,))
        if reduced.derived(FAMILY).name != _g6.NAME:
            return None
        params = _g6.setup(reduced).params
        if params is None:
            return None
        return cls(j, value, reduced, params, [c for c in range(robot.n) if c != j])

    def solve(self, robot: Arm, T: np.ndarray) -> SolutionSet:
        """The set at one rigid pose T (4, 4): :func:`solve_fixed`'s rows and flags.

        As that path: the general 6R set's rows (NaN where not valid), the held
        column, ``within_limits`` by :class:`SolutionSet`'s test (1e-9) on the whole
        row, ``singular`` the kernel's sigma below 1e-6, then :func:`_into_limits`.
        """
        Q, valid, _, sigma, _, _, _ = _g6.raw_solve(self.reduced.chain, self.params,
                                                   np.ascontiguousarray(T)[None])
        return _held_set(robot, self.j, self.keep, np.array(self.value), T[None], Q[0],
                         valid[0], sigma[0])


#: Per arm: (middle joint, value) -> :class:`MidHeld` (or None), filled on first use.
MID_HELD: Derived[dict[tuple[int, float], MidHeld | None]] = Derived(
    "middle-joint held general 6R set-ups", lambda arm: {})


def sweep_end(robot: Arm, j: int, T: np.ndarray, values: np.ndarray) -> SolutionSet | None:
    """``solve_fixed(robot, T, {joint j: values})``: one pose, an end joint, general 6R.

    The rows, ``valid``, ``singular`` and ``within_limits`` that path gives (one reduced
    chain, the moved targets, one compiled call, then ``_into_limits``), without its
    checks, its dispatch and its two set assemblies: the continued self-motion's
    sweeps (``self_motion_continued``; ~10 us per value less on 64 values). None
    where that path does not apply (a middle joint, a held closed form, a reduced
    chain that is not general 6R); the status and method are not filled in.

    Args:
        robot: The arm.
        j: The held joint's index.
        T: One validated pose (4, 4) [m].
        values: Held values (M,) [rad], finite.
    """
    sweep = EndSweep.of(robot, j, T)
    return None if sweep is None else sweep.solve(values)


@dataclass(frozen=True, eq=False)
class EndSweep:
    """:func:`sweep_end` for one arm, end joint and pose, its set-up looked up once.

    The continued self-motion family keeps one per pose (issue 29): every sweep
    of ``rows(t)`` then costs the moved targets, the compiled call and the
    assembly only (the reduced chain, its general-6R parameters, the joint's
    constant and the pose's product with it are not looked up again).

    Attributes:
        robot: The arm.
        j: The held joint's index.
        T: The pose (4, 4) [m].
        reduced: The reduced chain's arm (the joint held at 0).
        params: Its general 6R parameters.
        last: The joint is the chain's last (else its first).
        C: The chain's constant next to the joint; C_inv: its inverse.
        cols: The whole arm's columns of the reduced chain's joints.
    """

    robot: Arm
    j: int
    T: np.ndarray
    reduced: Arm
    params: np.ndarray
    last: bool
    C: np.ndarray
    C_inv: np.ndarray
    cols: list[int]

    @classmethod
    def of(cls, robot: Arm, j: int, T: np.ndarray) -> EndSweep | None:
        """The sweep of joint j at pose T, or None where :func:`sweep_end` does not apply."""
        end = _end_joint(robot, [j])
        if end is None or _held_solvers(robot).get(robot.joint_names[j]) is not None:
            return None
        reduced = _reduced(robot, [j], (0.0,))
        params = _g6.setup(reduced).params if reduced.derived(FAMILY).name == _g6.NAME else None
        if params is None:
            return None
        consts = robot.chain.arrays.consts
        C = consts[-1] if end == "last" else consts[0]
        return cls(robot, j, T, reduced, params, end == "last", C, invert(C),
                   [c for c in range(robot.n) if c != j])

    def solve(self, values: np.ndarray) -> SolutionSet:
        """The set at held values (M,) [rad], finite (as :func:`sweep_end`)."""
        return self.solve_pairs(values)[0]

    def solve_pairs(self, values: np.ndarray) -> tuple[SolutionSet, np.ndarray]:
        """:meth:`solve`, and per value the polynomial's complex root pairs nearest the axis.

        Returns:
            The set at held values (M,) [rad], and (M, 4, 2): per value the general
            6R kernel's four non-real root pairs of its eliminated polynomial closest
            to the real axis, nearest first, as (imaginary part of the split joint's
            angle [rad], > 0; its real part [rad]), inf where there are fewer. A
            pair whose imaginary part passes 0 between two values is a pair of rows
            born or dying there (issue 29: an island of the self-motion).
        """
        robot, j = self.robot, self.j
        joint = robot.chain.joints[robot.n - 1 if self.last else 0]
        M = len(values)
        Tb = np.broadcast_to(self.T, (M, 4, 4))
        Tm = np.ascontiguousarray(_move(Tb, values, self.last, self.C, self.C_inv,
                                        joint.kind, joint.sign))
        Q, valid, _, sigma, _, _, stats = _g6.raw_solve(self.reduced.chain, self.params, Tm)
        sols = _held_set(robot, j, self.cols, values, Tb, Q, valid, sigma)
        return sols, stats[:, 4:].reshape(M, 4, 2)  # M = 0 too


def _held_set(robot: Arm, j: int, cols: list[int] | np.ndarray, values: np.ndarray,
              T: np.ndarray, Q: np.ndarray, valid: np.ndarray, sigma: np.ndarray
              ) -> SolutionSet:
    """The set of a reduced chain's general 6R rows with joint j held, as :func:`solve_fixed`'s.

    The rows (NaN where not valid) with the held column, ``within_limits`` by
    :class:`SolutionSet`'s test (1e-9) on the whole row, ``singular`` the kernel's
    sigma below 1e-6, then :func:`_into_limits` (``status``, ``method`` and ``info``
    not filled in). Shared by :meth:`MidHeld.solve` and :meth:`EndSweep.solve_pairs`.

    Args:
        robot: The arm (7R).
        j: The held joint's index.
        cols: The whole arm's columns of the reduced chain's joints (n - 1,).
        values: The held values, shape L (() for one pose, (M,) for a sweep) [rad].
        T: The poses (prod(L), 4, 4) [m] (for :func:`_into_limits`).
        Q: The reduced chain's rows (*L, k, n - 1) [rad].
        valid: (*L, k) bool.
        sigma: The kernel's smallest singular values (*L, k).
    """
    q = np.full(Q.shape[:-1] + (robot.n,), np.nan)
    q[..., cols] = Q
    q[..., j] = values[..., None]
    q[~valid] = np.nan  # as SolutionSet does with rows that are not valid
    lim = robot.limits
    inside = _all_last((q >= lim[:, 0] - 1e-9) & (q <= lim[:, 1] + 1e-9))
    sols = SolutionSet._trusted(q, valid, robot.is_revolute, lim,
                                {"singular": (sigma < 1e-6) & valid, "within_limits": inside},
                                {}, np.empty(values.shape, dtype=object), "", None, {})
    return _into_limits(robot, j, T, values.reshape(-1), sols)


def _all_last(b: np.ndarray) -> np.ndarray:
    """``b.all(-1)`` of a bool array, its short last axis (the joints) one column at a time.

    numpy's reduction over a 7-long last axis costs ~10x more per element than
    one ``&=`` per column (the continued self-motion's sweeps, issue 29).
    """
    out: np.ndarray = b[..., 0].copy()
    for j in range(1, b.shape[-1]):
        out &= b[..., j]
    return out


_NUMBERS = (float, int, np.float64)


@dataclass(frozen=True, eq=False)
class NearHelper:
    """A held joint's near-coincident path for one pose, set up once per aligned value.

    Attributes:
        v0: The aligned value [rad].
        pair: ``coincident_pair(robot, joint, v0)``.
        reduced: The helper problem's arm (joint ``pair.a``, an end joint, held).
        params: Its general 6R parameters.
        moves: (2, 4, 4): the helper values' target moves (:func:`_moved_targets`'s
            product before the pose), ``pair.c`` and ``pair.c + HELPER_TURN``.
        keep: The helper arm's joints in the whole arm's order.
    """

    v0: float
    pair: _co.CoincidentPair
    reduced: Arm
    params: np.ndarray
    moves: np.ndarray
    keep: list[int]


def _near_helpers(robot: Arm, j: int) -> list[NearHelper] | None:
    """Joint j's :class:`NearHelper` per aligned value, in ``ALIGNED`` order (kept per arm).

    None (for every value) unless every aligned value's pair has its helper joint
    first in the chain, without a held closed form, and a general 6R helper chain: the path
    :func:`solve_fixed` takes, which :func:`_near_single` then takes with less overhead.
    """
    table = robot.derived(NEAR_HELPERS)
    if j in table:
        return table[j]
    out: list[NearHelper] = []
    for v0 in _nco.ALIGNED:
        pair = _co.coincident_pair(robot, j, v0)
        if pair is None:
            continue
        name = robot.joint_names[pair.a]
        if _end_joint(robot, [pair.a]) != "first" or _held_solvers(robot).get(name) is not None:
            out = []
            break
        reduced = _reduced(robot, [pair.a], (0.0,))
        params = (_g6.setup(reduced).params if reduced.derived(FAMILY).name == _g6.NAME
                  else None)
        if params is None:
            out = []
            break
        C0 = robot.chain.arrays.consts[0]
        c = np.array([pair.c, pair.c + _co.HELPER_TURN])
        # _moved_targets' product for the first joint, without the pose
        moves = C0 @ joint_motion(robot.chain.joints[0].kind,
                                  -robot.chain.joints[0].sign * c) @ invert(C0)
        out.append(NearHelper(v0, pair, reduced, params, moves,
                              [i for i in range(robot.n) if i != pair.a]))
    table[j] = out or None
    return table[j]


def _no_helpers(arm: Arm) -> dict[int, list[NearHelper] | None]:
    """A new, empty table of near-coincident helpers by joint."""
    return {}


#: The arm's near-coincident helper set-ups by held joint, filled on first use.
NEAR_HELPERS: Derived[dict[int, list[NearHelper] | None]] = Derived(
    "near-coincident helpers", _no_helpers)


def _near_single(robot: Arm, T: np.ndarray, name: str, x: float) -> SolutionSet | None:
    """``robot.ik(T, fixed={name: x})`` for one pose next to aligned axes, lean.

    The path :func:`solve_fixed` takes for one pose (:func:`_coincident_parts`, the
    helper problems by :func:`_end_general_6r`, ``near_coincident``), the same rows,
    without its per-call set-up: both helper values in one compiled call, the
    moves of the targets kept per arm, one set assembled. ~0.3 ms less per call
    (0.55 -> 0.25 ms CPU on the Panda, q2 next to 0). None where that path does not
    apply (the caller takes :func:`solve_fixed`).
    """
    j = robot.derived(JOINT_INDEX).get(name)
    if j is None or not np.isfinite(x) or T.shape != (4, 4):
        return None
    helpers = _near_helpers(robot, j)
    if helpers is None:
        return None
    # near_coincident_pair's choice: the first aligned value within NEAR with a pair
    h = next((h for h in helpers if 0.0 < abs(x - h.v0) <= _nco.NEAR), None)
    if h is None or _co.coincident_pair(robot, j, x) is not None:
        return None
    Tc = check_rigid(T, "T")
    pair, n = h.pair, robot.n
    Q, valid, _, _, status, _, _ = _g6.raw_solve(h.reduced.chain, h.params,
                                                 np.ascontiguousarray(h.moves @ Tc))
    q = np.empty(Q.shape[:-1] + (n,))
    q[..., h.keep] = Q
    q[..., pair.a] = np.array([pair.c, pair.c + _co.HELPER_TURN])[:, None]
    ok = valid & (np.abs(wrap_angle(q[..., j] - h.v0)) <= _nco.KEEP)
    rows = _nco.near_rows(robot, Tc[None], q[ok], np.zeros(int(ok.sum()), np.int64), pair,
                          h.v0, x)
    out, found, sing = _nco.placed(1, n, rows)
    why = np.asarray(STATUS_TEXT[_g6._STATUS[status[:1]]], dtype=object)
    method = f"{_g6.NAME} ({robot.joint_names[pair.a]} held) + {_nco.METHOD} ({name} held)"
    return SolutionSet(out[0], found[0], robot.is_revolute, robot.limits,
                       flags={"singular": sing[0]},
                       status=_nco.status_text(found, why).reshape(()), method=method,
                       info={"held": {name: np.asarray(x, dtype=np.float64)}})


@dataclass(frozen=True, eq=False)
class HeldSolver:
    """The ``pieper`` closed form of a chain with one joint held (any value).

    Attributes:
        params: ``pieper.setup(chain, held)``'s parameters.
        method: The sets' ``method`` text, e.g. "analytic:pieper (joint7 held)".
        info: The sets' ``info`` (without the held values).
        single: ``single(T, x, qn)``: one pose (4, 4) with the joint at x
            (``pieper.make_single``).
    """

    params: np.ndarray
    method: str
    info: dict[str, Any]
    single: Any

    def solve(self, robot: Arm, T: np.ndarray, q_near: np.ndarray | None,
              values: np.ndarray, *, compute_error: bool = False) -> SolutionSet:
        """Every solution for validated poses T (..., 4, 4) at held values (...)."""
        info = dict(self.info)
        name = robot.joint_names[int(self.params[_native.kernels.PIEPER_HELD])]
        info["held"] = {name: values}
        return _pk.solve(robot, T, q_near, params=self.params, method=self.method,
                         info=info, values=values, compute_error=compute_error)


def _held_solvers(robot: Arm) -> dict[str, HeldSolver]:
    """Joint name -> the closed form with that joint held, where one applies.

    Set up once per arm, kept in it (microseconds per joint: no reduced chain is built).
    """
    return robot.derived(HELD_SOLVERS)


def _build_held_solvers(robot: Arm) -> dict[str, HeldSolver]:
    """:func:`_held_solvers`' table, built (empty unless a 7R arm without dependent joints)."""
    chain = robot.chain
    out: dict[str, HeldSolver] = {}
    if chain.n != 7 or chain.n_chain != 7 or not chain.coupling.is_identity:
        return out
    for j, name in enumerate(robot.joint_names):
        setup = _pk.setup(chain, j)
        if setup.params is None:
            continue
        method = f"analytic:{_pk.NAME} ({name} held)"
        info = {"family": _pk.NAME, "measured": setup.measured, "near_family": False}
        one = _pk.make_single(chain, setup.params, method=method, info=info,
                              held=name)
        out[name] = HeldSolver(setup.params, method, info, one)
    return out


#: The arm's held-joint closed forms, kept in its ``Arm``.
HELD_SOLVERS: Derived[dict[str, HeldSolver]] = Derived(
    "held-joint closed forms", _build_held_solvers)


def _end_joint(robot: Arm, idx: list[int]) -> str | None:
    """"first" / "last" when one held coordinate is the chain's first / last joint."""
    chain = robot.chain
    if len(idx) != 1 or not chain.coupling.is_identity:
        return None
    if idx[0] == chain.n - 1:
        return "last"
    if idx[0] == 0:
        return "first"
    return None


def _moved_targets(robot: Arm, end: str, T: np.ndarray, v: np.ndarray) -> np.ndarray:
    """The targets of the reduced chain (held value 0) that equal T at value v."""
    C = robot.chain.arrays.consts
    j = robot.n - 1 if end == "last" else 0
    Cj = C[-1] if end == "last" else C[0]
    joint = robot.chain.joints[j]
    return _move(T, v, end == "last", Cj, invert(Cj), joint.kind, joint.sign)


def _move(T: np.ndarray, v: float | np.ndarray, last: bool, C: np.ndarray, C_inv: np.ndarray,
          kind: Any, sign: float) -> np.ndarray:
    """T (..., 4, 4) moved for the reduced chain (the end joint held at 0).

    The reduced chain reaches the result where the whole chain with the joint at v
    reaches T. C: the chain's constant next to the joint (``consts[-1]`` for the
    last, ``[0]`` for the first); C_inv: its inverse.
    """
    J = joint_motion(kind, -sign * v)
    out: np.ndarray = T @ C_inv @ J @ C if last else C @ J @ C_inv @ T
    return out


#: Reduced arms kept per arm: a sweep of a middle joint builds one per value
#: (a general-6R set-up each); the most recently used ones are kept, not all.
_REDUCED_KEPT = 16


def _reduced(robot: Arm, idx: list[int], values: tuple[float, ...]) -> Arm:
    """The arm of the remaining coordinates (the last few kept in ``robot.reduced``)."""
    key = (tuple(idx), values)
    kept = robot.reduced
    if key in kept:
        kept.move_to_end(key)
        return kept[key]
    held = ", ".join(f"{robot.joint_names[j]}={v:g}" for j, v in zip(idx, values,
                                                                      strict=True))
    # the chain and a name, nothing per motor of the whole arm (actuators)
    value = kept[key] = Arm(robot.chain.with_fixed(dict(zip(idx, values, strict=True))),
                            name=f"{robot.name} ({held} held)")
    while len(kept) > _REDUCED_KEPT:
        kept.popitem(last=False)
    return value


class Dispatch(Protocol):
    """``dispatch.solve``'s signature: solves the reduced arm.

    The dispatcher passes itself in (it imports this module).
    """

    def __call__(self, robot: ArmSource, T: npt.ArrayLike, *,
                 q_near: npt.ArrayLike | None = None, method: str = "auto",
                 **options: Any) -> SolutionSet:
        """Every solution for poses T (..., 4, 4)."""


def _assemble(robot: Arm, lead: tuple[int, ...], idx: list[int], keep: list[int],
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
