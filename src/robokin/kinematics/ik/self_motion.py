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
  181 values (one batch), its rows continued into branches by their slopes
  (``self_motion_continued``): limit crossings refined by Newton steps on the
  branch, folds bisected.

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
from robokin._validation import _real_array, check_finite, check_joints, check_rigid
from robokin.exceptions import InputError
from robokin.kinematics.arm import Arm, ArmSource, arm_of
from robokin.kinematics.ik.fixed import Dispatch, held_complete
from robokin.kinematics.ik.self_motion_base import _Family, seven_joint_serial
from robokin.kinematics.ik.self_motion_continua import (
    EXACT,
    LINE_PAIRS,
    Continua,
    continua,
    continua_best,
    onto,
)
from robokin.kinematics.ik.self_motion_continued import _ContinuedFamily
from robokin.kinematics.ik.self_motion_families import (
    HeldKernel,
    LimitCrossing,
    SelfMotionSetup,
    SingularPoint,
    _family,
    _HeldFamily,
    _setup,
    _SwivelFamily,
    continued_parameter,
    one_per_point,
)
from robokin.kinematics.ik.self_motion_hair import HAIR, bands_of, hair_grid
from robokin.kinematics.ik.self_motion_intervals import (
    GRID,
    _aligned_values,
    _compiled,
    _compiled_unchecked,
    _exact_points,
    _grid,
    _held_kernel,
    _held_records,
    _intervals,
    _joined,
    _node_cuts,
    _node_fills,
    _points_refined,
    _state_changes,
    _within,
)
from robokin.kinematics.ik.self_motion_nearest import (
    _SWING_ON,
    _at_limits,
    _distance,
    interval_nearest,
    nearer_points,
)
from robokin.kinematics.ik.swivel import SwivelArm
from robokin.spatial import wrap_angle

__all__ = ["LimitCrossing", "ManifoldPoint", "SelfMotion", "SelfMotionSetup", "SingularPoint",
           "auto_parameter", "exact_parameter",
           "nearest_on_manifold", "parameter_values", "self_motion", "swivel_nearest"]

#: Zoom rounds of SelfMotion.best / nearest (each narrows the span about 4 times).
_ZOOMS = 8
#: Intervals zoomed in on (the best by their samples).
_KEEP = 3


@dataclass(frozen=True)
class ManifoldPoint:
    """One configuration on the manifold: ``q`` (n,), at ``t`` on ``branch``, ``score``.

    ``q`` is ``sample(t)[branch]``, except for a solution ``SelfMotion.nearest`` or
    ``SelfMotion.best`` found off the branches' rows (a point of an aligned continuum,
    which the branches meet in one point): then ``branch`` is the branch whose row at
    t is nearest.
    """

    q: np.ndarray
    t: float
    branch: int
    score: float


@dataclass(frozen=True, eq=False)
class SelfMotion:
    """The self-motion manifold of one pose of a 7R arm (:func:`self_motion`).

    Attributes:
        T: The pose solved (4, 4): the input, its rotation projected onto SO(3)
            when it was off by more than rounding (``_validation.check_rigid``).
        parameter: ``"swivel"`` or the joint name held as the parameter t.
        joint: The parameter's joint index, or None for the swivel.
        domain: (2,) the parameter's range [rad] (the joint's limits, or -pi..pi).
        periodic: True when t wraps (the swivel).
        n_branches: k, the number of branch slots.
        intervals: (m, 2) parameter intervals [rad] where a branch is inside every
            joint limit, sorted by branch then start.
        interval_branch: (m,) the branch of each interval.
        crossings: Every point where a branch meets a joint limit with its other
            joints inside theirs (where an in-limit interval starts or ends, or a
            branch touches a limit from inside; a property: built from ``_points``
            or ``_records`` on first access, then kept in ``_kept``).
        singular: Branch ends ("fold") and aligned-axes points (the same; a
            kernel's repeats of one point merged: ``self_motion_families.one_per_point``).
        method: How the branches are computed.
        info: ``bisected`` (state changes found by bisection, not exactly),
            ``grid`` (values checked; the continued family: its nodes), and on
            the continued family ``solves`` (general-6R values solved),
            ``degenerate`` (its rows did not pair: every row singular) and
            ``dropped`` (tracks left out beyond the 64 longest: where it is not 0,
            branches may be missing; ``docs/ik.md``, session 17).
        limits: The arm's joint limits (n, 2).
        _points: The compiled kernel's points (p, 4) ``[t, branch, joint, kind]``
            (the swivel's ``SM_KIND_*``, the held joint's ``HM_KIND_*``), or None
            when ``_records`` was given.
        _records: ``(crossings, singular)``, the crossings of every branch, in or out of
            the other limits (the compiled held-joint kernel's omit the cells where a
            joint is certainly outside), built from ``_points`` when first read.
        _kept: ``_records`` with the crossings ``crossings`` lists, made on first
            access.
        _held: ``_points`` are the held-joint kernel's (``_held_records`` orders them).
        _corners: ``(t, branch, row)`` of corners whose row was refined on the pose
            (``self_motion_intervals._points_refined``): ``sample`` returns that row.
        _dispatch: ``dispatch.solve`` as :func:`self_motion` had it (``nearest`` and
            ``best`` solve the pose with an aligned joint held), or None.
    """

    T: np.ndarray
    parameter: str
    joint: int | None
    domain: np.ndarray
    periodic: bool
    n_branches: int
    intervals: np.ndarray
    interval_branch: np.ndarray
    method: str
    info: dict[str, Any]
    _family: _Family = field(repr=False)
    limits: np.ndarray = field(repr=False)
    _points: np.ndarray | None = field(default=None, repr=False)
    _records: tuple[tuple[LimitCrossing, ...], tuple[SingularPoint, ...]] | None = field(
        default=None, repr=False)
    _held: bool = field(default=False, repr=False)
    _corners: tuple[tuple[float, int, np.ndarray], ...] = field(default=(), repr=False)
    _dispatch: Dispatch | None = field(default=None, repr=False)
    _kept: tuple[tuple[LimitCrossing, ...], tuple[SingularPoint, ...]] | None = field(
        default=None, repr=False)

    @property
    def crossings(self) -> tuple[LimitCrossing, ...]:
        """Where a branch meets a joint limit, its other joints inside (:class:`LimitCrossing`).

        The ends of the in-limit intervals that are not branch ends or the domain's,
        and the points where a branch touches a limit from inside; a branch crossing a
        limit while another joint is outside bounds nothing and is not listed (the
        compiled held-joint kernel, the Panda's and the Gen3-like arm's, does not
        locate most of those: ``docs/ik.md``, session 24).
        """
        return self._built()[0]

    @property
    def singular(self) -> tuple[SingularPoint, ...]:
        """Branch ends ("fold") and aligned-axes points (:class:`SingularPoint`)."""
        return self._built()[1]

    def _built(self) -> tuple[tuple[LimitCrossing, ...], tuple[SingularPoint, ...]]:
        """The records inside the limits, made on first access and kept."""
        if self._kept is None:
            object.__setattr__(self, "_kept", self._inside_records(*self._every_record()))
        assert self._kept is not None
        return self._kept

    def _every_record(self) -> tuple[tuple[LimitCrossing, ...], tuple[SingularPoint, ...]]:
        """The records of every branch, in or out of the limits (``_records``)."""
        if self._records is None:
            assert self._points is not None
            made = (_held_records if self._held else _records_of)(self._points)
            object.__setattr__(self, "_records", made)
        assert self._records is not None
        return self._records

    def _inside_records(self, crossings: tuple[LimitCrossing, ...],
                        singular: tuple[SingularPoint, ...]
                        ) -> tuple[tuple[LimitCrossing, ...], tuple[SingularPoint, ...]]:
        """The crossings whose other joints are inside; ``singular`` as it is.

        Each crossing's row (``sample`` at its t) inside every limit but its own
        joint's to ``_RECORD_SLACK`` (a corner's other joint at its limit is kept).
        """
        if not crossings:
            return crossings, singular
        t = np.array([c.t for c in crossings])
        b = np.array([c.branch for c in crossings])
        j = np.array([c.joint for c in crossings])
        rows = self.sample(t)[np.arange(len(t)), b]
        lo, hi = self.limits[:, 0], self.limits[:, 1]
        with np.errstate(invalid="ignore"):
            ok = (rows >= lo - _RECORD_SLACK) & (rows <= hi + _RECORD_SLACK)
        ok[np.arange(len(t)), j] = True
        keep = ok.all(-1)
        return tuple(c for c, k in zip(crossings, keep, strict=True) if k), singular

    def sample(self, t: npt.ArrayLike, *, within_limits: bool = False) -> np.ndarray:
        """Every branch at parameter values t: (..., k, n), NaN where a branch has none.

        Args:
            t: Parameter values (...) [rad].
            within_limits: Also NaN the rows outside a joint limit.
        """
        ta = check_finite(_real_array(t, "t", "parameter values [rad, m]"), "t")
        q = self._rows(ta.reshape(-1))
        if within_limits:
            q = np.where(self._inside(q)[..., None], q, np.nan)
        return q.reshape(ta.shape + q.shape[-2:])

    def inside(self, t: npt.ArrayLike) -> np.ndarray:
        """(..., k) bool: the branch exists at t and is inside every joint limit."""
        ta = check_finite(_real_array(t, "t", "parameter values [rad, m]"), "t")
        q = self._rows(ta.reshape(-1))
        return self._inside(q).reshape(ta.shape + (q.shape[-2],))

    def _rows(self, t: np.ndarray) -> np.ndarray:
        """The family's rows at t (m,), a refined corner's row at its own t."""
        q, _, _ = self._family.sample_rows(t)
        for tc, b, row in self._corners:
            q[t == tc, b] = row
        return q

    def _inside(self, q: np.ndarray) -> np.ndarray:
        return _within(q, self.limits)

    @property
    def revolute(self) -> np.ndarray:
        """(n,) bool: the revolute joints (their columns of ``sample`` in rad; else m)."""
        return np.asarray(self._family.robot.is_revolute, dtype=bool)

    @property
    def reachable(self) -> bool:
        """True when some part of the manifold is inside every joint limit.

        An interval of a branch; where there is none, a point of an aligned continuum
        (``self_motion_continua``: q2 = 0, the pair turned against each other; the
        pose solved with that joint held, ~0.1-0.3 ms), else a solution next to a
        branch a hair outside a limit (``self_motion_hair``: a stretched elbow),
        which ``best`` and ``nearest`` also return.
        """
        if len(self.intervals):
            return True
        margin = _criterion("margin", None, self.limits)
        if self._dispatch is not None and continua_best(
                self._family.robot, self.T, self.limits, margin, -np.inf,
                self._dispatch) is not None:
            return True
        return self._hair_best(margin) is not None

    def best(self, criterion: str | Callable[[np.ndarray], np.ndarray] = "margin", *,
             robot: ArmSource | None = None, samples: int = 64) -> ManifoldPoint | None:
        """The in-limit configuration that maximises ``criterion``, or None.

        Args:
            criterion: ``"margin"`` (the smallest distance to a joint limit [rad]),
                ``"manipulability"`` (Yoshikawa's, needs ``robot``) or a function
                of configurations (m, n) -> scores (m,).
            robot: The arm (for ``"manipulability"``).
            samples: Values per feasible interval before zooming in on the best.

        The refined corners' rows are candidates too (a corner's interval can be a
        point the samples skip). Then the aligned continua
        (``self_motion_continua.continua_best``: where an
        axis pair lines up, q2 = 0, the pair turned against each other), whose points
        the branches' samples do not hold; one scoring higher is returned with its
        parameter value and the branch whose row there is nearest. Where neither has
        an in-limit point, the best solution next to a branch a hair outside a limit
        (:meth:`_hair_best`).
        """
        score = _criterion(criterion, robot, self.limits)
        point = self._with_corners(self._maximise(score, samples), score)
        found = None if self._dispatch is None else continua_best(
            self._family.robot, self.T, self.limits, score,
            -np.inf if point is None else point.score, self._dispatch)
        if found is not None:
            return self._off_branches(found[0], found[1])
        return point if point is not None else self._hair_best(score, samples)

    def nearest(self, q_near: npt.ArrayLike, *, samples: int = 64) -> ManifoldPoint | None:
        """The in-limit configuration nearest ``q_near`` (n,) (2 pi wrapped distance).

        On the compiled swivel (SRS arms) the kernel's search on the exact
        intervals (``SwivelArm.nearest``); elsewhere, and where that finds nothing
        (next to a stretched elbow), the exact intervals searched
        by ``self_motion_nearest.interval_nearest`` (end values, a 32-value grid,
        golden-section refinement of the best local minima), and the refined corners'
        rows (a corner's interval can be a point the searches skip); then a nearer
        solution off the branches where there is one (``self_motion_nearest.
        nearer_points``: the numeric solve from ``q_near`` next to a swing, a point of
        an aligned continuum, the branches' aligned-axes rows moved along their
        continua; its ``t`` its parameter value, ``branch`` the branch whose row
        there is nearest). Where none of these has an in-limit point, the best solution
        next to a branch a hair outside a limit (:meth:`_hair_best`, ``samples``
        values per band).
        """
        qn = check_finite(check_joints(q_near, self.limits.shape[0], "q_near"), "q_near")
        fam = self._family
        exact = isinstance(fam, _SwivelFamily) and not fam.reference  # the kernel's rows
        point = None
        if isinstance(fam, _SwivelFamily) and not fam.reference:
            point = _swivel_nearest(fam.arm, self.T, qn)
        if point is None and len(self.intervals):  # (the kernel's miss: its intervals)
            exact = False
            found = interval_nearest(fam, self.limits, self.intervals, self.interval_branch,
                                     qn)
            if found is not None and not self._exact_inside(found[0]):
                # an end row up to 1e-9 past a limit, clamped, that does not go back
                # onto the pose inside the limits: the rows inside to MANIFOLD_SLACK
                found = interval_nearest(fam, self.limits, self.intervals,
                                         self.interval_branch, qn, slack=0.0)
            point = None if found is None else ManifoldPoint(found[0], found[1], found[2],
                                                             -found[3])
        wrapped = np.asarray(self._family.robot.is_revolute, dtype=bool)

        def closeness(Q: np.ndarray) -> np.ndarray:
            """Minus the 2 pi wrapped distance of configurations (m, n) to q_near."""
            out: np.ndarray = -_distance(Q, qn, wrapped)
            return out

        found_point = point
        point = self._with_corners(point, closeness)
        if point is None:
            point = self._hair_best(closeness, samples)
        if point is not found_point:
            exact = False  # (a refined corner's row: checked on the pose, polished)
        if self._dispatch is None:
            return point
        q = np.full((1, len(qn)), np.nan) if point is None else point.q[None]
        q = nearer_points(self._family.robot, self.T[None], self.limits, qn[None], q,
                          self._dispatch, exact=exact,
                          seeds=lambda: self._aligned_rows()[None])
        if point is not None and np.array_equal(q[0], point.q):
            return point
        if not np.isfinite(q).all():
            # nothing on the branches and no continuum row moved onto the pose within
            # its limits (an aligned joint 1e-9 off its value next to a limit): the
            # continua sampled as ``best`` and ``reachable`` sample them
            cont = continua_best(self._family.robot, self.T, self.limits, closeness,
                                 -np.inf, self._dispatch)
            return None if cont is None else self._off_branches(cont[0], cont[1])
        return self._off_branches(q[0], float(closeness(q)[0]))

    def _exact_inside(self, q: np.ndarray) -> bool:
        """Whether q (n,) reaches the pose within ``EXACT`` inside the limits.

        Else it is taken back onto the pose inside them (``_at_limits``; q updated in
        place where that succeeds).
        """
        robot = self._family.robot
        _, err = onto(robot, q[None], self.T[None], steps=0)
        if err[0] <= EXACT:
            return True
        row, e = _at_limits(robot, q, self.T, self.limits)
        if not e <= EXACT:
            return False
        q[...] = row
        return True

    def _off_branches(self, q: np.ndarray, score: float) -> ManifoldPoint:
        """A solution q (n,) off the branches' samples as a point with ``score``.

        Its parameter value, and the branch whose row there is nearest (an aligned
        continuum meets it at its aligned point).
        """
        robot = self._family.robot
        t = (float(q[self.joint]) if self.joint is not None
             else float(parameter_values(robot, self.T, q[None, None])[1][0, 0]))
        wrapped = np.asarray(robot.is_revolute, dtype=bool)
        gap = _distance(self.sample(np.array([t]))[0], q, wrapped)
        branch = int(np.argmin(np.where(np.isfinite(gap), gap, np.inf)))
        return ManifoldPoint(q, t, branch, score)

    def continua(self) -> Continua | None:
        """The pose's aligned continua inside the limits (configurations off the branches).

        Where joint j at a value v puts two axes on one line (the Panda's q2 = 0, the
        iiwa's q2, q4 or q6 = 0), a pair of joints turns against each other at one
        parameter value (``self_motion_continua.continua``: each an in-limit stretch
        of that turn from a row solved with j held at v; ~0.7 ms on the Panda: one held
        solve per pair). None where this manifold was made without the dispatcher
        that solves such rows.
        """
        if self._dispatch is None:
            return None
        return continua(self._family.robot, self.T, self.limits, self._dispatch)

    def _aligned_rows(self) -> np.ndarray:
        """The branches' rows (k, n) at their aligned-axes points, in or out of the limits.

        (Out: a swing's middle row, q1 and q3 at +-pi next to the Panda's aligned
        shoulder; its continuum move can bring it in.) Then the rows at the intervals'
        ends with a pair's joint within ``_SWING_ON`` of its aligned value: a branch
        passing the continuum 1e-9 off without crossing it has no aligned point, and
        its swing's limit crossings end intervals there (the Panda with q2 = -1e-9 at
        q0: q0 1e-9 after such an end, 0.069 rad nearer q_near than the search's
        answer, which the grid steps over).
        """
        marks = [(p.t, p.branch) for p in self._every_record()[1] if p.kind == "aligned axes"]
        n = self.limits.shape[0]
        rows = np.zeros((0, n))
        if marks:
            t, b = (np.array(x) for x in zip(*marks, strict=True))
            rows = self.sample(t)[np.arange(len(t)), b]
        pairs = self._family.robot.derived(LINE_PAIRS)
        if len(self.intervals) and pairs:
            t = self.intervals.reshape(-1)
            b = np.repeat(self.interval_branch, 2)
            ends = self.sample(t)[np.arange(len(t)), b]
            j = [p[0] for p in pairs]
            with np.errstate(invalid="ignore"):
                off = np.abs(wrap_angle(ends[:, j] - np.array([p[1] for p in pairs])))
            rows = np.concatenate([rows, ends[(off <= _SWING_ON).any(-1)]])
        return rows

    def _with_corners(self, point: ManifoldPoint | None,
                      score: Callable[[np.ndarray], np.ndarray]) -> ManifoldPoint | None:
        """``point``, or a refined corner's row inside the limits scoring higher.

        (A corner's interval is a point or a sliver whose family rows at its ends can
        be a hair outside a limit: the searches on the intervals skip it, its refined
        row is inside.)
        """
        inside = [(t, b, row) for t, b, row in self._corners if bool(_within(row, self.limits))]
        if not inside:
            return point
        s = score(np.stack([row for _, _, row in inside]))
        k = int(np.argmax(s))
        if point is not None and not s[k] > point.score:
            return point
        t, b, row = inside[k]
        return ManifoldPoint(row.copy(), float(t), int(b), float(s[k]))

    def _hair_best(self, score: Callable[[np.ndarray], np.ndarray],
                   samples: int = 64) -> ManifoldPoint | None:
        """The best solution next to a branch a hair outside a limit, or None.

        Where the searches of the intervals found no in-limit row: the branches'
        stretches at most :data:`~robokin.kinematics.ik.self_motion_hair.HAIR` outside
        the limits (``hair_grid``, ``bands_of``), searched as intervals are
        (:func:`_maximise`, the limits widened by ``HAIR``), then the bands' own grid
        rows; the best row taken back inside the limits onto the
        pose (``self_motion_nearest._at_limits``); where that row does not reach the
        pose within ``EXACT`` inside the limits, the best row by the score less 1e6
        times its distance outside (the tangent point of a branch touching a limit)
        taken back the same way; else None. A stretched elbow's rows (q4 = 0 where the
        generating configuration has 1e-9) leave a joint the self-motion does not move
        ~5e-10 past the limit it is at, with no interval; a branch tangent to a limit
        (q2 at it, q4 = 2.7e-4: q2 = limit - 6.5e-5 psi^2) is inside at one point,
        which the swivel kernel gives as an interval of +-0.17 whose other rows are up
        to 2e-6 outside.
        """
        t, rows, near = hair_grid(self._rows, self.domain, self.limits)
        bands, branch = bands_of(t, near)
        if not len(bands):
            return None
        wide = self.limits + np.array([-HAIR, HAIR])
        margin = _criterion("margin", None, self.limits)

        def inward(q: np.ndarray) -> np.ndarray:
            """``score`` less 1e6 times the distance outside the limits."""
            out: np.ndarray = score(q) + 1e6 * np.minimum(margin(q), 0.0)
            return out

        for crit in (score, inward):
            point = _maximise(self._family, wide, bands, branch, crit, samples)
            if point is None:
                break
            q, err = _at_limits(self._family.robot, point.q, self.T, self.limits)
            if err <= EXACT:
                return ManifoldPoint(q, point.t, point.branch, float(score(q[None])[0]))
        # the bands' own grid rows (a branch that exists at isolated values only: the
        # rtb iiwa14 held at q3 with q2 and q4 within 1e-7 of 0, its one row at t = 0)
        i, b = np.nonzero(near)
        for k in np.argsort(-inward(rows[i, b]), kind="stable")[:3]:
            q, err = _at_limits(self._family.robot, rows[i[k], b[k]], self.T, self.limits)
            if err <= EXACT:
                return ManifoldPoint(q, float(t[i[k]]), int(b[k]), float(score(q[None])[0]))
        return None

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
                        dispatch: Dispatch) -> ManifoldPoint | None:
    """The in-limit configuration of pose T (4, 4) nearest ``q_near`` (n,), or None.

    ``dispatch`` is ``dispatch.solve`` (solves the arm with a joint held; passed in,
    as :func:`~robokin.kinematics.ik.fixed.solve_fixed` takes it, so this module
    does not import the dispatcher that imports it).

    :meth:`SelfMotion.nearest` of :func:`self_motion`: on SRS arms the compiled
    swivel search, on the others the exact in-limit intervals (compiled
    ``held_manifold`` on the Panda) searched by
    :func:`~robokin.kinematics.ik.self_motion_nearest.interval_nearest`; then the
    solutions off the branches (``nearer_points``).
    """
    return self_motion(arm_of(robot), T, dispatch=dispatch).nearest(q_near)


def _swivel_nearest(arm: SwivelArm, T: np.ndarray, q_near: np.ndarray) -> ManifoldPoint | None:
    """The compiled nearest point of one pose (``SwivelArm.nearest``), or None."""
    q, psi, slot, dist, found = arm.nearest(T[None], q_near[None])
    if not found[0]:
        return None
    return ManifoldPoint(q[0], float(psi[0]), int(slot[0]), -float(dist[0]))


def swivel_nearest(robot: ArmSource, T: np.ndarray, q_near: np.ndarray,
                   dispatch: Dispatch | None = None) -> np.ndarray | None:
    """The in-limit configurations (m, 7) of poses T (m, 4, 4) nearest ``q_near`` (m, 7).

    The compiled search on the exact swivel intervals (``SwivelArm.nearest``; NaN
    rows where no part of a manifold is inside the limits); None when the arm is
    not SRS (then :func:`nearest_on_manifold` per pose). With ``dispatch``
    (``dispatch.solve``) a row is replaced by a nearer solution off the branches
    where there is one (``self_motion_nearest.nearer_points``: the numeric solve from
    q_near, aligned continua); without, the kernel's.
    """
    robot = arm_of(robot)
    arm = _setup(robot).swivel
    if arm is None:
        return None
    q, _, _, _, found = arm.nearest(T, q_near)
    q[~found] = np.nan
    if dispatch is None:
        return q
    return nearer_points(robot, T, np.asarray(robot.limits, dtype=np.float64), q_near, q,
                         dispatch, exact=True)


def auto_parameter(robot: ArmSource) -> str | None:
    """The closed-form parameter ``self_motion(T)`` takes on this arm, or None.

    None for arms that are not 7R, or whose self-motion is continued numerically
    (no swivel, no held-joint closed form).
    """
    arm = arm_of(robot)
    if not seven_joint_serial(arm):
        return None
    setup = _setup(arm)
    if not setup.parameter_known:
        if setup.swivel is not None:
            setup.parameter = "swivel"
        else:
            from robokin.kinematics.ik.fixed import _held_solvers

            # not the elbow: on a near-SRS arm (the rtb-data iiwa14, a Gen3) it moves
            # over a tiny range on the manifold (the shoulder-wrist distance nearly
            # fixes it), a parameter the grid and the users cannot sample
            usable = [n for n in arm.joint_names[:3] + arm.joint_names[4:]
                      if n in _held_solvers(arm)]
            setup.parameter = usable[-1] if usable else None
        setup.parameter_known = True
    return setup.parameter


def exact_parameter(robot: ArmSource) -> str | None:
    """The parameter of a 7-joint arm whose whole manifold is exact, or None.

    ``auto_parameter``'s (a closed form: the SRS swivel, a held joint), else the
    continued family's joint (``continued_parameter``) where the pose with it held
    is solved completely (``fixed.held_complete``): a robot on a linear track (the
    robot's own closed form, ~25 ms a pose on a UR5 on a rail) or a general 7R arm
    (the general 6R solver, ~10-30 ms a pose). None for an arm whose held chain only
    the numeric solver samples (two prismatic joints left), and for arms that are
    not 7-joint serial: pose goals and ``ik_near(..., method="self_motion")`` take
    the manifold only where this is not None.
    """
    name = auto_parameter(robot)
    if name is not None:
        return name
    arm = arm_of(robot)
    if not seven_joint_serial(arm):
        return None
    name = continued_parameter(arm)
    return name if held_complete(arm, arm.joint_names.index(name)) else None


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
        A :class:`SelfMotion`. Its ``method`` names what solved the pose at each
        parameter value: ``"continued numeric (... held)"`` on an arm whose held
        six-joint chain has neither a closed form nor the general 6R solver (two
        prismatic joints, e.g. ``improved_dh_arm``): the rows are then numeric
        samples and a branch can be missed.

    Raises:
        InputError: not a 7R arm, a bad pose, or a parameter without a closed form
            (the message lists the choices).
    """
    robot = arm_of(robot)
    setup = _setup(robot) if robot.n == 7 and not reference else None
    kern: HeldKernel | None = setup.held if setup is not None else None
    if kern is not None and parameter not in ("auto", kern.named[0]):
        kern = None  # another parameter (its family chosen below)
    # the compiled held family "auto" took before: the kernel tests T itself (None:
    # check_rigid's, below), then no family choice again
    found = _compiled_unchecked(kern, T) if kern is not None else None
    Ta = T if found is not None and isinstance(T, np.ndarray) else check_rigid(T, "T")
    if Ta.shape != (4, 4):
        raise InputError("T", f"self_motion takes one pose (4, 4), got {Ta.shape}")
    limits = np.asarray(robot.limits, dtype=np.float64)
    # the compiled swivel (an SRS arm's "auto"): no family choice, no per-call lists
    if setup is not None and setup.swivel is not None and parameter in ("auto", "swivel"):
        return _swivel_motion(setup.swivel, Ta, robot, limits, dispatch)
    if kern is not None:
        fam: _Family = _HeldFamily(robot, kern.params, kern.joint, Ta, dispatch, kern.named)
    else:
        fam = _family(robot, Ta, parameter, dispatch, reference)
        kern = _held_kernel(robot, fam) if isinstance(fam, _HeldFamily) and not reference else None
        if kern is not None and setup is not None and parameter == "auto":
            setup.held = kern  # (not on SRS arms: their "auto" is the swivel)
    fallback: dict[str, Any] = {}
    if kern is not None:
        intervals, owner, points, info, close = found or _compiled(kern, Ta)
        if not info["flags"]:
            assert isinstance(fam, _HeldFamily)
            fam.polish = False  # the kernel's rows: its crossings are on them
            corners: tuple[tuple[float, int, np.ndarray], ...] = ()
            if close:  # the kernel ran _points_refined's cheap test: a uniform pose skips it
                intervals, owner, corners = _points_refined(fam, limits, intervals, owner,
                                                            points, K.HM_KIND_UPPER)
            return _held_motion(Ta, kern, intervals, owner, info, fam, limits, points, corners,
                                dispatch)
        fallback = {"compiled": False, "flags": info["flags"]}  # not certified: solved points
    if isinstance(fam, _ContinuedFamily):
        marks = fam.marks(limits, _aligned_values(robot))
        ends: list[tuple[float, int]] = []
        bisected, grid = 0, len(fam.t_nodes)
    else:
        marks = _exact_points(robot, fam, limits)
        grid_t = _grid(fam, int(grid), marks)
        q, valid, _ = fam.rows(grid_t)
        ends, bisected = _state_changes(fam, grid_t, q, valid, limits, marks)
    intervals, owner = _intervals(fam, limits, marks, ends)
    if isinstance(fam, _ContinuedFamily):  # a crossing the scan missed: its nodes show it
        intervals, owner, missed = _node_cuts(fam, limits, intervals, owner, fam.t_nodes,
                                              fam.tracks)
        marks["limit"] += missed
        intervals, owner, missed = _node_fills(
            fam, limits, intervals, owner, fam.t_nodes, fam.tracks,
            fam.regular_nodes if fam.degenerate else None)
        marks["limit"] += missed
    cuts = np.array([(t, b, j, 0) for t, b, j, _ in marks["limit"]], dtype=np.float64)
    touch = np.array(marks.get("touch", []), dtype=np.float64).reshape(-1, 3)
    sing = np.array([(t, b) for t, b, _ in marks["fold"] + marks["aligned"]],
                    dtype=np.float64).reshape(-1, 2)
    intervals, owner, corners = _points_refined(fam, limits, intervals, owner,
                                                cuts.reshape(-1, 4), 0,
                                                every=not isinstance(fam, _ContinuedFamily),
                                                touch=touch, singular=sing)
    if isinstance(fam, _ContinuedFamily):
        intervals, owner = _joined(intervals, owner)
    crossings = tuple(LimitCrossing(t, b, j, s) for t, b, j, s in marks["limit"])
    singular = tuple(SingularPoint(t, b, k) for t, b, k in marks["fold"] + marks["aligned"])
    method = ("swivel closed form (SRS)" if fam.name == "swivel"
              else f"continued {fam.held_method} ({fam.name} held)"
              if isinstance(fam, _ContinuedFamily) else f"analytic:pieper ({fam.name} held)")
    return SelfMotion(Ta, fam.name, fam.joint, np.array(fam.domain), fam.periodic, fam.k,
                      intervals, owner, method,
                      {"bisected": bisected, "grid": int(grid), **fallback,
                       **_solves(fam)}, fam, limits,
                      _records=(crossings, singular), _corners=corners, _dispatch=dispatch)


def _held_motion(T: np.ndarray, kern: HeldKernel, intervals: np.ndarray, owner: np.ndarray,
                 info: dict[str, Any], fam: _Family, limits: np.ndarray, points: np.ndarray,
                 corners: tuple[tuple[float, int, np.ndarray], ...] = (),
                 dispatch: Dispatch | None = None) -> SelfMotion:
    """The compiled held family's SelfMotion: the dataclass' fields set directly.

    Equal to ``SelfMotion(T, name, joint, domain, False, 8, intervals, owner, method,
    info, fam, limits, points, None, True, corners, dispatch)`` (the frozen dataclass' ``__init__``
    costs ~4 us; one dict literal as the instance's ``__dict__`` ~1 us, as
    ``_swivel_motion``).
    """
    sm = object.__new__(SelfMotion)
    object.__setattr__(sm, "__dict__", {
        "T": T, "parameter": kern.named[0], "joint": kern.joint, "domain": kern.domain.copy(),
        "periodic": False, "n_branches": 8, "intervals": intervals, "interval_branch": owner,
        "method": kern.method, "info": info, "_family": fam, "limits": limits,
        "_points": points, "_records": None, "_held": True, "_corners": corners,
        "_dispatch": dispatch, "_kept": None})
    return sm


def _swivel_motion(arm: SwivelArm, T: np.ndarray, robot: Arm, limits: np.ndarray,
                   dispatch: Dispatch | None = None) -> SelfMotion:
    """The compiled swivel's SelfMotion: the dataclass' fields set directly.

    Equal to ``SelfMotion(T, "swivel", None, domain, True, 8, intervals, owner, method,
    {"bisected": 0, "grid": 0}, family, limits, points, _corners=corners,
    _dispatch=dispatch)`` (the frozen dataclass'
    ``__init__`` is ~3 us of the ~9 us the API adds to the kernel; one dict literal
    as the instance's ``__dict__`` ~1 us).
    """
    sw = _SwivelFamily(arm, T, robot)
    intervals, owner, points, close = arm.manifold_one(sw.T)
    corners: tuple[tuple[float, int, np.ndarray], ...] = ()
    if close:  # the kernel ran _points_refined's cheap test (Round 8d): a uniform pose skips it
        intervals, owner, corners = _points_refined(sw, limits, intervals, owner, points,
                                                    K.SM_KIND_UPPER)
    sm = object.__new__(SelfMotion)
    object.__setattr__(sm, "__dict__", {
        "T": T, "parameter": "swivel", "joint": None, "domain": _SWIVEL_DOMAIN.copy(),
        "periodic": True, "n_branches": 8, "intervals": intervals, "interval_branch": owner,
        "method": _SWIVEL_METHOD, "info": {"bisected": 0, "grid": 0}, "_family": sw,
        "limits": limits, "_points": points, "_records": None, "_held": False,
        "_corners": corners, "_dispatch": dispatch, "_kept": None})
    return sm


def _solves(fam: _Family) -> dict[str, int]:
    """A continued family's ``solves``, ``degenerate`` and ``dropped`` (``info``)."""
    if not isinstance(fam, _ContinuedFamily):
        return {}
    return {"solves": fam.solves, "degenerate": fam.degenerate, "dropped": fam.dropped}


#: The swivel's parameter range (copied into each SelfMotion).
_SWIVEL_DOMAIN = np.array([-np.pi, np.pi])
#: The compiled swivel's ``method``.
_SWIVEL_METHOD = "swivel closed form (SRS), compiled"
#: A crossing's row within this of another limit [rad, m] counts as inside it
#: (``SelfMotion._inside_records``: a corner's other joint at its limit, rounded).
_RECORD_SLACK = 1e-9

#: The compiled swivel's point kinds (``SM_KIND_*`` 0-3), as the records name them.
_KINDS = ("lower", "upper", "aligned axes", "fold")


def _records_of(points: np.ndarray) -> tuple[tuple[LimitCrossing, ...],
                                             tuple[SingularPoint, ...]]:
    """The records of the compiled swivel's points (p, 4) ``[psi, branch, joint, kind]``."""
    cross: list[LimitCrossing] = []
    sing: list[SingularPoint] = []
    for t, b, j, k in one_per_point(points, K.SM_KIND_ALIGNED).tolist():
        if k <= K.SM_KIND_UPPER:
            cross.append(LimitCrossing(t, int(b), int(j), _KINDS[int(k)]))
        else:
            sing.append(SingularPoint(t, int(b), _KINDS[int(k)]))
    return tuple(cross), tuple(sing)


def parameter_values(robot: ArmSource, T: np.ndarray, q: np.ndarray
                     ) -> tuple[str, np.ndarray]:
    """The self-motion parameter of configurations q (..., k, n) of poses T (..., 4, 4).

    Returns ``(name, values (..., k))``: the swivel angle on SRS arms, else the
    ``auto`` parameter's joint (without a closed form, ``continued_parameter``: a
    track, else the last joint); NaN rows give
    NaN.
    """
    owner = arm_of(robot)
    name = auto_parameter(owner) or continued_parameter(owner)
    if name != "swivel":
        return name, q[..., owner.joint_names.index(name)]
    arm = _setup(owner).swivel
    assert arm is not None
    lead = q.shape[:-2]
    Tf = np.broadcast_to(T, lead + (4, 4)).reshape(-1, 4, 4)
    qf = q.reshape((len(Tf),) + q.shape[-2:])
    out = np.stack([arm.swivel_of(arm.frame(Ti), qi) for Ti, qi in zip(Tf, qf, strict=True)])
    return name, out.reshape(q.shape[:-1])
