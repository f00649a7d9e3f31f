"""Synthetic calibration data: a "true" robot near a nominal one, and its measurements.

For planning a calibration (how many poses, which noise), for tests and for the
benchmark. Every random draw comes from the ``rng`` given.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt

from robokin.calibration._frames import reframe
from robokin.calibration._identify import structural_rules
from robokin.calibration._model import Model
from robokin.exceptions import InputError

if TYPE_CHECKING:
    from robokin.robot import Robot

__all__ = ["SyntheticRobot", "measure", "perturb", "random_configurations"]


@dataclass(frozen=True)
class SyntheticRobot:
    """A perturbed robot and the truth to compare an identification with.

    Attributes:
        robot: The "true" robot (its base is the measuring frame -> robot base).
        truth: True values of the joint parameters, by name (``"j2.beta"``...),
            in the naming of :func:`~robokin.calibration.calibrate`.
        base: The true base (4, 4).
        tool: The true tool (4, 4).
    """

    robot: Robot
    truth: dict[str, float]
    base: np.ndarray
    tool: np.ndarray


def perturb(
    robot: Robot,
    rng: np.random.Generator,
    *,
    length_sigma: float = 0.5e-3,
    angle_sigma: float = math.radians(0.05),
    base: npt.ArrayLike | None = None,
    tool: npt.ArrayLike | None = None,
    parallel_tol: float = math.radians(10.0),
) -> SyntheticRobot:
    """A robot whose identifiable joint parameters are off nominal by random errors.

    Lengths (``d``, ``a``) get normal errors of ``length_sigma`` [m], angles
    (joint offsets ``theta``, twists ``alpha``, Hayati tilts ``beta`` of parallel
    axes) of ``angle_sigma`` [rad].

    Args:
        robot: The nominal robot.
        rng: The random generator (every draw comes from it).
        length_sigma: Standard deviation of length errors [m].
        angle_sigma: Standard deviation of angle errors [rad].
        base: The true base (measuring frame -> robot base) (4, 4); default the
            robot's.
        tool: The true tool (flange -> TCP) (4, 4); default the robot's.
        parallel_tol: As :func:`~robokin.calibration.calibrate`.
    """
    model = Model.from_chain(robot.chain, parallel_tol=parallel_tol)
    absorbed = structural_rules(model, "pose")
    x = np.zeros(model.size)
    truth: dict[str, float] = {}
    for i, (name, kind) in enumerate(zip(model.names, model.kinds)):
        if name.startswith(("base.", "tool.")) or name in absorbed:
            continue
        x[i] = rng.normal(0.0, length_sigma if kind == "length" else angle_sigma)
        truth[name] = float(model.nominal[i] + x[i])
    B = np.array(robot.base if base is None else base, dtype=float)
    T = np.array(robot.tool if tool is None else tool, dtype=float)
    chain = reframe(model.chain_at(x, B, T), robot.chain)
    true = robot.replace(chain=chain, name=f"{robot.name}_true", meta={})
    return SyntheticRobot(true, truth, B, T)


def random_configurations(robot: Robot, rng: np.random.Generator, count: int,
                          ) -> np.ndarray:
    """``count`` configurations uniform inside the limits (clipped to +-pi) (count, n)."""
    lim = robot.limits.copy()
    rev = robot.is_revolute
    lim[rev] = np.clip(lim[rev], -math.pi, math.pi)
    lim[~rev] = np.clip(lim[~rev], -1.0, 1.0)
    return rng.uniform(lim[:, 0], lim[:, 1], (int(count), robot.n))


def measure(
    robot: Robot,
    q: npt.ArrayLike,
    rng: np.random.Generator,
    *,
    kind: str = "position",
    noise: float = 2e-5,
    rotation_noise: float = math.radians(0.005),
    outliers: float = 0.0,
    outlier_size: float = 2e-3,
) -> tuple[np.ndarray, np.ndarray]:
    """Simulated tracker measurements of ``robot`` at ``q``.

    Args:
        robot: The true robot (base = measuring frame -> robot base).
        q: Joint coordinates (N, n).
        rng: The random generator.
        kind: ``"position"`` (points) or ``"pose"``.
        noise: Standard deviation per coordinate [m] (isotropic).
        rotation_noise: Standard deviation per rotation-vector component [rad].
        outliers: Fraction of poses given a gross error.
        outlier_size: Size of a gross error [m] (a random direction).

    Returns:
        ``(measured, noise-free)``: points (N, 3) or poses (N, 4, 4), each.
    """
    from robokin.spatial import matrix_from_axis_angle

    if kind not in ("position", "pose"):
        raise InputError("kind", f"expected 'position' or 'pose', got {kind!r}")
    T = robot.fk(np.asarray(q, dtype=float))
    N = len(T)
    dp = rng.normal(0.0, noise, (N, 3))
    bad = rng.random(N) < outliers
    if bad.any():
        d = rng.normal(size=(int(bad.sum()), 3))
        dp[bad] += outlier_size * d / np.linalg.norm(d, axis=1, keepdims=True)
    if kind == "position":
        return T[:, :3, 3] + dp, T[:, :3, 3].copy()
    M = T.copy()
    M[:, :3, 3] += dp
    R = matrix_from_axis_angle(rng.normal(0.0, rotation_noise, (N, 3)))
    M[:, :3, :3] = R[:, :3, :3] @ T[:, :3, :3]
    return M, T
