"""Workspace analysis: where the tool point can go.

Monte-Carlo sampling of the joint space inside the joint limits, pushed through the
compiled batch FK: the reachable point cloud, its bounding box, a volume estimate
by voxel counting, cross-section plots in the XY / XZ planes and a manipulability
colouring.

.. math::

    V \\approx N_{occupied} \\cdot h^3

where ``h`` is the voxel edge length. The estimate converges from below as the
sample count grows (unvisited voxels) and from above as ``h`` shrinks (voxels cut
by the boundary), so quote it with its voxel size.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
import numpy.typing as npt

from robokin.exceptions import InputError
from robokin.kinematics import forward
from robokin.kinematics.jacobian import manipulability as _manipulability

if TYPE_CHECKING:
    from robokin.robot import Robot

__all__ = [
    "Workspace",
    "plot_cross_section",
    "random_joints",
    "sample_workspace",
    "save_workspace_plots",
    "voxel_volume",
]

Plane = Literal["xy", "xz", "yz"]
_AXES = {"x": 0, "y": 1, "z": 2}


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


def _sampling_limits(robot: Robot) -> np.ndarray:
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
    robot: Robot,
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


def _plane_axes(plane: str) -> tuple[int, int, int]:
    if plane not in ("xy", "xz", "yz"):
        raise InputError("plane", f"expected 'xy', 'xz' or 'yz', got {plane!r}")
    a, b = _AXES[plane[0]], _AXES[plane[1]]
    return a, b, 3 - a - b


def plot_cross_section(
    ws: Workspace,
    plane: Plane = "xy",
    *,
    at: float | None = None,
    thickness: float | None = None,
    color_by: Literal["manipulability", "density"] = "manipulability",
    ax: Any = None,
) -> Any:
    """Plot a slab of the point cloud in a coordinate plane.

    Args:
        ws: The sampled workspace.
        plane: ``"xy"`` (top view), ``"xz"`` or ``"yz"`` (side views).
        at: Position of the slab along the third axis [m]; default the middle
            of the bounds.
        thickness: Slab thickness [m]; default 5 % of the extent along the
            third axis (at least one voxel).
        color_by: ``"manipulability"`` colours the subset with known
            manipulability; ``"density"`` draws a 2D histogram of all samples.
        ax: A matplotlib Axes to draw in; a new figure when None.

    Returns:
        The matplotlib Axes.
    """
    if ax is None:
        import matplotlib.pyplot as plt

        _, ax = plt.subplots(figsize=(6, 5.5))
    a, b, c = _plane_axes(plane)
    lo, hi = ws.bounds[0, c], ws.bounds[1, c]
    at = 0.5 * (lo + hi) if at is None else float(at)
    if thickness is None:
        thickness = max(0.05 * (hi - lo), ws.voxel_size)
    names = "xyz"
    if color_by == "manipulability" and ws.manipulability.size:
        pts = ws.points[ws.manipulability_index]
        sel = np.abs(pts[:, c] - at) <= 0.5 * thickness
        if not sel.any():  # a thin arm (e.g. planar): fall back to all of the subset
            sel = np.ones(len(pts), dtype=bool)
        sc = ax.scatter(
            pts[sel, a],
            pts[sel, b],
            c=ws.manipulability[sel],
            s=2,
            cmap="viridis",
            linewidths=0,
        )
        ax.figure.colorbar(sc, ax=ax, label="manipulability")
    elif color_by in ("density", "manipulability"):
        pts = ws.points
        sel = np.abs(pts[:, c] - at) <= 0.5 * thickness
        if not sel.any():
            sel = np.ones(len(pts), dtype=bool)
        h = ax.hist2d(pts[sel, a], pts[sel, b], bins=120, cmin=1, cmap="magma")
        ax.figure.colorbar(h[3], ax=ax, label="samples")
    else:
        raise InputError(
            "color_by", f"expected 'manipulability' or 'density', got {color_by!r}"
        )
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel(f"{names[a]} [m]")
    ax.set_ylabel(f"{names[b]} [m]")
    ax.set_title(
        f"{ws.robot_name}: {plane.upper()} section, "
        f"{names[c]} = {at:.3f} ± {0.5 * thickness:.3f} m"
    )
    ax.grid(True, alpha=0.3)
    return ax


def save_workspace_plots(ws: Workspace, out_dir: str | Path) -> list[Path]:
    """Write the XY / XZ cross sections (manipulability and density) as PNG files.

    Args:
        ws: The sampled workspace.
        out_dir: Output folder (created if missing).

    Returns:
        The paths written.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out = Path(out_dir)
    if out.exists() and not out.is_dir():
        raise InputError("out_dir", f"{out} is a file, expected a folder")
    out.mkdir(parents=True, exist_ok=True)
    written = []
    for plane in ("xy", "xz"):
        fig, axes = plt.subplots(1, 2, figsize=(12, 5.5))
        plot_cross_section(ws, plane, color_by="manipulability", ax=axes[0])
        plot_cross_section(ws, plane, color_by="density", ax=axes[1])
        fig.tight_layout()
        path = out / f"{ws.robot_name}_workspace_{plane}.png"
        fig.savefig(path, dpi=110)
        plt.close(fig)
        written.append(path)
    return written
