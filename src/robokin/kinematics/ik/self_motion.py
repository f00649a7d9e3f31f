r"""The self-motion manifold of a 7R arm at one pose: every branch, exact limits.

A seven-joint arm reaches a pose in a one-parameter family of configurations.
:func:`self_motion` (``Robot.self_motion``) describes that family for one pose as
branches :math:`q_b(t)` over a parameter t:

* ``"swivel"`` on SRS arms (axes 1-3 and 5-7 meet, the KUKA iiwa type): the arm
  angle about the shoulder-wrist line, closed form (``swivel.py``), 8 branches;
* a joint name: that joint held at t, the rest solved by the held-joint closed
  form (``pieper``: the Panda / FR3 with joint 4-7, an SRS arm with joint 1-3 or
  5-7), 8 branches whose slots stay the same branch for every t;
* ``"auto"``: the swivel on SRS arms, else the last joint with a held-joint closed
  form (q7 on the Panda / FR3: He and Liu's closed form), else the last joint;
* a joint without a held-joint closed form: the general held-joint 6R solver at
  181 values, its rows continued into branches by nearest pairing with step
  halving (``_ContinuedFamily``): seconds per pose.

**Limits exactly.** A branch leaves a joint's range where that joint equals a
limit: those points are the solutions of a finitely-solvable problem (the swivel's
subproblem 4 per joint and limit on SRS arms; the pose solved with that joint held
at its limit otherwise), each one mapped to its parameter value and branch. The
intervals of t inside every limit lie between those points (and the branch ends),
each decided at its midpoint. A grid of the parameter (``grid`` values) checks the
result: a change of state on the grid that no exact point explains (a crossing the
held-joint solver missed) is found by bisection to the last bit and counted in
``info["bisected"]``.

**Branch ends and singular points.** A branch of a joint parameter ends where the
held-joint 6R chain is singular (the manifold folds over the parameter: two slots
meet); those ends are found by bisection on the branch's existence (to the last
bit) and flagged ``"fold"``. Points where two axes of a meeting triple line up
(the Panda's q2 = 0, the iiwa's q2, q6 = 0) are found exactly like limits and
flagged ``"aligned axes"``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

from robokin._native import kernels as K
from robokin._validation import check_finite, check_joints, check_poses_fast
from robokin.exceptions import InputError
from robokin.kinematics.arm import Arm, ArmSource, arm_of
from robokin.kinematics.ik.fixed import Dispatch, solve_fixed
from robokin.kinematics.ik.swivel import SwivelArm, swivel_arm
from robokin.spatial import wrap_angle as _wrap

__all__ = ["LimitCrossing", "ManifoldPoint", "SelfMotion", "SelfMotionSetup", "SingularPoint",
           "auto_parameter",
           "nearest_on_manifold", "parameter_values", "self_motion"]

#: Parameter values on the checking grid.
GRID = 721
#: Bisection steps (a 2 pi domain to 2**-52 of its width).
_BISECT = 56
#: Rows of a slot at the same point are the same configuration within this [rad].
_SAME = 1e-6
_TWO_PI = 2 * np.pi
#: At most this many grid changes without an exact point are bisected (a pose on a
#: singular manifold, e.g. the SRS arm stretched with its wrist in line, has many).
_MAX_BISECT = 64
#: Largest joint step [rad] between paired rows of a continued branch.
_JUMP = 0.3
#: Checking-grid values of a continued family.
_CONTINUED_GRID = 181
#: Step halvings of the continuation.
_REFINE = 4
#: Half-width [rad] of ik_near's window around q_near's own parameter value.
_WINDOW = 0.05
#: Zoom rounds of SelfMotion.best / nearest (each narrows the span about 4 times).
_ZOOMS = 8
#: Intervals zoomed in on (the best by their samples).
_KEEP = 3


@dataclass(frozen=True)
class LimitCrossing:
    """A branch meeting a joint limit: ``joint`` (0-based) at ``limit`` ("lower"/"upper")."""

    t: float
    branch: int
    joint: int
    limit: str


@dataclass(frozen=True)
class SingularPoint:
    """A singular point of a branch: ``kind`` "fold" or "aligned axes"."""

    t: float
    branch: int
    kind: str


@dataclass(frozen=True)
class ManifoldPoint:
    """One configuration on the manifold: ``q`` (n,), at ``t`` on ``branch``, ``score``."""

    q: np.ndarray
    t: float
    branch: int
    score: float


# ------------------------------------------------------------------ the families
class _Family:
    """Branches of one pose: ``rows(t)`` and the exact points where a joint is at a value."""

    k = 8
    periodic = False
    domain: tuple[float, float]
    name: str
    joint: int | None

    def rows(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Q (m, k, n) (NaN where a branch has no point), valid (m, k), singular (m, k)."""
        raise NotImplementedError

    def candidates(self, j: int, value: float) -> list[tuple[float, np.ndarray | None]]:
        """Parameter values where joint j may equal ``value`` (with the configuration)."""
        raise NotImplementedError

    def param_of(self, q: np.ndarray) -> float:
        """The parameter value of a configuration q (n,) (of this pose or near it)."""
        assert self.joint is not None
        return float(q[self.joint])

    def points(self, queries: list[tuple[int, float]]) -> list[list[tuple[float, int]]]:
        """Per query (joint j, value): every (t, branch) where joint j equals value.

        The candidates of every query are evaluated in one batch; a branch takes a
        candidate when its joint j is at the value there (and its configuration is
        the candidate's, when the candidate has one).
        """
        cands = [self.candidates(j, v) for j, v in queries]
        ts = np.array([t for c in cands for t, _ in c], dtype=np.float64)
        out: list[list[tuple[float, int]]] = [[] for _ in queries]
        if not ts.size:
            return out
        q, valid, _ = self.rows(ts)
        i = 0
        for (j, value), cand, res in zip(queries, cands, out, strict=True):
            for t, row in cand:
                ok = valid[i].copy()
                d = np.full(len(ok), np.inf)
                d[ok] = (np.abs(_wrap(q[i, ok, j] - value)) if row is None
                         else np.abs(_wrap(q[i, ok] - row)).max(-1))
                # a shoulder joint is shared by both wrist roots (and vice versa)
                res += [(t, int(b)) for b in np.flatnonzero(d < _SAME)]
                i += 1
        return out


class _SwivelFamily(_Family):
    periodic = True
    domain = (-np.pi, np.pi)
    name = "swivel"
    joint = None

    def __init__(self, arm: SwivelArm, T: np.ndarray, robot: Arm, reference: bool = False
                 ) -> None:
        self.arm = arm
        self.T = np.ascontiguousarray(T, dtype=np.float64)
        self.robot = robot
        self.reference = reference
        self._fr: dict[str, Any] | None = None

    @property
    def fr(self) -> dict[str, Any]:
        """The numpy twin's per-pose constants (built when first needed)."""
        if self._fr is None:
            self._fr = self.arm.frame(self.T)
        return self._fr

    def rows(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        if self.reference:  # the numpy twin (the tests' reference)
            q, real, sing = self.arm.configurations(self.fr, t)
            q, ok = _polish(self.robot, q, real, self.T)
            return q, ok, sing
        t = np.atleast_1d(np.asarray(t, dtype=np.float64))
        Q, valid, sing = self.arm.rows(self.T[None], t[None])
        return Q[0], valid[0], sing[0]

    def exact(self) -> tuple[np.ndarray, np.ndarray, tuple[LimitCrossing, ...],
                             tuple[SingularPoint, ...]]:
        """The compiled intervals, owners, limit crossings and singular points."""
        iv, niv, pts, npts = self.arm.manifold(self.T[None])
        intervals = np.concatenate([iv[0, b, :niv[0, b]] for b in range(8)]).reshape(-1, 2)
        owner = np.repeat(np.arange(8), niv[0])
        p = pts[0, :npts[0]]
        kinds = {int(K.SM_KIND_LOWER): "lower", int(K.SM_KIND_UPPER): "upper",
                 int(K.SM_KIND_ALIGNED): "aligned axes", int(K.SM_KIND_FOLD): "fold"}
        cross, sing = [], []
        for t, b, j, k in p:
            kind = kinds[int(k)]
            if kind in ("lower", "upper"):
                cross.append(LimitCrossing(float(t), int(b), int(j), kind))
            else:
                sing.append(SingularPoint(float(t), int(b), kind))
        return intervals, owner, tuple(cross), tuple(sing)

    def param_of(self, q: np.ndarray) -> float:
        return float(self.arm.swivel_of(self.fr, q))

    def candidates(self, j: int, value: float) -> list[tuple[float, np.ndarray | None]]:
        if j == 3:
            return []  # the elbow does not move with the swivel
        return [(psi, None) for psi, _ in self.arm.limit_swivels(self.fr, j, value)]


class _HeldFamily(_Family):
    def __init__(self, robot: Arm, params: np.ndarray, j: int, T: np.ndarray,
                 dispatch: Dispatch) -> None:
        self.robot = robot
        self.dispatch = dispatch
        self.params = params
        self.joint = j
        self.name = robot.joint_names[j]
        lo, hi = (float(x) for x in robot.limits[j])
        self.domain = (lo, hi)
        self.T = T

    def rows(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        from robokin.kinematics.ik.analytic import pieper as pk

        t = np.ascontiguousarray(np.atleast_1d(t), dtype=np.float64)
        Tb = np.ascontiguousarray(np.broadcast_to(self.T, (len(t), 4, 4)))
        Q, valid, sing, _, _ = pk.raw_solve(self.params, Tb, t)
        Q = Q.copy()
        Q[~valid] = np.nan
        return _into_limits(self.robot, Q), valid, sing

    def candidates(self, j: int, value: float) -> list[tuple[float, np.ndarray | None]]:
        sols = solve_fixed(self.robot, self.T, {self.robot.joint_names[j]: value},
                           dispatch=self.dispatch)
        if "swivel" in str(sols.info.get("measured", "")) and j == 3:
            return []  # the SRS elbow held: a family, constant on the manifold
        out: list[tuple[float, np.ndarray | None]] = []
        for row in sols.q[sols.valid]:
            t = _shift_into(float(row[self.joint]), self.domain)
            if t is not None:
                out.append((t, row))
        return out


class _ContinuedFamily(_Family):
    """Any 7R arm, a joint held by the general held-joint 6R solver, branches continued.

    The pose is solved at ``nodes`` held values (one batch); consecutive values'
    rows are paired by nearest distance (2 pi wrapped), and where a pairing is
    ambiguous (the second-nearest within twice the nearest) or a step jumps more
    than ``_JUMP`` the step is halved (a midpoint solved) up to ``_REFINE`` times.
    Paired rows form tracks (the branches); a row with no partner starts a track.
    ``rows(t)`` solves at t and gives each track the row nearest its value there
    (interpolated between its nodes).
    """

    def __init__(self, robot: Arm, j: int, T: np.ndarray, dispatch: Dispatch,
                 nodes: int = 181) -> None:
        self.robot = robot
        self.dispatch = dispatch
        self.joint = j
        self.name = robot.joint_names[j]
        self.domain = (float(robot.limits[j, 0]), float(robot.limits[j, 1]))
        self.T = T
        t = np.linspace(*self.domain, nodes)
        Q = self._solve(t)
        for _ in range(_REFINE):
            bad = [i for i in range(len(t) - 1) if not _clean_step(Q[i], Q[i + 1])]
            if not bad:
                break
            mid = 0.5 * (t[bad] + t[np.array(bad) + 1])
            t = np.concatenate([t, mid])
            Q = np.concatenate([Q, self._solve(mid)])
            order = np.argsort(t)
            t, Q = t[order], Q[order]
        self.t_nodes = t
        self.tracks = _link(Q)  # (m, k, n)
        self.k = self.tracks.shape[1]

    def _solve(self, t: np.ndarray) -> np.ndarray:
        sols = solve_fixed(self.robot, self.T, {self.name: t}, dispatch=self.dispatch)
        Q = np.where(sols.valid[..., None], sols.q, np.nan)
        return _into_limits(self.robot, Q)

    def rows(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        t = np.atleast_1d(np.asarray(t, dtype=np.float64))
        Q = self._solve(t)  # (m, K, n)
        ref = self._interpolated(t)  # (m, k, n)
        out = np.full(ref.shape, np.nan)
        for i in range(len(t)):
            d = _dist(ref[i][:, None], Q[i][None])  # (k, K)
            d[~np.isfinite(d)] = np.inf
            while np.isfinite(d).any():
                b, r = np.unravel_index(int(np.argmin(d)), d.shape)
                if d[b, r] > _JUMP:
                    break
                out[i, b] = Q[i, r]
                d[b, :] = np.inf
                d[:, r] = np.inf
        valid = np.isfinite(out).all(-1)
        return out, valid, np.zeros_like(valid)

    def _interpolated(self, t: np.ndarray) -> np.ndarray:
        """Each track's value at t (m, k, n): linear between its nodes (NaN off it)."""
        tn, X = self.t_nodes, self.tracks
        i = np.clip(np.searchsorted(tn, t) - 1, 0, len(tn) - 2)
        w = ((t - tn[i]) / (tn[i + 1] - tn[i]))[:, None, None]
        a, b = X[i], X[i + 1]
        mid = a + w * _wrap(b - a)
        near = np.where(w < 0.5, a, b)
        return np.where(np.isfinite(mid), mid, near)

    def candidates(self, j: int, value: float) -> list[tuple[float, np.ndarray | None]]:
        sols = solve_fixed(self.robot, self.T, {self.robot.joint_names[j]: value},
                           dispatch=self.dispatch)
        out: list[tuple[float, np.ndarray | None]] = []
        for row in sols.q[sols.valid]:
            t = _shift_into(float(row[self.joint]), self.domain)
            if t is not None:
                out.append((t, row))
        return out


def _dist(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Largest 2 pi wrapped joint difference of rows a and b (broadcast, NaN -> NaN)."""
    out: np.ndarray = np.abs(_wrap(a - b)).max(-1)
    return out


def _clean_step(A: np.ndarray, B: np.ndarray) -> bool:
    """True when every row of A pairs with one of B unambiguously and within _JUMP."""
    a, b = A[np.isfinite(A).all(-1)], B[np.isfinite(B).all(-1)]
    if len(a) != len(b):
        return False
    if not len(a):
        return True
    d = np.sort(_dist(a[:, None], b[None]), axis=1)
    if d[:, 0].max() > _JUMP:
        return False
    return bool(len(b) < 2 or np.all(d[:, 1] > 2 * d[:, 0]))


def _link(Q: np.ndarray) -> np.ndarray:
    """Tracks (m, k, n) from rows per node (m, K, n): nearest pairing node to node."""
    m, K, n = Q.shape
    tracks: list[np.ndarray] = []
    last: list[int] = []  # per track: its row at the previous node, or -1
    for i in range(m):
        now = [-1] * len(tracks)
        rows = [r for r in range(K) if np.isfinite(Q[i, r]).all()]
        prev = [(tr, last[tr]) for tr in range(len(tracks)) if last[tr] >= 0]
        if prev and rows:
            d = np.array([[float(_dist(Q[i - 1, pr], Q[i, r])) for r in rows] for _, pr in prev])
            while np.isfinite(d).any():
                a, c = np.unravel_index(int(np.argmin(d)), d.shape)
                if d[a, c] > _JUMP:
                    break
                now[prev[a][0]] = rows[c]
                tracks[prev[a][0]][i] = Q[i, rows[c]]
                d[a, :] = np.inf
                d[:, c] = np.inf
        for r in rows:
            if r not in now:
                tr = np.full((m, n), np.nan)
                tr[i] = Q[i, r]
                tracks.append(tr)
                now.append(r)
        last = now
    if not tracks:
        return np.full((m, 1, n), np.nan)
    return np.stack(tracks, axis=1)


def _shift_into(t: float, domain: tuple[float, float]) -> float | None:
    """T shifted by whole turns into the closed domain, or None."""
    lo, hi = domain
    for s in (0.0, _TWO_PI, -_TWO_PI):
        if lo - 1e-12 <= t + s <= hi + 1e-12:
            return min(max(t + s, lo), hi)
    return None


def _into_limits(robot: Arm, q: np.ndarray) -> np.ndarray:
    """Revolute angles shifted by 2 pi into the limits where that fits."""
    lo, hi = robot.limits[:, 0], robot.limits[:, 1]
    rev = np.asarray(robot.is_revolute, bool)
    up = rev & (q < lo) & (q + _TWO_PI <= hi)
    down = rev & (q > hi) & (q - _TWO_PI >= lo)
    out: np.ndarray = q + _TWO_PI * up - _TWO_PI * down
    return out


def _polish(robot: Arm, q: np.ndarray, real: np.ndarray, T: np.ndarray
            ) -> tuple[np.ndarray, np.ndarray]:
    """Rows whose pose error exceeds 1e-13 get minimum-norm Gauss-Newton steps.

    The error is the larger of the position [m] and rotation [rad] norms. A step
    is kept only where it lowers it; rows still above 5e-13 (next to a singular
    point of the closed form) are dropped (NaN, not valid).
    """
    from robokin.kinematics.forward import forward_kinematics
    from robokin.kinematics.jacobian import jacobian_and_pose
    from robokin.spatial import pose_error

    ok = real.copy()
    rows = np.flatnonzero(ok.reshape(-1))
    if not rows.size:
        return q, ok
    flat = q.reshape(-1, q.shape[-1])
    e = pose_error(forward_kinematics(robot.chain, flat[rows]), T)
    for _ in range(3):
        bad = _size(e) > 1e-13
        if not bad.any():
            break
        rows, e = rows[bad], e[bad]
        J, _ = jacobian_and_pose(robot.chain, flat[rows])
        trial = flat[rows] + np.einsum("mij,mj->mi", np.linalg.pinv(J), e)
        et = pose_error(forward_kinematics(robot.chain, trial), T)
        better = _size(et) < _size(e)
        flat[rows[better]] = trial[better]
        e = np.where(better[:, None], et, e)
    lost = rows[_size(e) > 5e-13]
    flat[lost] = np.nan
    ok.reshape(-1)[lost] = False
    return flat.reshape(q.shape), ok


def _size(e: np.ndarray) -> np.ndarray:
    """The larger of the position and rotation norms of pose errors (..., 6)."""
    out: np.ndarray = np.maximum(np.linalg.norm(e[..., :3], axis=-1), np.linalg.norm(e[..., 3:], axis=-1))
    return out


# ------------------------------------------------------------------ the result
@dataclass(frozen=True, eq=False)
class SelfMotion:
    """The self-motion manifold of one pose of a 7R arm (:func:`self_motion`).

    Attributes:
        T: The pose (4, 4).
        parameter: ``"swivel"`` or the joint name held as the parameter t.
        joint: The parameter's joint index, or None for the swivel.
        domain: (2,) the parameter's range [rad] (the joint's limits, or -pi..pi).
        periodic: True when t wraps (the swivel).
        n_branches: k, the number of branch slots.
        intervals: (m, 2) parameter intervals [rad] where a branch is inside every
            joint limit, sorted by branch then start.
        interval_branch: (m,) the branch of each interval.
        crossings: Every point where a branch meets a joint limit.
        singular: Branch ends ("fold") and aligned-axes points.
        method: How the branches are computed.
        info: ``bisected`` (state changes found by bisection, not exactly),
            ``grid`` (values checked).
        limits: The arm's joint limits (n, 2).
    """

    T: np.ndarray
    parameter: str
    joint: int | None
    domain: np.ndarray
    periodic: bool
    n_branches: int
    intervals: np.ndarray
    interval_branch: np.ndarray
    crossings: tuple[LimitCrossing, ...]
    singular: tuple[SingularPoint, ...]
    method: str
    info: dict[str, Any]
    _family: _Family = field(repr=False)
    limits: np.ndarray = field(repr=False)

    def sample(self, t: npt.ArrayLike, *, within_limits: bool = False) -> np.ndarray:
        """Every branch at parameter values t: (..., k, n), NaN where a branch has none.

        Args:
            t: Parameter values (...) [rad].
            within_limits: Also NaN the rows outside a joint limit.
        """
        ta = check_finite(np.asarray(t, dtype=np.float64), "t")
        q, _, _ = self._family.rows(ta.reshape(-1))
        if within_limits:
            q = np.where(self._inside(q)[..., None], q, np.nan)
        return q.reshape(ta.shape + q.shape[-2:])

    def inside(self, t: npt.ArrayLike) -> np.ndarray:
        """(..., k) bool: the branch exists at t and is inside every joint limit."""
        ta = check_finite(np.asarray(t, dtype=np.float64), "t")
        q, _, _ = self._family.rows(ta.reshape(-1))
        return self._inside(q).reshape(ta.shape + (q.shape[-2],))

    def _inside(self, q: np.ndarray) -> np.ndarray:
        lo, hi = self.limits[:, 0], self.limits[:, 1]
        with np.errstate(invalid="ignore"):
            out: np.ndarray = np.all((q >= lo - 1e-12) & (q <= hi + 1e-12), axis=-1)
            return out

    @property
    def reachable(self) -> bool:
        """True when some part of the manifold is inside every joint limit."""
        return bool(len(self.intervals))

    def best(self, criterion: str | Callable[[np.ndarray], np.ndarray] = "margin", *,
             robot: ArmSource | None = None, samples: int = 64) -> ManifoldPoint | None:
        """The in-limit configuration that maximises ``criterion``, or None.

        Args:
            criterion: ``"margin"`` (the smallest distance to a joint limit [rad]),
                ``"manipulability"`` (Yoshikawa's, needs ``robot``) or a function
                of configurations (m, n) -> scores (m,).
            robot: The arm (for ``"manipulability"``).
            samples: Values per feasible interval before zooming in on the best.
        """
        score = _criterion(criterion, robot, self.limits)
        return self._maximise(score, samples)

    def nearest(self, q_near: npt.ArrayLike, *, samples: int = 64) -> ManifoldPoint | None:
        """The in-limit configuration nearest ``q_near`` (n,) (2 pi wrapped distance)."""
        qn = check_finite(check_joints(q_near, self.limits.shape[0], "q_near"), "q_near")

        def score(q: np.ndarray) -> np.ndarray:
            out: np.ndarray = -np.linalg.norm(_wrap(q - qn), axis=-1)
            return out

        return self._maximise(score, samples)

    def _maximise(self, score: Callable[[np.ndarray], np.ndarray],
                  samples: int) -> ManifoldPoint | None:
        return _maximise(self._family, self.limits, self.intervals, self.interval_branch,
                         score, samples)


def _maximise(fam: _Family, limits: np.ndarray, intervals: np.ndarray, branches: np.ndarray,
              score: Callable[[np.ndarray], np.ndarray], samples: int) -> ManifoldPoint | None:
    """The best in-limit point: ``samples`` values per interval, then zooming in.

    The best ``_KEEP`` intervals (by their best sample) are zoomed ``_ZOOMS`` times,
    each time to +-1 step around their best value with 9 values.
    """
    if not len(intervals):
        return None
    m = max(int(samples), 3)
    a, b = intervals[:, :1], intervals[:, 1:]
    t, br = a + (b - a) * np.linspace(0.0, 1.0, m), np.asarray(branches)
    s = _scores(fam, limits, score, t, br)
    top = np.argsort(-s.max(axis=1))[:_KEEP]
    top = top[np.isfinite(s[top].max(axis=1))]
    if not len(top):
        return None
    t, s, br, a, b = t[top], s[top], br[top], a[top], b[top]
    u = np.linspace(0.0, 1.0, 9)
    rows = np.arange(len(t))
    for _ in range(_ZOOMS):
        i = np.argmax(s, axis=1)
        step = (t[:, -1] - t[:, 0]) / (t.shape[1] - 1)
        lo = np.maximum(t[rows, i] - step, a[:, 0])
        hi = np.minimum(t[rows, i] + step, b[:, 0])
        keep_t, keep_s = t[rows, i], s[rows, i]
        t = lo[:, None] + (hi - lo)[:, None] * u
        s = _scores(fam, limits, score, t, br)
        t, s = np.column_stack([t, keep_t]), np.column_stack([s, keep_s])  # never worse
        order = np.argsort(t, axis=1)
        t, s = np.take_along_axis(t, order, 1), np.take_along_axis(s, order, 1)
    r, c = np.unravel_index(int(np.argmax(s)), s.shape)
    q = fam.rows(np.array([t[r, c]]))[0][0, br[r]]
    return ManifoldPoint(q, float(t[r, c]), int(br[r]), float(s[r, c]))


def _scores(fam: _Family, limits: np.ndarray, score: Callable[[np.ndarray], np.ndarray],
            t: np.ndarray, br: np.ndarray) -> np.ndarray:
    """Scores (p, m) of branch br[i] at t[i, :]; -inf outside the limits."""
    q = fam.rows(t.reshape(-1))[0]
    q = q.reshape(t.shape + q.shape[-2:])
    qb = q[np.arange(len(t)), :, br]  # (p, m, n)
    ok = np.isfinite(qb).all(-1) & _within(qb, limits)
    flat = qb.reshape(-1, qb.shape[-1])
    out = np.full(flat.shape[0], -np.inf)
    good = ok.reshape(-1)
    if good.any():
        out[good] = score(flat[good])
    return out.reshape(t.shape)


def nearest_on_manifold(robot: ArmSource, T: np.ndarray, q_near: np.ndarray, *,
                        dispatch: Dispatch, samples: int = 61) -> ManifoldPoint | None:
    """The in-limit configuration of pose T (4, 4) nearest ``q_near`` (n,), or None.

    ``dispatch`` is ``dispatch.solve`` (solves the arm with a joint held; passed in,
    as :func:`~robokin.kinematics.ik.fixed.solve_fixed` takes it, so this module
    does not import the dispatcher that imports it).

    Without the exact intervals (``ik_near``'s fast path): every branch sampled at
    ``samples`` parameter values over its range and over +-0.05 rad around
    ``q_near``'s own parameter value, the nearest in-limit sample zoomed in on.
    """
    arm = arm_of(robot)
    fam = _family(arm, T, "auto", dispatch)
    k = fam.k
    lo, hi = fam.domain
    # every branch over the whole range, and a window around q_near's own parameter
    # value (an in-limit island narrower than the samples is found there)
    tn = fam.param_of(q_near)
    if fam.periodic:
        window = (tn - _WINDOW, tn + _WINDOW)
    else:
        window = (max(lo, tn - _WINDOW), min(hi, tn + _WINDOW))
        if window[0] >= window[1]:
            window = (lo, hi)
    intervals = np.vstack([np.tile([lo, hi], (k, 1)), np.tile(window, (k, 1))])

    def score(q: np.ndarray) -> np.ndarray:
        out: np.ndarray = -np.linalg.norm(_wrap(q - q_near), axis=-1)
        return out

    return _maximise(fam, np.asarray(arm.limits, dtype=np.float64), intervals,
                     np.tile(np.arange(k), 2), score, samples)


def auto_parameter(robot: ArmSource) -> str | None:
    """The closed-form parameter ``self_motion(T)`` takes on this arm, or None.

    None for arms that are not 7R, or whose self-motion is continued numerically
    (no swivel, no held-joint closed form).
    """
    arm = arm_of(robot)
    chain = arm.chain
    if arm.n != 7 or chain.n_chain != 7 or not chain.coupling.is_identity:
        return None
    setup = _setup(arm)
    if not setup.parameter_known:
        if setup.swivel is not None:
            setup.parameter = "swivel"
        else:
            from robokin.kinematics.ik.fixed import _held_solvers

            usable = [n for n in arm.joint_names if n in _held_solvers(arm)]
            setup.parameter = usable[-1] if usable else None
        setup.parameter_known = True
    return setup.parameter


@dataclass(slots=True, eq=False)
class SelfMotionSetup:
    """What the self-motion of a 7R arm needs per chain (kept in ``Arm.self_motion``).

    Attributes:
        swivel: The SRS arm's swivel closed form, or None (not SRS).
        parameter: ``auto_parameter``'s answer once ``parameter_known``.
        parameter_known: True once ``parameter`` is set.
        aligned: ``_aligned_values``' (joint, value) pairs, or None until needed.
    """

    swivel: SwivelArm | None
    parameter: str | None = None
    parameter_known: bool = False
    aligned: list[tuple[int, float]] | None = None


def _setup(arm: Arm) -> SelfMotionSetup:
    """The arm's :class:`SelfMotionSetup`, built on first use (a 7-joint chain)."""
    setup = arm.self_motion
    if not isinstance(setup, SelfMotionSetup):
        setup = arm.self_motion = SelfMotionSetup(swivel_arm(arm.chain))
    return setup


def _criterion(criterion: Any, robot: ArmSource | None, limits: np.ndarray
               ) -> Callable[[np.ndarray], np.ndarray]:
    if callable(criterion):
        def user(q: np.ndarray) -> np.ndarray:
            return np.asarray(criterion(q), dtype=np.float64).reshape(len(q))
        return user
    if criterion == "margin":
        def margin(q: np.ndarray) -> np.ndarray:
            out: np.ndarray = np.minimum(q - limits[:, 0], limits[:, 1] - q).min(-1)
            return out
        return margin
    if criterion == "manipulability":
        if robot is None:
            raise InputError("robot", "criterion 'manipulability' needs the robot: "
                                      "sm.best('manipulability', robot=robot)")
        from robokin.kinematics.jacobian import manipulability

        chain = arm_of(robot).chain
        return lambda q: manipulability(chain, q)
    raise InputError("criterion", f"expected 'margin', 'manipulability' or a function "
                                  f"of configurations (m, n) -> (m,), got {criterion!r}")


# ------------------------------------------------------------------ building it
def _family(robot: Arm, T: np.ndarray, parameter: str, dispatch: Dispatch,
            reference: bool = False) -> _Family:
    names = list(robot.joint_names)
    choices = ["auto", "swivel", *names]
    if robot.n != 7 or robot.chain.n_chain != 7 or not robot.chain.coupling.is_identity:
        raise InputError("robot", f"self_motion needs a 7-joint serial arm without "
                                  f"coupled joints; {robot.name!r} has {robot.n} joints")
    if parameter not in choices:
        raise InputError("parameter", f"expected one of {', '.join(map(repr, choices))}, "
                                      f"got {parameter!r}")
    arm = _setup(robot).swivel
    if parameter in ("auto", "swivel") and arm is not None:
        return _SwivelFamily(arm, T, robot, reference)
    if parameter == "swivel":
        raise InputError("parameter", f"{robot.name!r} is not an SRS arm (axes 1-3 and "
                                      f"5-7 must meet): give a joint name or 'auto'")
    from robokin.kinematics.ik.fixed import _held_solvers

    held = {n: h for n, h in _held_solvers(robot).items()
            if not (arm is not None and n == names[3])}  # the SRS elbow: a family
    if parameter == "auto":
        usable = [n for n in names if n in held]
        parameter = usable[-1] if usable else names[-1]
    if parameter not in held:  # the general held-joint 6R solver, continued
        return _ContinuedFamily(robot, names.index(parameter), T, dispatch)
    return _HeldFamily(robot, held[parameter].params, names.index(parameter), T, dispatch)


def self_motion(robot: ArmSource, T: npt.ArrayLike, parameter: str = "auto", *,
                dispatch: Dispatch, grid: int = GRID, reference: bool = False) -> SelfMotion:
    """The self-motion manifold of one pose T (4, 4) of a 7R arm.

    Args:
        robot: A 7-joint arm (a Robot, its ``Arm`` or a chain).
        T: The tool pose (4, 4) [m].
        parameter: ``"auto"``, ``"swivel"`` (SRS arms) or a joint name.
        dispatch: ``dispatch.solve`` (solves the arm with a joint held; the caller
            passes it, as to :func:`~robokin.kinematics.ik.fixed.solve_fixed`).
        grid: Parameter values of the checking grid (see the module docstring).
        reference: The swivel computed by its numpy twin (rows, limit points, grid
            and bisection), not the compiled kernel: the tests' reference.

    Returns:
        A :class:`SelfMotion`.

    Raises:
        InputError: not a 7R arm, a bad pose, or a parameter without a closed form
            (the message lists the choices).
    """
    robot = arm_of(robot)
    Ta = check_poses_fast(T, "T")
    if Ta.shape != (4, 4):
        raise InputError("T", f"self_motion takes one pose (4, 4), got {Ta.shape}")
    fam = _family(robot, Ta, parameter, dispatch, reference)
    limits = np.asarray(robot.limits, dtype=np.float64)
    if isinstance(fam, _SwivelFamily) and not reference:
        intervals, owner, crossings, singular = fam.exact()
        return SelfMotion(Ta, fam.name, None, np.array(fam.domain), True, 8, intervals, owner,
                          crossings, singular, "swivel closed form (SRS), compiled",
                          {"bisected": 0, "grid": 0}, fam, limits)
    marks = _exact_points(robot, fam, limits)
    if isinstance(fam, _ContinuedFamily):
        grid = min(int(grid), _CONTINUED_GRID)  # each value is a general-6R solve
    grid_t = _grid(fam, int(grid), marks)
    q, valid, _ = fam.rows(grid_t)
    ends, bisected = _state_changes(fam, grid_t, q, valid, limits, marks)
    intervals, owner = _intervals(fam, limits, marks, ends)
    crossings = tuple(LimitCrossing(t, b, j, s) for t, b, j, s in marks["limit"])
    singular = tuple(SingularPoint(t, b, k) for t, b, k in marks["fold"] + marks["aligned"])
    method = ("swivel closed form (SRS)" if fam.name == "swivel"
              else f"continued general 6R ({fam.name} held)"
              if isinstance(fam, _ContinuedFamily) else f"analytic:pieper ({fam.name} held)")
    return SelfMotion(Ta, fam.name, fam.joint, np.array(fam.domain), fam.periodic, fam.k,
                      intervals, owner, crossings, singular, method,
                      {"bisected": bisected, "grid": int(grid)}, fam, limits)


def _exact_points(robot: Arm, fam: _Family, limits: np.ndarray) -> dict[str, list[Any]]:
    """Every limit point and aligned-axes point of every branch, exactly."""
    out: dict[str, list[Any]] = {"limit": [], "fold": [], "aligned": []}
    rev = np.asarray(robot.is_revolute, bool)
    queries: list[tuple[int, float]] = []
    tags: list[tuple[str, Any]] = []
    for j in range(robot.n):
        lo, hi = limits[j]
        if j == fam.joint or (rev[j] and hi - lo >= _TWO_PI):
            continue  # the parameter, or every angle has an in-limit turn
        queries += [(j, float(lo)), (j, float(hi))]
        tags += [("limit", "lower"), ("limit", "upper")]
    for j, value in _aligned_values(robot):
        if j != fam.joint:
            queries.append((j, value))
            tags.append(("aligned", "aligned axes"))
    for (j, _), (kind, text), found in zip(queries, tags, fam.points(queries), strict=True):
        if kind == "limit":
            out["limit"] += [(t, b, j, text) for t, b in found]
        else:
            out["aligned"] += [(t, b, text) for t, b in found]
    return out


def _aligned_values(robot: Arm) -> list[tuple[int, float]]:
    """(joint, value): where axes j-1 and j+1 of a meeting triple line up."""
    setup = _setup(robot)
    if setup.aligned is None:
        setup.aligned = _find_aligned(robot)
    return setup.aligned


def _find_aligned(robot: Arm) -> list[tuple[int, float]]:
    from robokin.kinematics.ik.analytic._geometry import poe_from_chain
    from robokin.kinematics.ik.swivel import _sp4

    poe = poe_from_chain(robot.chain)
    sign, offset = robot.chain.arrays.sign, robot.chain.arrays.offset
    found = []
    for j in range(1, robot.chain.n_chain - 1):
        a, h, b = poe.h[j - 1], poe.h[j], poe.h[j + 1]
        for c in (1.0, -1.0):
            tp, tm, real = _sp4(h, a, b, np.array(c))
            if bool(real) and abs(float(tp) - float(tm)) < 1e-6:
                v = float((tp + tm) / 2)
                found.append((j, float(_wrap((v - offset[j]) * sign[j]))))
    return found


def _grid(fam: _Family, m: int, marks: dict[str, list[Any]]) -> np.ndarray:
    """The checking grid: m values over the range, refined next to aligned points.

    Next to a point where a triple lines up a branch's outer angles swing by up to
    pi over a tiny parameter range, where the held-joint solver can miss a limit
    crossing: values at 10^-k (k = 1..12) either side catch those for bisection.
    """
    lo, hi = fam.domain
    t = [np.linspace(lo, hi, m)]
    near = np.array([10.0 ** -k for k in range(1, 13)])
    for ts, *_ in marks["aligned"]:
        t.append(np.clip(np.concatenate([ts - near, ts + near]), lo, hi))
    return np.unique(np.concatenate(t))


def _state_changes(fam: _Family, t: np.ndarray, q: np.ndarray, valid: np.ndarray,
                   limits: np.ndarray, marks: dict[str, list[Any]]
                   ) -> tuple[list[tuple[float, int]], int]:
    """Branch ends (bisected on existence) and unexplained in-limit changes on the grid.

    Returns ``([(t, branch), ...] extra breakpoints, how many were bisected)``; the
    fold ends are added to ``marks["fold"]``. All cells are bisected together (one
    batch per step).
    """
    inside = valid & _within(q, limits)
    exact: dict[int, list[float]] = {}
    for tt, b, *_ in marks["limit"] + marks["aligned"]:
        exact.setdefault(b, []).append(tt)
    folds, changes = [], []
    for b in range(fam.k):
        folds += [(i, b) for i in np.flatnonzero(valid[1:, b] != valid[:-1, b])]
        for i in np.flatnonzero((inside[1:, b] != inside[:-1, b])
                                & valid[1:, b] & valid[:-1, b]):
            if not any(t[i] <= x <= t[i + 1] for x in exact.get(b, [])):
                changes.append((i, b))
    changes = changes[:_MAX_BISECT]
    cells = folds + changes
    if not cells:
        return [], 0
    idx = np.array([i for i, _ in cells])
    br = np.array([b for _, b in cells])
    kind = np.array([c >= len(folds) for c in range(len(cells))])  # True: in-limit change
    state0 = np.where(kind, inside[idx, br], valid[idx, br])
    lo, hi = t[idx].astype(np.float64), t[idx + 1].astype(np.float64)
    for _ in range(_BISECT):
        mid = 0.5 * (lo + hi)
        qm, vm, _ = fam.rows(mid)
        rows = np.arange(len(mid))
        now = np.where(kind, vm[rows, br] & _within(qm[rows, br], limits), vm[rows, br])
        same = now == state0
        lo, hi = np.where(same, mid, lo), np.where(same, hi, mid)
    ends = np.where(state0, lo, hi)  # the last point of the state that holds there
    marks["fold"] += [(float(e), int(b), "fold") for e, b, k in zip(ends, br, kind) if not k]
    return [(float(e), int(b)) for e, b in zip(ends, br)], len(changes)


def _within(q: np.ndarray, limits: np.ndarray) -> np.ndarray:
    """(...) bool: rows q (..., n) inside every limit (1e-12 slack); NaN rows False."""
    with np.errstate(invalid="ignore"):
        out: np.ndarray = np.all((q >= limits[:, 0] - 1e-12) & (q <= limits[:, 1] + 1e-12), axis=-1)
        return out


def _intervals(fam: _Family, limits: np.ndarray, marks: dict[str, list[Any]],
               extra: list[tuple[float, int]]) -> tuple[np.ndarray, np.ndarray]:
    """Per branch: the maximal parameter intervals inside every limit."""
    lo_d, hi_d = fam.domain
    cuts: dict[int, list[float]] = {b: [lo_d, hi_d] for b in range(fam.k)}
    for t, b, *_ in marks["limit"] + marks["fold"]:
        cuts[b].append(t)
    for t, b in extra:
        cuts[b].append(t)
    pieces: list[tuple[int, float, float]] = []
    mids, owners, spans = [], [], []
    for b in range(fam.k):
        c = np.unique(np.clip(cuts[b], lo_d, hi_d))
        for a, e in zip(c[:-1], c[1:], strict=True):
            if e > a:
                mids.append(0.5 * (a + e))
                owners.append(b)
                spans.append((a, e))
    if not mids:
        return np.zeros((0, 2)), np.zeros(0, dtype=int)
    q, valid, _ = fam.rows(np.array(mids))
    idx = np.arange(len(mids))
    qb = q[idx, owners]
    with np.errstate(invalid="ignore"):
        ok = valid[idx, owners] & np.all((qb >= limits[:, 0]) & (qb <= limits[:, 1]), -1)
    for (a, e), b, good in zip(spans, owners, ok, strict=True):
        if not good:
            continue
        if pieces and pieces[-1][0] == b and pieces[-1][2] == a:
            pieces[-1] = (b, pieces[-1][1], e)
        else:
            pieces.append((b, a, e))
    if fam.periodic:
        pieces = _join_wrap(pieces, lo_d, hi_d)
    arr = np.array([[a, e] for _, a, e in pieces]).reshape(-1, 2)
    return arr, np.array([b for b, _, _ in pieces], dtype=int)


def _join_wrap(pieces: list[tuple[int, float, float]], lo: float, hi: float
               ) -> list[tuple[int, float, float]]:
    """Periodic parameter: a branch's piece ending at hi and one starting at lo join.

    The joined interval is given as (start, end + 2 pi) with end + 2 pi > hi.
    """
    out = list(pieces)
    for b in {p[0] for p in pieces}:
        own = [p for p in out if p[0] == b]
        first = next((p for p in own if p[1] == lo), None)
        last = next((p for p in own if p[2] == hi), None)
        if first is not None and last is not None and first is not last:
            out.remove(first)
            out.remove(last)
            out.append((b, last[1], first[2] + _TWO_PI))
    return sorted(out)


def parameter_values(robot: ArmSource, T: np.ndarray, q: np.ndarray
                     ) -> tuple[str, np.ndarray]:
    """The self-motion parameter of configurations q (..., k, n) of poses T (..., 4, 4).

    Returns ``(name, values (..., k))``: the swivel angle on SRS arms, else the
    ``auto`` parameter's joint (the last joint without a closed form); NaN rows give
    NaN.
    """
    owner = arm_of(robot)
    name = auto_parameter(owner) or owner.joint_names[-1]
    if name != "swivel":
        return name, q[..., owner.joint_names.index(name)]
    arm = _setup(owner).swivel
    assert arm is not None
    lead = q.shape[:-2]
    Tf = np.broadcast_to(T, lead + (4, 4)).reshape(-1, 4, 4)
    qf = q.reshape((len(Tf),) + q.shape[-2:])
    out = np.stack([arm.swivel_of(arm.frame(Ti), qi) for Ti, qi in zip(Tf, qf, strict=True)])
    return name, out.reshape(q.shape[:-1])
