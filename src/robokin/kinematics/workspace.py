r"""Workspace analysis: where the tool point can go.

Monte-Carlo sampling of the joint space inside the joint limits, pushed through the
compiled batch FK: the reachable point cloud, its bounding box, a volume estimate
by voxel counting, cross-section plots in the XY / XZ planes and a manipulability
colouring.

.. math::

    V \approx N_{occupied} \cdot h^3

where ``h`` is the voxel edge length. The estimate converges from below as the
sample count grows (unvisited voxels) and from above as ``h`` shrinks (voxels cut
by the boundary), so quote it with its voxel size.
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
from robokin.kinematics.jacobian import manipulability as _manipulability

if TYPE_CHECKING:
    from robokin.kinematics.robot_like import RobotLike

__all__ = [
    "Workspace",
    "random_joints",
    "sample_workspace",
    "voxel_volume",
]



@dataclass(frozen=True, eq=False)
class Workspace:
    """A Monte-Carlo sample of a robot's reachable tool positions.

    Attributes:
        robot_name: The robot's name.
        points: Tool positions in the world frame [m], shape (N, 3).
        q: The joint samples behind ``points`` [rad, m], shape (N, n), or None
            when not kept.
        bounds: ``[[xmin, ymin, zmin], [xmax, ymax, zmax]]`` [m], shape (2, 3).
        voxel_size: Voxel edge length used for ``volume`` [m].
        volume: Volume estimate ``occupied voxels * voxel_size**3`` [m^3].
        occupied_voxels: Number of voxels holding at least one sample.
        manipulability_index: Indices into ``points`` of the subset whose
            manipulability was computed, shape (K,).
        manipulability: Yoshikawa manipulability of that subset, shape (K,).
    """

    robot_name: str
    points: np.ndarray
    q: np.ndarray | None
    bounds: np.ndarray
    voxel_size: float
    volume: float
    occupied_voxels: int
    manipulability_index: np.ndarray
    manipulability: np.ndarray

    @property
    def n_samples(self) -> int:
        """Number of samples N."""
        return int(self.points.shape[0])

    @property
    def extent(self) -> np.ndarray:
        """Bounding-box edge lengths [m], shape (3,)."""
        return self.bounds[1] - self.bounds[0]

    def summary(self) -> dict[str, Any]:
        """Plain numbers for reports and JSON."""
        return {
            "robot": self.robot_name,
            "samples": self.n_samples,
            "bounds_min_m": self.bounds[0].tolist(),
            "bounds_max_m": self.bounds[1].tolist(),
            "voxel_size_m": self.voxel_size,
            "occupied_voxels": self.occupied_voxels,
            "volume_m3": self.volume,
            "manipulability_max": float(self.manipulability.max())
            if self.manipulability.size
            else 0.0,
        }


def _sampling_limits(robot: RobotLike) -> np.ndarray:
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
    return lim[:, 0] + u * (lim[:, 1] - lim[:, 0])


def voxel_volume(points: npt.ArrayLike, voxel_size: float) -> tuple[float, int]:
    """Volume covered by a point cloud, by counting occupied voxels.

    Args:
        points: Positions [m], shape (N, 3).
        voxel_size: Voxel edge length [m], > 0.

    Returns:
        ``(volume [m^3], occupied voxel count)``.
    """
    if not (voxel_size > 0 and math.isfinite(voxel_size)):
        raise InputError("voxel_size", f"must be finite and > 0 [m], got {voxel_size}")
    p = np.asarray(points, dtype=float).reshape(-1, 3)
    if p.shape[0] == 0:
        return 0.0, 0
    idx = np.floor((p - p.min(axis=0)) / voxel_size).astype(np.int64)
    dims = idx.max(axis=0) + 1
    if np.prod(dims.astype(float)) < 2**62:
        flat = np.ravel_multi_index(idx.T, tuple(int(d) for d in dims))
        count = int(np.unique(flat).size)
    else:  # too many cells for one int64 index: unique rows (slower, exact)
        count = int(np.unique(idx, axis=0).shape[0])
    return count * voxel_size**3, count


def sample_workspace(
    robot: RobotLike,
    n_samples: int = 1_000_000,
    *,
    rng: np.random.Generator | None = None,
    voxel_size: float | None = None,
    chunk: int = 250_000,
    keep_q: bool = False,
    manipulability_samples: int = 50_000,
    progress: Callable[[int, int], None] | None = None,
) -> Workspace:
    """Sample the reachable workspace of the tool point.

    Joints are drawn uniformly inside their limits (revolute joints with more
    than one turn of travel, or none, are sampled over one turn); FK runs in
    compiled batches of ``chunk`` samples.

    Args:
        robot: The robot.
        n_samples: Number of joint samples N (>= 1).
        rng: Random generator; ``np.random.default_rng(0)`` when None.
        voxel_size: Voxel edge [m] for the volume estimate; default: the
            bounding box's longest edge / 100.
        chunk: Samples per FK batch.
        keep_q: Keep the joint samples in ``Workspace.q``.
        manipulability_samples: Size of the random subset whose
            manipulability is computed (for the colouring), 0 to skip.
        progress: Called as ``progress(done, total)`` after every batch.

    Returns:
        The :class:`Workspace`.

    Raises:
        InputError: a non-positive count, or a prismatic joint without finite
            limits.
    """
    n_samples = int(n_samples)
    if n_samples < 1:
        raise InputError("n_samples", f"must be >= 1, got {n_samples}")
    if chunk < 1:
        raise InputError("chunk", f"must be >= 1, got {chunk}")
    rng = np.random.default_rng(0) if rng is None else rng
    lim = _sampling_limits(robot)
    k = max(0, min(int(manipulability_samples), n_samples))
    points = np.empty((n_samples, 3))
    q_all = np.empty((n_samples, robot.n)) if keep_q else None
    # The samples are i.i.d., so the first k of them are a random subset.
    q_sub = np.empty((k, robot.n))
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
            progress(done, n_samples)
    bounds = np.stack([points.min(axis=0), points.max(axis=0)])
    if voxel_size is None:
        edge = float((bounds[1] - bounds[0]).max())
        voxel_size = edge / 100.0 if edge > 0 else 1e-3
    volume, count = voxel_volume(points, voxel_size)
    sub = np.arange(k, dtype=np.int64)
    w = _manipulability(robot.chain, q_sub) if k else np.zeros(0)
    for arr in (points, bounds, sub, w):
        arr.setflags(write=False)
    return Workspace(
        robot_name=robot.name,
        points=points,
        q=q_all,
        bounds=bounds,
        voxel_size=float(voxel_size),
        volume=float(volume),
        occupied_voxels=count,
        manipulability_index=sub,
        manipulability=w,
    )
