"""Checked inputs of the process functions: robot and scene, poses, tool samples."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, TypedDict

import numpy as np
import numpy.typing as npt

from robokin._text import short_repr
from robokin._validation import (
    check_finite,
    check_finite_number,
    check_joints,
    check_transform,
)
from robokin.exceptions import InputError
from robokin.process.costs import Costs
from robokin.spatial import rotz

if TYPE_CHECKING:
    from robokin.collision.scene import Scene
    from robokin.robot import Robot

__all__ = ["MAX_ANGLES", "MAX_SAMPLES", "Placed", "ToolSamples", "check_max_step",
           "SearchInputs", "SearchKeywords", "check_poses", "check_q_start", "place",
           "search_inputs", "tool_samples"]

#: Most tool rotations sampled per waypoint (a tenth of a degree over a full turn).
MAX_ANGLES = 3600
#: Most sampled tool poses (waypoints x rotations) one call solves: each holds every
#: IK solution (about 0.5 kB on a 6R arm), so this bounds the memory near 0.5 GB.
MAX_SAMPLES = 1_000_000
FREE_AXES = (None, "z")
_FREE_STEP = math.radians(5.0)  # default tool-rotation sampling [rad]


@dataclass(frozen=True, eq=False)
class Placed:
    """The robot as it stands in the world, and what the collision check needs.

    Attributes:
        robot: The robot in the world frame of the poses (with a scene: its base
            placement and tool).
        bare: The robot before the scene placed it (``collision.check`` takes it),
            or None without a scene.
        scene: The scene, or None.
        clearance: Required clearance [m].
    """

    robot: Robot
    bare: Robot | None
    scene: Scene | None
    clearance: float


def place(robot: Robot, scene: Any, clearance: Any) -> Placed:
    """Check ``robot``, ``scene`` and ``clearance``; place the robot in the scene."""
    from robokin.robot import Robot as _Robot

    if not isinstance(robot, _Robot):
        raise InputError("robot", f"expected a robokin.Robot, got {short_repr(robot)}")
    c = check_finite_number(clearance, "clearance")
    if c < 0.0:
        raise InputError("clearance", f"expected a distance >= 0 [m], got {c}")
    if scene is None:
        if c > 0.0:
            raise InputError("clearance", "a clearance needs a scene (scene=None)")
        return Placed(robot, None, None, 0.0)
    from robokin.collision.scene import Scene as _Scene

    if not isinstance(scene, _Scene):
        raise InputError("scene", f"expected a collision.Scene, got {short_repr(scene)}")
    bare = scene.unplaced(robot)
    return Placed(scene.attach(bare), bare, scene, c)


def check_poses(poses: Any, name: str = "poses") -> np.ndarray:
    """Tool poses as a C-contiguous float64 (N, 4, 4) array, N >= 1."""
    if isinstance(poses, (list, tuple)) and len(poses) == 0:
        raise InputError(name, "expected at least one pose, got none")
    T = check_transform(poses, name)
    if T.ndim == 2:
        T = T[None]
    if T.ndim != 3 or T.shape[0] == 0:
        raise InputError(name, f"expected shape (N, 4, 4) with N >= 1, got {T.shape}")
    return np.ascontiguousarray(T, dtype=np.float64)


@dataclass(frozen=True, eq=False)
class ToolSamples:
    """The rotations about the tool's free axis tried at every waypoint.

    Attributes:
        axis: ``"z"`` or None (the tool orientation is fixed).
        angles: Rotation angles (K,) [rad] about the tool z axis (``[0.0]`` for a
            fixed orientation).
        rotations: The rotations as (K, 4, 4) poses (applied on the right).
    """

    axis: str | None
    angles: np.ndarray
    rotations: np.ndarray

    @property
    def count(self) -> int:
        """K, the rotations per waypoint."""
        return int(self.angles.shape[0])


def tool_samples(free_axis: Any, free_range: Any, free_step: Any) -> ToolSamples:
    """The sampled rotations of a free tool axis (checked arguments).

    ``free_range`` (lo, hi) [rad] defaults to a full turn [-pi, pi); samples are
    ``lo, lo + free_step, ...`` up to ``hi`` inclusive (a full turn stops one step
    short of repeating ``lo``).
    """
    if free_axis not in FREE_AXES:
        raise InputError("free_axis", f"expected one of {list(FREE_AXES)}, got "
                         f"{short_repr(free_axis)}")
    if free_axis is None:
        if free_range is not None:
            raise InputError("free_range", "given without free_axis (pass free_axis='z' "
                             "to let the tool turn about its z axis)")
        zero = np.zeros(1)
        return ToolSamples(None, zero, rotz(zero))
    lo, hi = _free_range(free_range)
    step = check_finite_number(free_step, "free_step")
    if step <= 0.0:
        raise InputError("free_step", f"expected an angle > 0 [rad], got {step}")
    full = hi - lo >= 2.0 * math.pi - 1e-9
    count = math.floor((hi - lo) / step + 1e-9) + 1
    if full and lo + (count - 1) * step >= lo + 2.0 * math.pi - 1e-9:
        count -= 1
    if count > MAX_ANGLES:
        raise InputError("free_step", f"{step:.6g} rad over free_range ({lo:.6g}, "
                         f"{hi:.6g}) is {count} rotations per waypoint; at most "
                         f"{MAX_ANGLES} (a larger free_step)")
    angles = np.asarray(lo + step * np.arange(count), dtype=np.float64)
    return ToolSamples(free_axis, angles, rotz(angles))


def _free_range(free_range: Any) -> tuple[float, float]:
    if free_range is None:
        return -math.pi, math.pi
    try:
        lo, hi = free_range
    except (TypeError, ValueError):
        raise InputError("free_range", f"expected (lo, hi) [rad], got "
                         f"{short_repr(free_range)}") from None
    lo = check_finite_number(lo, "free_range")
    hi = check_finite_number(hi, "free_range")
    if not lo <= hi or hi - lo > 2.0 * math.pi + 1e-9:
        raise InputError("free_range", f"expected lo <= hi spanning at most a turn, got "
                         f"({lo:.6g}, {hi:.6g}) [rad]")
    return lo, hi


def check_max_step(max_step: Any) -> float:
    """``max_step`` as a float > 0 [rad, m] (``math.inf``: no step limit)."""
    if isinstance(max_step, (int, float)) and max_step == math.inf:
        return math.inf
    v = check_finite_number(max_step, "max_step")
    if v <= 0.0:
        raise InputError("max_step", f"expected a joint step > 0 [rad, m], got {v}")
    return v


def check_q_start(q_start: npt.ArrayLike | None, robot: Robot) -> np.ndarray | None:
    """``q_start`` as a finite (n,) array inside the limits, or None."""
    if q_start is None:
        return None
    q = check_finite(check_joints(q_start, robot.n, "q_start"), "q_start")
    if q.ndim != 1:
        raise InputError("q_start", f"expected one configuration ({robot.n},), got "
                         f"{q.shape}")
    if not bool(robot.within_limits(q)):
        lim = robot.limits
        j = int(np.argmax((q < lim[:, 0] - 1e-9) | (q > lim[:, 1] + 1e-9)))
        raise InputError("q_start", f"joint {j + 1} at {q[j]:.6g} is outside its limits "
                         f"[{lim[j, 0]:.6g}, {lim[j, 1]:.6g}]")
    return q.astype(np.float64, copy=True)


class SearchKeywords(TypedDict, total=False):
    """The keywords :func:`~robokin.process.follow` and :func:`~robokin.process.order` share."""

    free_axis: str | None
    free_range: tuple[float, float] | None
    free_step: float
    q_start: npt.ArrayLike | None
    scene: Any
    clearance: float
    travel_weight: float
    singularity_weight: float
    singularity_margin: float
    singular_tol: float
    limit_weight: float
    limit_margin: float


@dataclass(frozen=True, eq=False)
class SearchInputs:
    """The checked inputs of a tool-path search.

    Attributes:
        placed: The robot and scene as placed (:func:`place`).
        T: The tool poses (N, 4, 4) [m].
        samples: The tool rotations tried per pose.
        q_start: The start configuration (n,), or None.
        costs: The objective's weights and margins.
    """

    placed: Placed
    T: np.ndarray
    samples: ToolSamples
    q_start: np.ndarray | None
    costs: Costs


def search_inputs(robot: Robot, poses: Any, *, free_axis: Any = None,
                  free_range: Any = None, free_step: Any = _FREE_STEP,
                  q_start: npt.ArrayLike | None = None, scene: Any = None,
                  clearance: Any = 0.0, **weights: float) -> SearchInputs:
    """The :class:`SearchInputs` of ``poses`` and the keywords (``SearchKeywords``).

    Raises:
        InputError: a bad argument (named).
    """
    placed = place(robot, scene, clearance)
    T = check_poses(poses)
    samples = tool_samples(free_axis, free_range, free_step)
    qs = check_q_start(q_start, placed.robot)
    return SearchInputs(placed, T, samples, qs, Costs(**weights))
