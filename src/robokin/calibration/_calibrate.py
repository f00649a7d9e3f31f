"""``calibrate``: identify a robot's kinematic errors from measured tool positions or poses.

The steps (see ``docs/calibration.md``):

1. the identification model of the nominal robot (DH rows, Hayati's ``beta``
   instead of ``d`` on near-parallel axes: :mod:`robokin.calibration._model`);
2. the measuring frame (and the tool) registered in closed form
   (:mod:`robokin.calibration._register`), so any tracker placement converges;
3. the parameters absorbed by construction left out, with the reason
   (:func:`~robokin.calibration._identify.structural_rules`);
4. a least-squares fit (``scipy.optimize.least_squares``, exact Jacobian); when
   poses lie beyond a chi-square limit of the robust noise estimate, a robust
   (``soft_l1``) fit sets them aside, and the inliers are fitted again;
5. identifiability judged by rank at the estimate, on a rich synthetic pose set
   (parameters that trade with others for every pose are dropped and named) and
   on the data (a set that cannot identify what was asked is refused, naming
   the parameters);
6. standard deviations from the covariance ``sigma^2 (J^T J)^-1``;
7. the calibrated robot, with link frames kept where the nominal robot's are
   (:func:`~robokin.calibration._frames.reframe`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
import numpy.typing as npt

from robokin._validation import _real_array, check_finite, check_joints
from robokin.calibration._fit import Problem
from robokin.calibration._frames import reframe
from robokin.calibration._identify import (
    RANK_TOL,
    dependent_parameters,
    observability,
    scaled_svd,
    structural_rules,
)
from robokin.calibration._model import Model, pose_values
from robokin.calibration._register import register_points, register_poses
from robokin.exceptions import InputError

if TYPE_CHECKING:
    from robokin.robot import Robot

__all__ = ["CalibrationResult", "Parameter", "calibrate", "check_measurements"]

Kind = Literal["position", "pose"]
#: Extras that may be declared with ``extras=``.
EXTRAS = ("scale", "compliance")
#: Default angle below which consecutive axes count as parallel [rad] (10 deg).
PARALLEL_TOL = math.radians(10.0)
#: A pose is an outlier when its squared residual exceeds sigma^2 times the
#: chi-square quantile at 1 - 1e-4 (scipy.stats.chi2.ppf(1 - 1e-4, dof)), for 3
#: (points) or 6 (poses) components: 2 in 10,000 inliers are set aside.
_CHI2_LIMIT = {3: 21.107513466160444, 6: 27.85634123601417}
#: A parameter redundant at the nominal geometry comes back at the estimate only
#: when its scaled singular value exceeds this share of the largest.
PRACTICAL_TOL = 1e-3


@dataclass(frozen=True)
class Parameter:
    """One identified parameter.

    Attributes:
        name: ``"j2.beta"``, ``"j4.d"``, ``"base.x"``, ``"tool.roll"``, ...
        nominal: The nominal value (SI: m, rad; base and tool: the given
            robot's).
        identified: The identified value.
        std: Its standard deviation (from the covariance of the fit).
        unit: ``"m"``, ``"rad"``, ``"1"`` (gear-ratio error) or ``"rad/(N m)"``.
    """

    name: str
    nominal: float
    identified: float
    std: float
    unit: str

    @property
    def error(self) -> float:
        """``identified - nominal`` (angles wrapped into [-pi, pi))."""
        d = self.identified - self.nominal
        if self.unit == "rad":
            d = (d + math.pi) % (2 * math.pi) - math.pi
        return d


@dataclass(frozen=True)
class CalibrationResult:
    """What :func:`calibrate` found.

    Attributes:
        robot: The calibrated robot (base = measuring frame -> robot base, tool =
            flange -> TCP), same joint names.
        parameters: The identified parameters (nominal, identified, std).
        unidentifiable: ``(name, reason)`` of every parameter left at nominal.
        residual_rms: RMS of the inliers' position residuals [m].
        rotation_rms: RMS of the inliers' rotation residuals [rad] (poses), or NaN.
        kind: ``"position"`` or ``"pose"``.
        outliers: Indices of the poses the robust fit set aside.
        registered: The nominal robot with only base and tool fitted (the
            "before" of a hold-out report).
        covariance: Covariance of the identified parameters, in the order of
            ``parameters`` (base and tool in x, y, z, roll, pitch, yaw).
        observability: ``{"O1", "condition", "min_singular"}`` of the scaled
            identification Jacobian at the estimate.
        rotation_weight: The weight of rotation residuals [m/rad] (poses).
        sigma: The estimated measurement noise (RMS per component) [m].
    """

    robot: Robot
    parameters: tuple[Parameter, ...]
    unidentifiable: tuple[tuple[str, str], ...]
    residual_rms: float
    rotation_rms: float
    kind: str
    outliers: tuple[int, ...]
    registered: Robot
    covariance: np.ndarray = field(repr=False)
    observability: dict[str, float] = field(default_factory=dict)
    rotation_weight: float = math.nan
    sigma: float = math.nan

    def parameter(self, name: str) -> Parameter:
        """The parameter called ``name`` (KeyError listing the names if unknown)."""
        for p in self.parameters:
            if p.name == name:
                return p
        raise KeyError(f"no identified parameter {name!r}; identified: "
                       f"{[p.name for p in self.parameters]}")

    def to_dict(self) -> dict[str, Any]:
        """A JSON-ready summary (SI units)."""
        return {
            "kind": self.kind,
            "residual_rms_m": self.residual_rms,
            "rotation_rms_rad": None if math.isnan(self.rotation_rms) else self.rotation_rms,
            "sigma_m": self.sigma,
            "outliers": list(self.outliers),
            "observability": dict(self.observability),
            "parameters": [{"name": p.name, "unit": p.unit, "nominal": p.nominal,
                            "identified": p.identified, "std": p.std}
                           for p in self.parameters],
            "unidentifiable": [{"name": n, "reason": r} for n, r in self.unidentifiable],
        }


# ---------------------------------------------------------------------- inputs
def check_measurements(measured: npt.ArrayLike, n_poses: int, kind: str,
                       name: str = "measured") -> np.ndarray:
    """Measured points (N, 3) or poses (N, 4, 4) for ``kind``; InputError if not."""
    from robokin._validation import check_transform

    if kind not in ("position", "pose"):
        raise InputError("kind", f"expected 'position' or 'pose', got {kind!r}")
    m = _real_array(measured, name, "points (N, 3) or poses (N, 4, 4)")
    if m.ndim == 3 and m.shape[1:] == (4, 4):
        m = check_transform(m, name)
        if kind == "position":
            m = m[:, :3, 3].copy()
    elif m.ndim == 2 and m.shape[1] == 3:
        if kind == "pose":
            raise InputError(name, "kind='pose' needs poses (N, 4, 4), got points (N, 3)")
        check_finite(m, name)
    else:
        raise InputError(name, f"expected points (N, 3) or poses (N, 4, 4), got "
                         f"shape {m.shape}")
    if len(m) != n_poses:
        raise InputError(name, f"{len(m)} measurements for {n_poses} joint "
                         "configurations")
    return m


def _check_q(robot: Robot, q: npt.ArrayLike) -> np.ndarray:
    qa = check_finite(check_joints(q, robot.n, "q"), "q")
    if qa.ndim != 2:
        raise InputError("q", f"expected joint coordinates (N, {robot.n}), got shape "
                         f"{qa.shape}")
    return qa


def _check_torque(robot: Robot, torque: npt.ArrayLike | None, N: int,
                  extras: tuple[str, ...]) -> np.ndarray | None:
    if "compliance" not in extras:
        if torque is not None:
            raise InputError("torque", "given without extras=('compliance',)")
        return None
    if torque is None:
        raise InputError("torque", "extras 'compliance' needs the joint torques "
                         f"(N, {robot.n}) [N m] of every pose")
    if not robot.chain.coupling.is_identity:
        raise InputError("extras", "'compliance' needs a robot whose joints are its "
                         "coordinates (no coupling)")
    t = check_finite(check_joints(torque, robot.n, "torque"), "torque")
    if t.shape != (N, robot.n):
        raise InputError("torque", f"expected shape ({N}, {robot.n}), got {t.shape}")
    return t


def _check_extras(extras: Sequence[str]) -> tuple[str, ...]:
    if isinstance(extras, str):
        extras = (extras,)
    out = tuple(extras)
    for e in out:
        if e not in EXTRAS:
            raise InputError("extras", f"unknown extra {e!r}; choose from {list(EXTRAS)}")
    return out


# ------------------------------------------------------------------ the steps
def _register(model: Model, q: np.ndarray, measured: np.ndarray, pose: bool,
              tool: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Registered base ``B_0`` and tool ``T_0`` (nominal tool rotation for points)."""
    x0 = np.zeros(model.size)
    flange = model.evaluate(q, x0, np.eye(4), np.eye(4)).T
    if pose:
        return register_poses(flange, measured, tool)
    B, t = register_points(flange, measured, tool[:3, 3])
    T0 = np.array(tool, dtype=float)
    T0[:3, 3] = t
    return B, T0


def _active_set(model: Model, absorbed: dict[str, str], what: Any,
                fixed: Sequence[str]) -> list[int]:
    """Indices asked for: ``model`` ('auto', 'base_tool' or names) minus ``fixed``."""
    names = model.names
    for f in fixed:
        if f not in names:
            raise InputError("fixed", f"unknown parameter {f!r}; parameters: {list(names)}")
    if isinstance(what, str):
        if what == "auto":
            wanted = [n for n in names if n not in absorbed]
        elif what == "base_tool":
            wanted = [n for n in names if n.startswith(("base.", "tool."))
                      and n not in absorbed]
        else:
            raise InputError("model", f"expected 'auto', 'base_tool' or a list of "
                             f"parameter names, got {what!r}")
    else:
        wanted = list(what)
        for w in wanted:
            if w in absorbed:
                raise InputError("model", f"{w!r} cannot be identified: {absorbed[w]}")
            if w not in names:
                raise InputError("model", f"unknown parameter {w!r}; parameters: "
                                 f"{list(names)}")
    return [names.index(n) for n in wanted if n not in fixed]


def _rich_q(robot: Robot, count: int) -> np.ndarray:
    """A spread of configurations inside the limits (seeded: same every call)."""
    rng = np.random.default_rng(20260428)
    lim = np.clip(robot.limits, -math.pi, math.pi)
    return rng.uniform(lim[:, 0], lim[:, 1], (count, robot.n))


def _rich_jacobian(problem: Problem, robot: Robot, x: np.ndarray,
                   active: list[int]) -> np.ndarray:
    """The identification Jacobian of a rich synthetic pose set (no compliance)."""
    rich = Problem(problem.model, _rich_q(robot, max(60, 2 * len(active))),
                   np.zeros((0, 3)), problem.pose, problem.base, problem.tool, None,
                   problem.rotation_weight)
    ev = rich.evaluate(x, np.array(active))
    assert ev.Jp is not None and ev.Jr is not None
    J = np.concatenate([ev.Jp, ev.Jr], axis=1) if problem.pose else ev.Jp
    return J.reshape(-1, len(active))


def _structural_drops(problem: Problem, robot: Robot, x: np.ndarray,
                      active: list[int], tol: float = RANK_TOL
                      ) -> list[tuple[str, list[str]]]:
    """Parameters that trade with others for every pose, at parameters ``x``.

    Compliance columns need torques: they are judged on the data alone.
    """
    cols = [i for i in active if i not in problem.model.compliance]
    J = _rich_jacobian(problem, robot, x, cols)
    return dependent_parameters(J, [problem.model.names[i] for i in cols], tol)


def _restored(problem: Problem, robot: Robot, x: np.ndarray, active: list[int],
              dropped: list[int]) -> list[int]:
    """Parameters dropped at nominal that the estimate identifies after all.

    One is restored when, with it, the smallest scaled singular value of the
    rich Jacobian stays above :data:`PRACTICAL_TOL` of the largest: an exact
    redundancy at the nominal geometry (parallel axes) that the estimate breaks
    only by its 0.05 deg tilts stays dropped (it would amplify noise ~1000x).
    """
    back: list[int] = []
    for i in dropped:
        cols = [c for c in active + back + [i] if c not in problem.model.compliance]
        s, _, _ = scaled_svd(_rich_jacobian(problem, robot, x, cols))
        if s[-1] > PRACTICAL_TOL * s[0]:
            back.append(i)
    return back


def _inliers(problem: Problem, x: np.ndarray) -> tuple[np.ndarray, float]:
    """Poses within the chi-square limit of a robust noise estimate (MAD), and it."""
    rp, rr = problem.split_residual(problem.evaluate(x, None))
    comp = rp if rr is None else np.concatenate([rp, problem.rotation_weight * rr], 1)
    sigma = 1.4826 * float(np.median(np.abs(comp)))
    limit = _CHI2_LIMIT[comp.shape[1]] * max(sigma, 1e-12) ** 2
    return np.flatnonzero((comp**2).sum(1) <= limit), sigma


def _robust_stages(problem: Problem, x: np.ndarray, active: list[int],
                   weight_given: bool) -> tuple[np.ndarray, np.ndarray, float]:
    """Fit, noise and rotation weight, outliers; returns (x, inlier rows, sigma).

    A least-squares fit of every pose first; for poses the rotation weight is
    then the ratio of the robust position and rotation noise (MAD). Only when
    some pose lies beyond the chi-square limit is the fit redone: without the
    suspects, then with a robust loss (``soft_l1`` of each pose's residual,
    scale 3 sigma, :meth:`~robokin.calibration._fit.Problem.solve_robust`) over
    every pose, and the outliers found again.
    """
    act = np.array(active)
    x = problem.solve(x, act)
    if problem.pose and not weight_given:
        rp, rr = problem.split_residual(problem.evaluate(x, None))
        assert rr is not None
        sp = 1.4826 * np.median(np.abs(rp))
        sr = 1.4826 * np.median(np.abs(rr))
        if sp > 0 and sr > 0:
            problem.rotation_weight = float(sp / sr)
            x = problem.solve(x, act)
    inliers, sigma = _inliers(problem, x)
    if len(inliers) < len(problem.q):
        # the suspects left out first (a least-squares fit of the rest), then a
        # robust fit of every pose from there, then the outliers found again
        x = problem.solve(x, act, rows=inliers)
        x = problem.solve_robust(x, act, 3 * max(sigma, 1e-12))
        inliers, sigma = _inliers(problem, x)
    return x, inliers, sigma


def _covariance(problem: Problem, x: np.ndarray, active: list[int],
                rows: np.ndarray) -> tuple[np.ndarray, float, np.ndarray]:
    """Covariance of the active parameters, noise RMS per component, Jacobian."""
    r, J = problem.residual_and_jacobian(x, np.array(active), rows)
    dof = max(len(r) - len(active), 1)
    s2 = float(r @ r) / dof
    s, Vt, norms = scaled_svd(J)
    inv = (Vt.T / s**2) @ Vt
    cov = s2 * inv / np.outer(norms, norms)
    return cov, math.sqrt(s2), J


def _refuse_unidentified(J: np.ndarray, names: list[str], n_poses: int,
                         per_pose: int) -> None:
    """InputError naming the parameters these poses cannot identify."""
    if n_poses * per_pose < len(names):
        raise InputError("q", f"too few poses: {n_poses} give {n_poses * per_pose} "
                         f"equations for {len(names)} parameters; measure at least "
                         f"{-(-len(names) // per_pose)} well-spread poses (3x that "
                         "is better)")
    bad = dependent_parameters(J, names, RANK_TOL)
    if bad:
        what = "; ".join(f"{n}" + (f" (trades with {', '.join(p)})" if p else "")
                         for n, p in bad)
        raise InputError("q", f"these poses cannot identify {what}: the data are "
                         "degenerate for them (a joint that hardly moves, too few "
                         "distinct poses); add poses that move those joints, or "
                         "hold them with fixed=[...]")


# --------------------------------------------------------------------- public
def calibrate(
    robot: Robot,
    q: npt.ArrayLike,
    measured: npt.ArrayLike,
    kind: Kind = "position",
    model: str | Sequence[str] = "auto",
    *,
    fixed: Sequence[str] = (),
    extras: Sequence[str] = (),
    torque: npt.ArrayLike | None = None,
    rotation_weight: float | None = None,
    parallel_tol: float = PARALLEL_TOL,
) -> CalibrationResult:
    """Identify the kinematic errors of ``robot`` from measurements.

    Args:
        robot: The nominal robot (any chain: DH, URDF, elementary).
        q: Joint coordinates at the measurements [rad, m], shape (N, n).
        measured: Tool positions (N, 3) [m] or poses (N, 4, 4) in the measuring
            (tracker) frame, anywhere relative to the robot.
        kind: ``"position"`` or ``"pose"`` (poses also fit rotations and can
            identify the tool's orientation).
        model: ``"auto"`` (every identifiable parameter: joint offsets, lengths,
            twist angles, Hayati ``beta`` on near-parallel axes, base and tool),
            ``"base_tool"`` (only the measuring frame and the tool), or a list of
            parameter names.
        fixed: Parameter names held at nominal.
        extras: Declared extras: ``"scale"`` (a gear-ratio error per joint) and
            ``"compliance"`` (a joint stiffness term ``c_k tau_k`` per joint,
            needs ``torque``).
        torque: Joint torques (N, n) [N m] for ``"compliance"`` (e.g. gravity
            torques from a dynamics model).
        rotation_weight: Weight of rotation residuals [m/rad] for poses (default:
            estimated from the residuals, the ratio of the position and rotation
            noise).
        parallel_tol: Consecutive axes closer than this angle [rad] get Hayati's
            ``beta`` instead of ``d``.

    Returns:
        A :class:`CalibrationResult`.

    Raises:
        InputError: bad shapes or values (named), too few poses, or poses that
            cannot identify the parameters asked for (named).
    """
    qa = _check_q(robot, q)
    N = len(qa)
    meas = check_measurements(measured, N, kind)
    ext = _check_extras(extras)
    tq = _check_torque(robot, torque, N, ext)
    if rotation_weight is not None and not (rotation_weight > 0 and
                                            math.isfinite(rotation_weight)):
        raise InputError("rotation_weight", f"expected a positive number [m/rad], "
                         f"got {rotation_weight!r}")
    if not 0.0 <= parallel_tol < math.pi / 2:
        raise InputError("parallel_tol", f"expected an angle in [0, pi/2) [rad], got "
                         f"{parallel_tol!r}")
    pose = kind == "pose"
    mdl = Model.from_chain(robot.chain, parallel_tol=parallel_tol, extras=ext)
    absorbed = structural_rules(mdl, kind)
    active = _active_set(mdl, absorbed, model, fixed)
    per_pose = 6 if pose else 3
    if N * per_pose < len(active):
        _refuse_unidentified(np.zeros((N * per_pose, len(active))),
                             [mdl.names[i] for i in active], N, per_pose)
    B0, T0 = _register(mdl, qa, meas, pose, robot.tool)
    prob = Problem(mdl, qa, meas, pose, B0, T0, tq, rotation_weight or 0.1)
    unident = dict(absorbed)
    x, inliers = _fit_identifiable(prob, robot, active, unident,
                                   rotation_weight is not None)
    if not isinstance(model, str):
        lost = [n for n in model if n not in fixed and mdl.index(n) not in active]
        if lost:
            raise InputError("model", "cannot identify " + "; ".join(
                f"{n!r}: {unident[n]}" for n in lost) + " (leave it out)")
    x = prob.solve(x, np.array(active), rows=inliers)
    cov, sigma, J = _covariance(prob, x, active, inliers)
    _refuse_unidentified(J, [mdl.names[i] for i in active], len(inliers), per_pose)
    return _result(robot, prob, x, active, cov, sigma, J, inliers, unident, kind)


def _fit_identifiable(prob: Problem, robot: Robot, active: list[int],
                      unident: dict[str, str], weight_given: bool
                      ) -> tuple[np.ndarray, np.ndarray]:
    """The fit with identifiability judged at nominal and again at the estimate.

    Updates ``active`` (sorted) and ``unident`` (name -> reason) in place;
    returns the parameters and the inlier rows.
    """
    mdl = prob.model
    x = np.zeros(mdl.size)
    at_nominal = []
    for name, partners in _structural_drops(prob, robot, x, active):
        unident[name] = "redundant with " + ", ".join(partners)
        active.remove(mdl.index(name))
        at_nominal.append(mdl.index(name))
    x, inliers, _ = _robust_stages(prob, x, active, weight_given)
    # judged again at the estimate: the set may change away from nominal
    for name, partners in _structural_drops(prob, robot, x, active, PRACTICAL_TOL):
        unident[name] = ("redundant with " + ", ".join(partners) + " (nearly: any "
                         "pose set amplifies noise > 1000x for it)")
        active.remove(mdl.index(name))
        x[mdl.index(name)] = 0.0
    for i in _restored(prob, robot, x, active, at_nominal):
        active.append(i)
        del unident[mdl.names[i]]
    active.sort()
    return x, inliers


def _result(robot: Robot, prob: Problem, x: np.ndarray, active: list[int],
            cov: np.ndarray, sigma: float, J: np.ndarray, inliers: np.ndarray,
            unident: dict[str, str], kind: str) -> CalibrationResult:
    mdl = prob.model
    chain = reframe(mdl.chain_at(x, prob.base, prob.tool), robot.chain)
    calibrated = robot.replace(chain=chain, name=f"{robot.name}_calibrated",
                               meta={})
    params, pcov = _parameters(robot, prob, x, active, cov)
    ev = prob.evaluate(x, None, inliers)
    rp, rr = prob.split_residual(ev, inliers)
    registered = _registered(robot, prob, inliers)
    unidentifiable = tuple((n, r) for n, r in unident.items()
                           if n not in {p.name for p in params})
    return CalibrationResult(
        robot=calibrated, parameters=params, unidentifiable=unidentifiable,
        residual_rms=float(np.sqrt((rp**2).sum(1).mean())),
        rotation_rms=math.nan if rr is None else float(np.sqrt((rr**2).sum(1).mean())),
        kind=kind, outliers=tuple(int(i) for i in np.setdiff1d(np.arange(len(prob.q)),
                                                              inliers)),
        registered=registered, covariance=pcov,
        observability=observability(J, len(inliers)),
        rotation_weight=prob.rotation_weight if prob.pose else math.nan, sigma=sigma)


def _registered(robot: Robot, prob: Problem, inliers: np.ndarray) -> Robot:
    """The nominal robot with only the measuring frame and the tool fitted.

    A least-squares fit of the inliers, as ``model="base_tool"`` makes.
    """
    mdl = prob.model
    x = np.zeros(mdl.size)
    act = [i for i, n in enumerate(mdl.names) if n.startswith(("base.", "tool."))]
    if not prob.pose:
        act = [i for i in act if mdl.names[i] not in ("tool.roll", "tool.pitch",
                                                      "tool.yaw")]
    x = prob.solve(x, np.array(act), rows=inliers)
    chain = robot.chain.replace(base=prob.base @ mdl.pose_correction(x, "base"),
                                tool=prob.tool @ mdl.pose_correction(x, "tool"))
    return robot.replace(chain=chain, name=f"{robot.name}_registered", meta={})


def _parameters(robot: Robot, prob: Problem, x: np.ndarray, active: list[int],
                cov: np.ndarray) -> tuple[tuple[Parameter, ...], np.ndarray]:
    """The report rows, base and tool as x y z roll pitch yaw (delta method)."""
    mdl = prob.model
    pos = {i: c for c, i in enumerate(active)}
    # reported quantities g(x): joint parameters themselves, base/tool pose values
    rows: list[tuple[str, float, float, str, np.ndarray]] = []
    for i in active:
        n = mdl.names[i]
        if n.startswith(("base.", "tool.")):
            continue
        g = np.zeros(len(active))
        g[pos[i]] = 1.0
        unit = {"length": "m", "angle": "rad", "scale": "1",
                "compliance": "rad/(N m)"}[mdl.kinds[i]]
        rows.append((n, float(mdl.nominal[i]) + 0.0, float(mdl.nominal[i] + x[i]), unit, g))
    for side, T_nom, T_fit in (("base", robot.base, prob.base),
                               ("tool", robot.tool, prob.tool)):
        idx = [mdl.index(f"{side}.{c}") for c in ("x", "y", "z", "yaw", "pitch", "roll")]
        if not any(i in pos for i in idx):
            continue

        def values(xx: np.ndarray, side: str = side, T_fit: np.ndarray = T_fit
                   ) -> np.ndarray:
            return pose_values(T_fit @ mdl.pose_correction(xx, side))

        v0 = values(x)
        G = np.zeros((6, len(active)))
        for i in idx:
            if i in pos:
                h = 1e-7
                xp, xm = x.copy(), x.copy()
                xp[i] += h
                xm[i] -= h
                dv = values(xp) - values(xm)
                dv[3:] = (dv[3:] + math.pi) % (2 * math.pi) - math.pi
                G[:, pos[i]] = dv / (2 * h)
        nom = pose_values(np.asarray(T_nom))
        for k, c in enumerate(("x", "y", "z", "roll", "pitch", "yaw")):
            if side == "tool" and k >= 3 and not prob.pose:
                continue
            rows.append((f"{side}.{c}", float(nom[k]), float(v0[k]),
                         "m" if k < 3 else "rad", G[k]))
    Gm = np.array([r[4] for r in rows]).reshape(len(rows), len(active))
    pcov = Gm @ cov @ Gm.T
    std = np.sqrt(np.maximum(np.diag(pcov), 0.0))
    params = tuple(Parameter(n, nom, ident, float(s), unit)
                   for (n, nom, ident, unit, _), s in zip(rows, std))
    return params, pcov
