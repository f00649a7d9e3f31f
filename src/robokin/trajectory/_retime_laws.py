"""Time laws along a path: the fastest ``s(t)`` within joint (and tool) limits.

Two solvers, one per kind of limit set:

* :func:`topp_ra_law` -- velocity and acceleration limits (and a tool speed):
  TOPP-RA (Pham & Pham 2018) through the ``toppra`` package. toppra discretises the
  path on a grid ``s_0 .. s_N`` and computes, backwards, the *controllable sets*
  ``K_i = [x_lo, x_hi]`` of squared path speeds ``x = sd^2`` from which the end can
  still be reached at rest (its reachability analysis, paper Sec. IV). robokin
  then runs the greedy forward pass itself (paper Alg. 1, step 2): from ``x_0 =
  0``, the largest admissible path acceleration ``u`` at each stage, clipped to
  ``K_{i+1}``. toppra's own pass shaves ``x`` by ``1e-8`` (and 1e-4 relative near
  rest) at every step for numerical safety, which costs about 1e-6 s on a 1.5 s
  move; robokin's exact pass does not, and the final check below catches any
  rounding.
* :func:`jerk_limited_law` -- with jerk limits: ``ruckig`` (Berscheid & Kroeger
  2021), time-optimal for one degree of freedom, applied to the path parameter
  with constant path-space limits that keep every joint within its own over the
  whole stretch. On a straight joint-space move (a point-to-point move) these
  limits are exact and the result is the time-optimal jerk-limited move (what
  ruckig's phase synchronisation gives for all joints); on a curved stretch they
  are conservative.

**Exact final timing.** Between grid nodes TOPP-RA's path acceleration ``u`` is
constant, so ``x`` is linear in ``s`` and the time across an interval is exactly
``2 ds / (sd_i + sd_{i+1})``. Where the optimal profile switches from one active
constraint to another inside a grid interval (accelerating to cruising, cruising
to braking), the node values are exact but their chord cuts the corner; robokin
inserts the corners themselves (:func:`_insert_switches`), which makes a
rest-to-rest move along a straight joint path exact to rounding whatever the grid.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from typing import TYPE_CHECKING, Any

import numpy as np

from robokin.exceptions import InputError, MissingExtraError, RobokinError
from robokin.trajectory._retime_path import SplinePath

if TYPE_CHECKING:
    from robokin.robot import Robot

__all__ = ["ConstAccelLaw", "RuckigLaw", "StretchedLaw", "TimeLaw", "jerk_limited_law",
           "topp_ra_law"]


Derivatives = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]


class TimeLaw(ABC):
    """``s(t)`` from rest at ``s = 0`` to rest at ``s = length``.

    Attributes:
        duration: Its duration [s].
        length: The path length it covers (the path parameter's end).
        method: ``"toppra"``, ``"ruckig"`` (and ``"... x c"`` when stretched).
    """

    duration: float
    length: float
    method: str

    @abstractmethod
    def evaluate(self, t: np.ndarray) -> Derivatives:
        """``(s, sd, sdd, sddd)`` at times ``t`` in ``[0, duration]``, shape (k,) each."""

    def time_at(self, s: np.ndarray) -> np.ndarray:
        """The times [s] at which the law reaches path parameters ``s`` (k,)."""
        grid = np.linspace(0.0, self.duration, 4097)
        sg = self.evaluate(grid)[0]
        sg = np.maximum.accumulate(sg)
        return np.interp(np.asarray(s, float), sg, grid)

    def stretched(self, factor: float) -> TimeLaw:
        """The same law run ``factor`` (>= 1) times slower."""
        return StretchedLaw(self, factor)


class ConstAccelLaw(TimeLaw):
    """Piecewise-constant path acceleration between nodes ``s_i`` (TOPP-RA's form).

    Args:
        s: Nodes [path units], shape (k,), increasing, ``s[0] = 0``.
        x: Squared path speed at the nodes, shape (k,), ``x[0] = x[-1] = 0``.
        method: Label.
    """

    def __init__(self, s: np.ndarray, x: np.ndarray, method: str = "toppra") -> None:
        self.s = np.asarray(s, float)
        self.sd = np.sqrt(np.maximum(np.asarray(x, float), 0.0))
        ds = np.diff(self.s)
        v = self.sd[:-1] + self.sd[1:]
        if not (v > 0).all():
            k = int(np.flatnonzero(~(v > 0))[0])
            raise RobokinError(f"the path speed is zero on both ends of the interval "
                               f"s = {self.s[k]:.6g} .. {self.s[k + 1]:.6g}: no finite "
                               "time law passes it")
        self.dt = 2.0 * ds / v          # exact for constant acceleration
        self.u = (self.sd[1:] ** 2 - self.sd[:-1] ** 2) / (2.0 * ds)
        self.t = np.concatenate([[0.0], np.cumsum(self.dt)])
        self.duration = float(self.t[-1])
        self.length = float(self.s[-1])
        self.method = method

    def evaluate(self, t: np.ndarray) -> Derivatives:
        tt = np.clip(np.asarray(t, float), 0.0, self.duration)
        i = np.clip(np.searchsorted(self.t, tt, side="right") - 1, 0, self.u.size - 1)
        tau = tt - self.t[i]
        u = self.u[i]
        sd = np.maximum(self.sd[i] + u * tau, 0.0)
        s = np.minimum(self.s[i] + self.sd[i] * tau + 0.5 * u * tau * tau, self.length)
        return s, sd, u, np.zeros_like(tt)

    def time_at(self, s: np.ndarray) -> np.ndarray:
        ss = np.clip(np.asarray(s, float), 0.0, self.length)
        i = np.clip(np.searchsorted(self.s, ss, side="right") - 1, 0, self.u.size - 1)
        d = ss - self.s[i]
        sd0, u = self.sd[i], self.u[i]
        # s_i + sd0 tau + u tau^2 / 2 = s  ->  tau = 2 d / (sd0 + sqrt(sd0^2 + 2 u d))
        root = np.sqrt(np.maximum(sd0 * sd0 + 2.0 * u * d, 0.0))
        den = sd0 + root
        tau = np.where(den > 0, 2.0 * d / np.where(den > 0, den, 1.0), 0.0)
        out: np.ndarray = self.t[i] + np.minimum(tau, self.dt[i])
        return out


class RuckigLaw(TimeLaw):
    """A one-degree-of-freedom ruckig profile (seven constant-jerk phases).

    Args:
        profile: ``ruckig.Trajectory(1).profiles[0][0]`` (``t``, ``j`` per phase,
            ``p``, ``v``, ``a`` at the phase boundaries).
        length: The target position.
    """

    def __init__(self, profile: Any, length: float) -> None:
        self.phase_t = np.concatenate([[0.0], np.cumsum(np.asarray(profile.t, float))])
        self.j = np.asarray(profile.j, float)
        self.p = np.asarray(profile.p, float)
        self.v = np.asarray(profile.v, float)
        self.a = np.asarray(profile.a, float)
        self.duration = float(self.phase_t[-1])
        self.length = float(length)
        self.method = "ruckig"

    def evaluate(self, t: np.ndarray) -> Derivatives:
        tt = np.clip(np.asarray(t, float), 0.0, self.duration)
        k = np.clip(np.searchsorted(self.phase_t, tt, side="right") - 1, 0,
                    self.j.size - 1)
        d = tt - self.phase_t[k]
        j, a, v, p = self.j[k], self.a[k], self.v[k], self.p[k]
        s = p + d * (v + d * (a / 2.0 + d * j / 6.0))
        return (np.clip(s, 0.0, self.length), np.maximum(v + d * (a + d * j / 2.0), 0.0),
                a + d * j, j)


class StretchedLaw(TimeLaw):
    """A law run ``factor`` times slower: ``s(t / c)``; rates scale by 1/c, 1/c^2, 1/c^3."""

    base: TimeLaw
    factor: float

    def __init__(self, law: TimeLaw, factor: float) -> None:
        if not factor >= 1.0:
            raise RobokinError(f"a law is only ever slowed down, got factor {factor}")
        base = law.base if isinstance(law, StretchedLaw) else law
        c = factor * (law.factor if isinstance(law, StretchedLaw) else 1.0)
        self.base, self.factor = base, c
        self.duration = base.duration * c
        self.length = base.length
        self.method = f"{base.method} x {c:.6g}"

    def evaluate(self, t: np.ndarray) -> Derivatives:
        c = self.factor
        s, sd, sdd, sddd = self.base.evaluate(np.asarray(t, float) / c)
        return s, sd / c, sdd / c**2, sddd / c**3

    def time_at(self, s: np.ndarray) -> np.ndarray:
        out: np.ndarray = self.base.time_at(s) * self.factor
        return out


# ------------------------------------------------------------------- TOPP-RA
def _toppra() -> Any:
    try:
        import toppra
        import toppra.algorithm
        import toppra.constraint
    except ImportError:
        raise MissingExtraError("toppra", "retime") from None
    return toppra


def _needs_robot(robot: Robot | None) -> Robot:
    """The robot a tool speed limit is computed with (its Jacobian)."""
    if robot is None:
        raise InputError("robot", "a tool speed limit needs the robot (its Jacobian)")
    return robot


def _tool_rates(robot: Robot, path: SplinePath, s: np.ndarray) -> np.ndarray:
    """``|dp/ds|``: tool-point travel per unit of path parameter at ``s`` (k,)."""
    J = robot.jacobian(path(s))[..., :3, :]
    return np.asarray(np.linalg.norm(np.einsum("kij,kj->ki", J, path(s, 1)), axis=1))


def _speed_constraint(toppra: Any, dof: int, x_max: Any) -> Any:
    """A toppra first-order constraint ``x <= x_max(path, grid)`` in float64.

    toppra's own ``JointVelocityConstraint`` computes its bound in single precision
    (0.49 becomes 0.48999998), a 4e-8 error either way; this one is exact.
    """

    class SpeedBound(toppra.constraint.LinearConstraint):
        def __init__(self) -> None:
            super().__init__()
            self.dof = dof

        def compute_constraint_params(self, path: Any, gridpoints: np.ndarray,
                                      *args: Any, **kwargs: Any) -> tuple:
            xbound = np.zeros((gridpoints.size, 2))
            xbound[:, 1] = x_max(path, gridpoints)
            return None, None, None, None, None, None, xbound

    return SpeedBound()


def _joint_speed_bound(v_max: np.ndarray) -> Any:
    """``x_max(s) = min_j (v_j / |q_j'(s)|)^2``: every joint within its speed."""
    def x_max(path: Any, grid: np.ndarray) -> np.ndarray:
        dq = np.abs(path(grid, 1))
        with np.errstate(divide="ignore", over="ignore"):
            out: np.ndarray = np.minimum(((v_max / dq) ** 2).min(axis=1), 1e300)
        return out
    return x_max


def _tool_speed_bound(robot: Robot, v_tool: float) -> Any:
    """``x_max(s) = (v_tool / |dp/ds|)^2``: the tool point within ``v_tool``."""
    def x_max(path: Any, grid: np.ndarray) -> np.ndarray:
        rate = _tool_rates(robot, path, grid)
        out: np.ndarray = np.minimum(v_tool**2 / np.maximum(rate * rate, 1e-300),
                                     1e300)
        return out
    return x_max


def _stage_rows(constraints: list[Any], path: SplinePath, grid: np.ndarray
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Every constraint at every stage as rows ``A u + B x <= C``, and the x caps.

    Returns:
        ``A, B, C`` of shape (N + 1, R) and ``x_hi`` (N + 1,) from the first-order
        (``xbound``) constraints.
    """
    A, B, C = [], [], []
    x_hi = np.full(grid.size, np.inf)
    for con in constraints:
        a, b, c, F, g, ubound, xbound = con.compute_constraint_params(path, grid)
        if xbound is not None:
            x_hi = np.minimum(x_hi, np.asarray(xbound)[:, 1])
        if ubound is not None:  # u_lo <= u <= u_hi as two rows
            ub = np.asarray(ubound)
            one = np.ones((grid.size, 1))
            A += [one, -one]
            B += [0 * one, 0 * one]
            C += [ub[:, 1:2], -ub[:, 0:1]]
        if a is None:
            continue
        if F.ndim == 2:  # identical at every stage
            A.append(a @ F.T)
            B.append(b @ F.T)
            C.append(g[None, :] - c @ F.T)
        else:
            A.append(np.einsum("ikm,im->ik", F, a))
            B.append(np.einsum("ikm,im->ik", F, b))
            C.append(g - np.einsum("ikm,im->ik", F, c))
    if not A:
        z = np.zeros((grid.size, 1))
        return z, z, z + np.inf, x_hi
    return np.hstack(A), np.hstack(B), np.hstack(C), x_hi


def _forward_pass(A: np.ndarray, B: np.ndarray, C: np.ndarray, x_cap: np.ndarray,
                  K: np.ndarray, grid: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Greedy forward pass (Pham & Pham 2018, Alg. 1), without a safety shave.

    From each stage the largest admissible ``u``, clipped into the next
    controllable set.

    Returns:
        ``x`` (N + 1,) and, per interval (N,), what set its end: 0 the largest
        acceleration, 1 the speed cap, 2 the controllable set (braking).
    """
    n = grid.size
    ds = np.diff(grid)
    x = np.zeros(n)
    why = np.zeros(n - 1, np.int8)
    pos, neg = A > 1e-300, A < -1e-300
    for i in range(n - 1):
        rhs = C[i] - B[i] * x[i]
        p, q = pos[i], neg[i]
        u_hi = float((rhs[p] / A[i, p]).min()) if p.any() else 1e300
        u_lo = float((rhs[q] / A[i, q]).max()) if q.any() else -1e300
        reach = x[i] + 2.0 * ds[i] * u_hi
        cap = min(K[i + 1, 1], x_cap[i + 1])
        why[i] = 0 if reach <= cap else (
            2 if K[i + 1, 1] < x_cap[i + 1] * (1.0 - 1e-9) else 1)
        x[i + 1] = max(min(reach, cap), x[i] + 2.0 * ds[i] * u_lo, K[i + 1, 0], 0.0)
    x[-1] = 0.0
    return x, why


def _insert_switches(s: np.ndarray, x: np.ndarray, why: np.ndarray, A: np.ndarray,
                     B: np.ndarray, C: np.ndarray, x_cap: np.ndarray, feasible: Any
                     ) -> tuple[np.ndarray, np.ndarray]:
    """Put the switch points of ``x(s)`` that fall inside a grid interval on nodes.

    A switch (from accelerating to cruising or braking, from cruising to braking)
    lies in the first interval whose end was set by another bound than the
    interval before (``why``; accelerating before the first), or in the first or
    last interval. Within it the
    optimal ``x(s)`` is (to first order) the lowest of three lines: accelerating at
    the largest admissible ``u`` from ``(s_i, x_i)``, braking at the most negative
    ``u`` into ``(s_{i+1}, x_{i+1})``, and the speed cap. Each is at least the
    chord at both ends, so their lower envelope is never below it; its corners
    become nodes, when every limit holds at them (``feasible(s, x, u)``, with the
    path accelerations on both sides; on a curved path the lines are only first
    order, and a corner that would overshoot is left out). Along a stretch that
    follows one constraint nothing changes.
    """
    add_s, add_x = [], []
    switch = np.flatnonzero(why != np.concatenate([[0], why[:-1]]))
    switch = np.union1d(switch, [0, why.size - 1])  # the ends, always
    for i in switch.tolist():
        h = s[i + 1] - s[i]
        lines = []
        f = 2.0 * _u_bound(A, B, C, i, x[i], True)
        if math.isfinite(f):
            lines.append((x[i], f))
        b = 2.0 * _u_bound(A, B, C, i + 1, x[i + 1], False)
        if -math.inf < b < 0.0:
            lines.append((x[i + 1] - b * h, b))
        if np.isfinite(x_cap[i]) and np.isfinite(x_cap[i + 1]):
            lines.append((x_cap[i], (x_cap[i + 1] - x_cap[i]) / h))
        ds = []
        for k, (x0, m0) in enumerate(lines):
            for x1, m1 in lines[k + 1:]:
                if m0 != m1:
                    d = (x1 - x0) / (m0 - m1)
                    # a corner closer to a node gains nothing (< 1e-6 of the
                    # interval's time) and its tiny interval would carry a
                    # path acceleration spoilt by rounding
                    if 1e-6 * h < d < (1.0 - 1e-6) * h:
                        ds.append(d)
        last = -math.inf
        new_d, new_x = [], []
        for d in sorted(ds):
            if d - last < 1e-6 * h:  # lines meeting in one point (an apex on the cap)
                continue
            last = d
            env = min(x0 + m * d for x0, m in lines)
            chord = x[i] + (x[i + 1] - x[i]) * d / h
            if env - chord > 1e-12 * env:
                new_d.append(d)
                new_x.append(env)
        if not new_d:
            continue
        nd = np.concatenate([[0.0], new_d, [h]])
        nx = np.concatenate([[x[i]], new_x, [x[i + 1]]])
        u = np.diff(nx) / (2.0 * np.diff(nd))
        ss = s[i] + nd[1:-1]
        if feasible(ss, nx[1:-1], u[:-1]).all() and feasible(ss, nx[1:-1], u[1:]).all():
            add_s += list(ss)
            add_x += list(nx[1:-1])
    if not add_s:
        return s, x
    s2 = np.concatenate([s, add_s])
    order = np.argsort(s2, kind="stable")
    return s2[order], np.concatenate([x, add_x])[order]


def _u_bound(A: np.ndarray, B: np.ndarray, C: np.ndarray, i: int, x: float,
             upper: bool) -> float:
    """The largest (or smallest) admissible path acceleration at stage i and ``x``."""
    rhs = C[i] - B[i] * x
    sel = A[i] > 1e-300 if upper else A[i] < -1e-300
    if not sel.any():
        return math.inf if upper else -math.inf
    vals = rhs[sel] / A[i, sel]
    return float(vals.min() if upper else vals.max())


def topp_ra_law(path: SplinePath, v_max: np.ndarray, a_max: np.ndarray, *,
                robot: Robot | None = None, tool_speed: float | None = None,
                grid_points: int | None = None) -> ConstAccelLaw:
    """The time-optimal law along ``path`` within joint speed and acceleration limits.

    Args:
        path: The stretch, run from rest to rest.
        v_max: Joint speed limits [rad/s or m/s], shape (n,).
        a_max: Joint acceleration limits [rad/s^2 or m/s^2], shape (n,).
        robot: For the tool speed (its Jacobian), else None.
        tool_speed: Largest tool-point speed [m/s], or None.
        grid_points: Grid intervals, uniform (default: the spline's knots, where
            ``q''`` peaks, and at least 100).

    Returns:
        A :class:`ConstAccelLaw`.

    Raises:
        MissingExtraError: toppra is not installed.
        RobokinError: toppra finds the path not controllable (a numerical failure;
            a rest-to-rest path under these limits always is).

    References:
        Pham, H., Pham, Q.-C., "A New Approach to Time-Optimal Path
        Parameterization Based on Reachability Analysis", IEEE Transactions on
        Robotics 34(3), 645-659, 2018.
    """
    toppra = _toppra()
    if grid_points:
        grid = np.linspace(0.0, path.length, grid_points + 1)
    else:  # the knots (where q'' peaks: it is linear between them), at least 100
        grid = np.union1d(path.knots, np.linspace(0.0, path.length, 101))
        grid = grid[np.concatenate([[True], np.diff(grid) > 1e-9 * path.length])]
        grid[-1] = path.length
    tc = toppra.constraint
    cons = [_speed_constraint(toppra, path.dof, _joint_speed_bound(v_max)),
            tc.JointAccelerationConstraint(
                a_max, discretization_scheme=tc.DiscretizationType.Interpolation)]
    if tool_speed is not None:
        cons.append(_speed_constraint(toppra, path.dof,
                                      _tool_speed_bound(_needs_robot(robot), tool_speed)))
    algo = toppra.algorithm.TOPPRA(cons, path, gridpoints=grid, solver_wrapper="seidel")
    K = algo.compute_controllable_sets(0.0, 0.0)
    if np.isnan(K).any() or K[0, 0] > 1e-9 * max(1.0, float(K[:, 1].max())):
        raise RobokinError("toppra found the path not controllable (a numerical "
                           "failure); try other grid_points")
    A, B, C, x_cap = _stage_rows(cons, path, grid)
    x, why = _forward_pass(A, B, C, x_cap, K, grid)
    speed_bounds = [_joint_speed_bound(v_max)] + (
        [] if tool_speed is None else [_tool_speed_bound(_needs_robot(robot), tool_speed)])

    def feasible(s: np.ndarray, x: np.ndarray, u: np.ndarray) -> np.ndarray:
        """Every limit at path points ``s`` with ``sd^2 = x`` and ``sdd = u``."""
        qdd = path(s, 2) * x[:, None] + path(s, 1) * u[:, None]
        ok: np.ndarray = (np.abs(qdd) <= a_max * (1 + 1e-12)).all(axis=1)
        for bound in speed_bounds:
            ok &= x <= bound(path, s) * (1 + 1e-12)
        return ok

    s, x = _insert_switches(grid, x, why, A, B, C, x_cap, feasible)
    return ConstAccelLaw(s, x, "toppra")


# -------------------------------------------------------------------- ruckig
def path_space_limits(path: SplinePath, v: np.ndarray, a: np.ndarray, j: np.ndarray,
                      tool_rate: float = 0.0, tool_speed: float | None = None
                      ) -> tuple[float, float, float]:
    """Constant path-space limits ``(V, A, J)`` that keep every joint within its own.

    They hold along the whole stretch, for speed, acceleration and jerk.

    With ``g1, g2, g3`` the largest ``|q'|, |q''|, |q'''|`` of a joint on the
    stretch, ``qd = q' sd``, ``qdd = q'' sd^2 + q' sdd`` and ``qddd = q''' sd^3 +
    3 q'' sd sdd + q' sddd`` stay within ``v, a, j`` when ``g1 V <= v``, ``g2 V^2 +
    g1 A <= a`` and ``g3 V^3 + 3 g2 V A + g1 J <= j``. ``V`` first takes at most
    half the acceleration budget and a third of the jerk budget for the curvature
    terms, ``A`` what acceleration is left, ``J`` the rest (A halved until J keeps
    a twentieth of its budget). For a straight joint path (``g2 = g3 = 0``) these are
    exactly ``v / g1``, ``a / g1``, ``j / g1``: the path is as fast as its slowest
    joint allows.
    """
    g1, g2, g3 = path.extremes()
    moving = g1 > 0
    g1, g2, g3 = g1[moving], g2[moving], g3[moving]
    v, a, j = v[moving], a[moving], j[moving]
    with np.errstate(divide="ignore"):
        V = float(np.min(np.concatenate([
            v / g1, np.sqrt(a / (2.0 * g2)), np.cbrt(j / (3.0 * g3))])))
        if tool_speed is not None and tool_rate > 0:
            V = min(V, tool_speed / tool_rate)
        acc = float(np.min((a - g2 * V * V) / g1))
        for _ in range(60):
            jerk = float(np.min((j - g3 * V**3 - 3.0 * g2 * V * acc) / g1))
            if jerk >= 0.05 * float(np.min(j / g1)):
                break
            acc *= 0.5
    return V, acc, jerk


def jerk_limited_law(path: SplinePath, v_max: np.ndarray, a_max: np.ndarray,
                     j_max: np.ndarray, *, robot: Robot | None = None,
                     tool_speed: float | None = None) -> RuckigLaw:
    """A jerk-limited rest-to-rest law along ``path`` (ruckig on the path parameter).

    Args:
        path: The stretch.
        v_max: Joint speed limits, shape (n,).
        a_max: Joint acceleration limits, shape (n,).
        j_max: Joint jerk limits [rad/s^3 or m/s^3], shape (n,).
        robot: For the tool speed, else None.
        tool_speed: Largest tool-point speed [m/s], or None.

    Returns:
        A :class:`RuckigLaw` (time-optimal for a straight joint path; see
        :func:`path_space_limits` for curved ones).

    Raises:
        MissingExtraError: ruckig is not installed.
        RobokinError: ruckig fails.

    References:
        Berscheid, L., Kroeger, T., "Jerk-limited Real-time Trajectory Generation
        with Arbitrary Target States", Robotics: Science and Systems XVII, 2021.
    """
    try:
        import ruckig
    except ImportError:
        raise MissingExtraError("ruckig", "retime") from None
    rate = 0.0
    if tool_speed is not None:
        k = path.knots
        s = np.sort(np.concatenate([k, (k[:-1] + k[1:]) / 2]))
        rate = float(_tool_rates(_needs_robot(robot), path, s).max())
    V, A, J = path_space_limits(path, v_max, a_max, j_max, rate, tool_speed)
    inp = ruckig.InputParameter(1)
    inp.current_position = [0.0]
    inp.target_position = [path.length]
    inp.max_velocity = [V]
    inp.max_acceleration = [A]
    inp.max_jerk = [J]
    out = ruckig.Trajectory(1)
    result = ruckig.Ruckig(1).calculate(inp, out)
    if result not in (ruckig.Result.Working, ruckig.Result.Finished):
        raise RobokinError(f"ruckig failed ({result}) on a stretch of length "
                           f"{path.length:.6g} with V {V:.6g}, A {A:.6g}, J {J:.6g}")
    law = RuckigLaw(out.profiles[0][0], path.length)
    if not math.isclose(law.duration, out.duration, rel_tol=1e-12, abs_tol=1e-12):
        raise RobokinError("ruckig returned a profile with a braking phase")
    return law
