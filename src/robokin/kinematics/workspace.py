r"""Workspace analysis: where the tool point can go, and how much space that is.

Monte-Carlo sampling of the joint space inside the joint limits, pushed through the
compiled batch FK: the reachable point cloud, its bounding box, cross-section
plots in the XY / XZ planes and a manipulability colouring; and the volume of the
**position workspace**: the set of points the tool point reaches inside the joint
limits, with any orientation (the "reachable workspace" of Kumar and Waldron,
"The workspace of a mechanical manipulator", J. Mech. Des. 103(3), 1981).

The volume is a hit-or-miss Monte-Carlo integral over a box ``B`` that holds the
set (Hammersley and Handscomb, "Monte Carlo Methods", 1964, ch. 5): M points
uniform in the box, each tested for membership by a position-only inverse
kinematics (:func:`position_reachable`), H of them reached:

.. math::

    \hat V = |B| \, \frac{H}{M}, \qquad
    \operatorname{se}(\hat V) = |B| \sqrt{\hat p (1 - \hat p) / M},
    \quad \hat p = H / M

An unbiased estimate with its standard error, whatever M: a reached point is
proven reachable (a configuration inside the limits puts the tool point within
``tol`` of it), and a random subset of the missed points is solved again,
thoroughly (many restarts), to count the fast test's false misses; those found
are folded into the estimate and its standard error (:class:`VolumeEstimate`).
The box is the sampled
cloud's bounds grown by 10 % of the extent on every side (and grown again if a
reached point lies in the outer half of that margin), cut to the ball no
configuration leaves (:func:`reach_ball`); points outside the ball count as
misses without a solve.

(The voxel count of the cloud this replaces, ``occupied voxels * h^3``, depended
on the sample count: the UR5 gave 0.126, 0.937 and 2.45 m^3 at 20,000, 200,000
and 1,000,000 samples, for a set of about 3.5 m^3; issue 25.)
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from robokin.exceptions import InputError
from robokin.kinematics import forward
from robokin.kinematics.arm import Arm, ArmSource, arm_of
from robokin.kinematics.jacobian import manipulability as _manipulability

if TYPE_CHECKING:
    from robokin.model.chain import Chain

__all__ = [
    "VolumeEstimate",
    "Workspace",
    "position_reachable",
    "random_joints",
    "reach_ball",
    "sample_workspace",
]

#: Position tolerance [m] of the membership test: a point within it of the set
#: counts as reached (a shell of 1 um: below 1e-5 m^3 on an arm's surface).
REACH_TOL = 1e-6
_MARGIN = 0.10  # of the cloud's extent, on every side of the volume's box
_MAX_GROWTH = 3  # times the box may grow when reached points crowd its margin
_RECHECK = 500  # missed points solved again, thoroughly
_THOROUGH = {"max_restarts": 64, "max_iterations": 300}
_VOLUME_CHUNK = 50_000  # membership tests between progress reports
DEFAULT_VOLUME_POINTS = 200_000


@dataclass(frozen=True, eq=False)
class VolumeEstimate:
    """The volume of the position workspace, by hit-or-miss Monte Carlo.

    "Volume" is that of the set of points the tool point reaches inside the
    joint limits with any orientation (see :mod:`robokin.kinematics.workspace`).

    Attributes:
        value: The estimate ``|B| H / M`` [m^3] (H with the rescued share of
            the misses added, see ``rescued``).
        std_error: Its standard error ``|B| sqrt(p (1 - p) / M)`` [m^3]
            (p = H / M; plus the rescue fraction's sampling error).
        interval: 95 % Wilson score interval ``[lo, hi]`` [m^3] of the
            binomial part (meaningful even when no point, or every point, is
            reached).
        points: M, the test points drawn uniformly in the box.
        hits: H, the test points reached by the membership test.
        region: The box ``[[x0, y0, z0], [x1, y1, z1]]`` [m] in the world.
        rechecked: Missed points (inside the reach ball) solved again with 64
            restarts of 300 iterations: a random subset of the F misses.
        rescued: How many of those the thorough solve reached (0 expected):
            ``F * rescued / rechecked`` more hits are folded into ``value``,
            and the uncertainty of that fraction into ``std_error``.
    """

    value: float
    std_error: float
    interval: np.ndarray
    points: int
    hits: int
    region: np.ndarray
    rechecked: int
    rescued: int

    @property
    def box_volume(self) -> float:
        """Volume of the sampled box |B| [m^3]."""
        return float(np.prod(self.region[1] - self.region[0]))

    def summary(self) -> dict[str, Any]:
        """Plain numbers for reports and JSON."""
        return {
            "volume_m3": self.value,
            "volume_std_error_m3": self.std_error,
            "volume_95_interval_m3": self.interval.tolist(),
            "volume_points": self.points,
            "volume_hits": self.hits,
            "volume_region_m": self.region.tolist(),
            "misses_rechecked": self.rechecked,
            "misses_rescued": self.rescued,
        }


@dataclass(frozen=True, eq=False)
class Workspace:
    """A Monte-Carlo sample of a robot's reachable tool positions.

    Attributes:
        robot_name: The robot's name.
        points: Tool positions in the world frame [m], shape (N, 3).
        q: The joint samples behind ``points`` [rad, m], shape (N, n), or None
            when not kept.
        bounds: ``[[xmin, ymin, zmin], [xmax, ymax, zmax]]`` of ``points`` [m],
            shape (2, 3).
        volume_estimate: The volume of the position workspace with its
            uncertainty (:class:`VolumeEstimate`), or None when not estimated.
        manipulability_index: Indices into ``points`` of the subset whose
            manipulability was computed, shape (K,).
        manipulability: Yoshikawa manipulability of that subset, shape (K,).
    """

    robot_name: str
    points: np.ndarray
    q: np.ndarray | None
    bounds: np.ndarray
    volume_estimate: VolumeEstimate | None
    manipulability_index: np.ndarray
    manipulability: np.ndarray

    @property
    def n_samples(self) -> int:
        """Number of samples N."""
        return int(self.points.shape[0])

    @property
    def extent(self) -> np.ndarray:
        """Bounding-box edge lengths [m], shape (3,)."""
        extent: np.ndarray = self.bounds[1] - self.bounds[0]
        return extent

    @property
    def volume(self) -> float:
        """Volume of the position workspace [m^3] (NaN when not estimated)."""
        return math.nan if self.volume_estimate is None else self.volume_estimate.value

    @property
    def volume_std_error(self) -> float:
        """Standard error of :attr:`volume` [m^3] (NaN when not estimated)."""
        e = self.volume_estimate
        return math.nan if e is None else e.std_error

    def summary(self) -> dict[str, Any]:
        """Plain numbers for reports and JSON."""
        out: dict[str, Any] = {
            "robot": self.robot_name,
            "samples": self.n_samples,
            "bounds_min_m": self.bounds[0].tolist(),
            "bounds_max_m": self.bounds[1].tolist(),
        }
        if self.volume_estimate is not None:
            out["volume_of"] = ("the position workspace: points the tool point reaches "
                                "inside the joint limits, any orientation")
            out.update(self.volume_estimate.summary())
        out["manipulability_max"] = (float(self.manipulability.max())
                                     if self.manipulability.size else 0.0)
        return out


def _sampling_limits(robot: Arm) -> np.ndarray:
    lim = np.array(robot.limits, dtype=float)
    rev = np.asarray(robot.is_revolute, dtype=bool)
    for i in range(lim.shape[0]):
        lo, hi = lim[i]
        if rev[i]:
            # A revolute joint never needs more than one turn to cover its positions.
            if not math.isfinite(lo) or not math.isfinite(hi) or hi - lo > 2 * math.pi:
                mid = (
                    0.0
                    if not (math.isfinite(lo) and math.isfinite(hi))
                    else 0.5 * (lo + hi)
                )
                lim[i] = (mid - math.pi, mid + math.pi)
        elif not (math.isfinite(lo) and math.isfinite(hi)):
            name = robot.joint_names[i]
            raise InputError(
                "robot",
                f"prismatic joint '{name}' has no finite limits [{lo}, {hi}]; "
                "a workspace needs a bounded stroke",
            )
    return lim


def random_joints(
    rng: np.random.Generator, limits: npt.ArrayLike, count: int
) -> np.ndarray:
    """Uniform joint samples inside the limits.

    Args:
        rng: The random generator.
        limits: Finite joint limits [rad, m], shape (n, 2).
        count: Number of samples.

    Returns:
        Joint samples, shape (count, n).
    """
    lim = np.asarray(limits, dtype=float)
    if lim.ndim != 2 or lim.shape[1] != 2 or not np.isfinite(lim).all():
        raise InputError(
            "limits", f"expected finite limits of shape (n, 2), got {lim.shape}"
        )
    u = rng.random((int(count), lim.shape[0]))
    q: np.ndarray = lim[:, 0] + u * (lim[:, 1] - lim[:, 0])
    return q


def reach_ball(chain: Chain) -> tuple[np.ndarray, float]:
    """A ball no configuration takes the tool point out of.

    Every point of the chain ``T(q) = C_0 J_1 C_1 ... J_n C_n`` lies within
    the sum of the translation lengths after ``C_0`` (``|t(C_k)|``, k >= 1,
    plus the largest stroke of each prismatic joint over the limits) of the
    origin of ``C_0``: rotations keep lengths.

    Args:
        chain: The canonical chain.

    Returns:
        ``(centre (3,) [m], radius [m])``; the radius is inf when a prismatic
        joint has no finite stroke.
    """
    arr = chain.arrays
    consts = np.asarray(arr.consts).reshape(-1, 4, 4)
    radius = float(np.linalg.norm(consts[1:, :3, 3], axis=-1).sum())
    lo, hi = np.asarray(arr.lower), np.asarray(arr.upper)
    with np.errstate(invalid="ignore"):
        far = np.maximum(np.abs(lo), np.abs(hi))  # largest |q_j| over the limits
    for k in np.flatnonzero(np.asarray(arr.kind) != 0.0):  # prismatic chain joints
        # v_k = sign (M q + c)_k + offset_k over the limits box
        row = np.asarray(arr.M)[k]
        used = row != 0.0
        radius += abs(arr.sign[k] * arr.c[k] + arr.offset[k]) + float(
            np.abs(row[used]) @ far[used])
    return consts[0, :3, 3].copy(), radius if math.isfinite(radius) else math.inf


def position_reachable(
    robot: ArmSource,
    points: npt.ArrayLike,
    *,
    seeds: npt.ArrayLike | None = None,
    tol: float = REACH_TOL,
    max_restarts: int = 4,
    max_iterations: int = 100,
) -> np.ndarray:
    """Which points the tool point reaches inside the joint limits, any orientation.

    A position-only inverse kinematics per point (the compiled damped least
    squares of :func:`robokin.kinematics.ik.numeric.solve`, ``mask="xyz"``):
    one descent from the seed, then from the four seed-table configurations
    whose tool points are nearest the point. A point is reached when a
    configuration inside the limits puts the tool point within ``tol`` of it,
    so every True is proven; a False is "not found", which for points inside
    the set happens rarely (see :class:`VolumeEstimate`'s ``rescued``).

    Args:
        robot: The robot.
        points: Positions in the world [m], shape (..., 3).
        seeds: First guesses (..., n) [rad, m], e.g. the joints of the nearest
            sampled tool point; default the middle of the limits.
        tol: Position tolerance [m].
        max_restarts: Restarts after the first descent: the first four from
            the seed table, then random ones (seeded: same points, same answer).
        max_iterations: Iterations per descent.

    Returns:
        Shape (...) bool.

    Raises:
        InputError: points not (..., 3) finite numbers, bad seeds.
    """
    robot = arm_of(robot)
    from robokin._validation import check_finite
    from robokin.kinematics.ik.numeric import solve

    p = check_finite(np.asarray(points, dtype=np.float64), "points")
    if p.ndim == 0 or p.shape[-1] != 3:
        raise InputError("points", f"expected positions (..., 3), got shape {p.shape}")
    lead = p.shape[:-1]
    flat = p.reshape(-1, 3)
    T = np.zeros((flat.shape[0], 4, 4))
    T[:, 0, 0] = T[:, 1, 1] = T[:, 2, 2] = T[:, 3, 3] = 1.0
    T[:, :3, 3] = flat
    q0 = None
    if seeds is not None:
        q0 = np.asarray(seeds, dtype=np.float64)
        if q0.shape != lead + (robot.n,):
            raise InputError("seeds", f"expected one configuration per point, shape "
                             f"{lead + (robot.n,)}, got {q0.shape}")
        q0 = q0.reshape(-1, robot.n)
    if flat.shape[0] == 0:
        return np.zeros(lead, dtype=bool)
    res = solve(robot, T, q0=q0, mask="xyz", tol=tol, max_restarts=max_restarts,
                max_iterations=max_iterations, rng=np.random.default_rng(0))
    return np.asarray(res.success, dtype=bool).reshape(lead)


def _wilson(hits: float, m: int, z: float = 1.959963984540054) -> tuple[float, float]:
    """95 % Wilson score interval of a binomial proportion (Wilson, JASA 22, 1927)."""
    if m == 0:
        return 0.0, 1.0
    p = hits / m
    d = 1.0 + z * z / m
    c = (p + z * z / (2 * m)) / d
    h = z * math.sqrt(p * (1 - p) / m + z * z / (4 * m * m)) / d
    return max(0.0, c - h), min(1.0, c + h)


def _volume_box(robot: Arm, bounds: np.ndarray, margin: float) -> np.ndarray:
    """The cloud's bounds grown by ``margin`` of the extent, cut to the reach ball."""
    extent = bounds[1] - bounds[0]
    pad = margin * np.maximum(extent, 1e-3 * max(float(extent.max()), 1e-3))
    box = np.stack([bounds[0] - pad, bounds[1] + pad])
    centre, radius = reach_ball(robot.chain)
    if math.isfinite(radius):
        box = np.stack([np.maximum(box[0], centre - radius),
                        np.minimum(box[1], centre + radius)])
    return box


def _membership(robot: Arm, X: np.ndarray, tree: Any, sample_q: np.ndarray,
                progress: Callable[[int], None] | None) -> tuple[np.ndarray, np.ndarray]:
    """position_reachable of X (M, 3), seeded by the nearest samples, in chunks.

    Returns ``(hit (M,), seed (M,) sample index)``; points outside the reach
    ball are misses without a solve (seed -1).
    """
    centre, radius = reach_ball(robot.chain)
    inside = np.linalg.norm(X - centre, axis=-1) <= radius
    hit = np.zeros(X.shape[0], dtype=bool)
    seed = np.full(X.shape[0], -1, dtype=np.int64)
    for a in range(0, X.shape[0], _VOLUME_CHUNK):
        b = min(a + _VOLUME_CHUNK, X.shape[0])
        sel = a + np.flatnonzero(inside[a:b])
        if sel.size:
            seed[sel] = tree.query(X[sel], k=1, workers=-1)[1]
            hit[sel] = position_reachable(robot, X[sel], seeds=sample_q[seed[sel]])
        if progress is not None:
            progress(b)
    return hit, seed


def _sample_box(robot: Arm, bounds: np.ndarray, M: int, rng: np.random.Generator,
                tree: Any, sample_q: np.ndarray, progress: Callable[[int], None] | None,
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``(box, X, hit, seed)``: M test points in a box that holds the set.

    The box starts at the cloud's bounds grown by :data:`_MARGIN`; while a
    reached point lies in the outer half of the margin (on a side the reach
    ball does not cut) the set may reach past it, and the margin doubles.
    """
    margin = _MARGIN
    for _ in range(_MAX_GROWTH + 1):
        box = _volume_box(robot, bounds, margin)
        X = box[0] + rng.random((M, 3)) * (box[1] - box[0])
        hit, seed = _membership(robot, X, tree, sample_q, progress)
        inner = _volume_box(robot, bounds, margin / 2)
        fixed = np.isclose(box, _volume_box(robot, bounds, 2 * margin))  # ball-cut sides
        crowded = ((X[hit] < inner[0]) & ~fixed[0]) | ((X[hit] > inner[1]) & ~fixed[1])
        if not crowded.any():
            break
        margin *= 2
    return box, X, hit, seed


def _estimate_volume(robot: Arm, points: np.ndarray, sample_q: np.ndarray,
                     bounds: np.ndarray, M: int, rng: np.random.Generator,
                     progress: Callable[[int], None] | None) -> VolumeEstimate:
    """The hit-or-miss estimate (see the module docstring) with M test points."""
    from scipy.spatial import cKDTree

    tree = cKDTree(points)
    box, X, hit, seed = _sample_box(robot, bounds, M, rng, tree, sample_q, progress)
    # the fast test's false misses, counted on a random subset of its misses
    missed = np.flatnonzero(~hit & (seed >= 0))
    F = missed.size
    sub = rng.choice(missed, min(_RECHECK, F), replace=False) if F else missed
    rescued = int(position_reachable(robot, X[sub], seeds=sample_q[seed[sub]],
                                      **_THOROUGH).sum()) if sub.size else 0
    f = rescued / sub.size if sub.size else 0.0
    hits = float(hit.sum() + F * f)
    vol = float(np.prod(box[1] - box[0]))
    p = hits / M
    var = M * p * (1 - p) + (F * F * f * (1 - f) / sub.size if sub.size else 0.0)
    lo, hi = _wilson(hits, M)
    region = box.copy()
    interval = np.array([lo * vol, hi * vol])
    for arr in (region, interval):
        arr.setflags(write=False)
    return VolumeEstimate(value=vol * p, std_error=vol * math.sqrt(var) / M,
                          interval=interval, points=M, hits=int(hit.sum()), region=region,
                          rechecked=int(sub.size), rescued=rescued)


def _count(value: Any, name: str, minimum: int) -> int:
    if isinstance(value, bool) or not isinstance(value, int | np.integer) or value < minimum:
        raise InputError(name, f"expected an integer >= {minimum}, got {value!r:.40}")
    return int(value)


def sample_workspace(
    robot: ArmSource,
    n_samples: int = 1_000_000,
    *,
    rng: np.random.Generator | None = None,
    volume_points: int | None = None,
    chunk: int = 250_000,
    keep_q: bool = False,
    manipulability_samples: int = 50_000,
    progress: Callable[[int, int], None] | None = None,
) -> Workspace:
    """Sample the reachable workspace of the tool point and estimate its volume.

    Joints are drawn uniformly inside their limits (revolute joints with more
    than one turn of travel, or none, are sampled over one turn); FK runs in
    compiled batches of ``chunk`` samples. The volume is that of the position
    workspace (any orientation), by hit-or-miss Monte Carlo with a
    position-only IK membership test seeded from the nearest sample (see the
    module docstring), reported with its standard error.

    Args:
        robot: The robot.
        n_samples: Number of joint samples N (>= 1).
        rng: Random generator; ``np.random.default_rng(0)`` when None.
        volume_points: Test points M of the volume estimate (its relative
            standard error is about ``sqrt((1 - p) / (p M))``, p the fraction
            of the box the set fills: 0.3 % for the UR5 at the default);
            default ``min(N, 200_000)``; 0 to skip the volume.
        chunk: Samples per FK batch.
        keep_q: Keep the joint samples in ``Workspace.q``.
        manipulability_samples: Size of the random subset whose
            manipulability is computed (for the colouring), 0 to skip.
        progress: Called as ``progress(done, total)`` after every batch of
            samples and of volume test points (``total = N + M``).

    Returns:
        The :class:`Workspace`.

    Raises:
        InputError: a count that is not a positive integer (``volume_points``:
            not >= 0), or a prismatic joint without finite limits.
    """
    robot = arm_of(robot)
    n_samples = _count(n_samples, "n_samples", 1)
    chunk = _count(chunk, "chunk", 1)
    M = min(n_samples, DEFAULT_VOLUME_POINTS) if volume_points is None else _count(
        volume_points, "volume_points", 0)
    rng = np.random.default_rng(0) if rng is None else rng
    lim = _sampling_limits(robot)
    k = max(0, min(int(manipulability_samples), n_samples))
    points = np.empty((n_samples, 3))
    q_all = np.empty((n_samples, robot.n)) if keep_q or M else None
    # The samples are i.i.d., so the first k of them are a random subset.
    q_sub = np.empty((k, robot.n))
    total = n_samples + M
    done = 0
    while done < n_samples:
        m = min(chunk, n_samples - done)
        q = random_joints(rng, lim, m)
        T = forward.forward_kinematics(robot.chain, q)
        points[done : done + m] = T[:, :3, 3]
        if q_all is not None:
            q_all[done : done + m] = q
        if done < k:
            q_sub[done : min(k, done + m)] = q[: k - done]
        done += m
        if progress is not None:
            progress(done, total)
    bounds = np.stack([points.min(axis=0), points.max(axis=0)])
    estimate = None
    if M and q_all is not None:
        tick = None if progress is None else (lambda d: progress(n_samples + d, total))
        estimate = _estimate_volume(robot, points, q_all, bounds, M, rng, tick)
    sub = np.arange(k, dtype=np.int64)
    w = _manipulability(robot.chain, q_sub) if k else np.zeros(0)
    for arr in (points, bounds, sub, w):
        arr.setflags(write=False)
    return Workspace(
        robot_name=robot.name,
        points=points,
        q=q_all if keep_q else None,
        bounds=bounds,
        volume_estimate=estimate,
        manipulability_index=sub,
        manipulability=w,
    )
