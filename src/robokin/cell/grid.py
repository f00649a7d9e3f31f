"""The voxel grid of a reachability map and the tool orientations tried in each voxel.

Voxels are numbered in C order over ``(ix, iy, iz)``: voxel ``v`` has grid index
``numpy.unravel_index(v, shape)`` and centre ``origin + (index + 0.5) * voxel``.
A chunk of voxels ``[start, stop)`` is computed from its numbers alone, so any
split into chunks gives the same centres, bit for bit.

Tool orientations follow the usual capability-map construction (Zacharias et
al., "Capturing robot workspace structure: representing robot capabilities",
IROS 2007; Vahrenkamp et al., "Robot placement based on reachability
inversion", ICRA 2013): approach directions (the tool z axis) spread evenly over
the sphere on a Fibonacci (golden-angle) spiral, each combined with rolls about
that axis.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from robokin._text import short_repr
from robokin._validation import _real_array, check_finite_number
from robokin.exceptions import InputError
from robokin.spatial import rotz

__all__ = ["MAX_ORIENTATIONS", "VoxelGrid", "check_orientation_count", "tool_orientations"]

_MAX_VOXELS = 2**40  # a bound on V that keeps every index exact in int64 arithmetic
#: Most tool orientations per voxel (approach directions x rolls): 100,000 is a
#: direction every 0.7 degrees with 1 roll; a map's counts hold V x K bytes.
MAX_ORIENTATIONS = 100_000
_GOLDEN_ANGLE = math.pi * (3.0 - math.sqrt(5.0))  # [rad]


@dataclass(frozen=True, eq=False)
class VoxelGrid:
    """A regular grid of cubic voxels.

    Attributes:
        origin: The grid's lower corner in the world [m], shape (3,).
        voxel: Voxel edge length [m].
        shape: Voxels along x, y, z, ``(nx, ny, nz)``.
    """

    origin: np.ndarray
    voxel: float
    shape: tuple[int, int, int]

    def __post_init__(self) -> None:
        """Freeze the origin as a read-only float64 (3,) array."""
        origin = np.array(self.origin, dtype=np.float64).reshape(3)
        origin.setflags(write=False)
        object.__setattr__(self, "origin", origin)
        object.__setattr__(self, "voxel", float(self.voxel))
        object.__setattr__(self, "shape", tuple(int(s) for s in self.shape))

    @classmethod
    def from_region(cls, region: npt.ArrayLike, voxel: float) -> VoxelGrid:
        """The grid of voxels of edge ``voxel`` covering ``region``.

        The grid starts at the region's lower corner; its upper side lies at most
        one voxel beyond the region's.

        Args:
            region: ``[[x0, y0, z0], [x1, y1, z1]]`` [m], shape (2, 3).
            voxel: Edge length [m], > 0.

        Returns:
            The :class:`VoxelGrid`.

        Raises:
            InputError: a region that is not (2, 3) finite numbers or is empty
                (an upper coordinate not above the lower one), a voxel that is
                not a finite number > 0, or more than 2**40 voxels.
        """
        v = check_voxel(voxel)
        lo, hi = check_region(region)
        n = np.maximum(1, np.ceil((hi - lo) / v - 1e-9)).astype(np.int64)
        if float(np.prod(n.astype(float))) > _MAX_VOXELS:
            raise InputError(
                "voxel",
                f"{v * 1000:g} mm gives {int(n[0])} x {int(n[1])} x {int(n[2])} "
                "voxels, more than 2**40: choose a larger voxel or a smaller region",
            )
        return cls(lo, v, (int(n[0]), int(n[1]), int(n[2])))

    @property
    def size(self) -> int:
        """Number of voxels V."""
        nx, ny, nz = self.shape
        return nx * ny * nz

    @property
    def bounds(self) -> np.ndarray:
        """``[[x0, y0, z0], [x1, y1, z1]]`` [m] of the whole grid, shape (2, 3)."""
        return np.stack([self.origin, self.origin + np.array(self.shape) * self.voxel])

    def axis(self, k: int) -> np.ndarray:
        """Voxel centres along axis ``k`` (0 = x, 1 = y, 2 = z) [m], shape (n_k,)."""
        return self.origin[k] + (np.arange(self.shape[k]) + 0.5) * self.voxel

    def centers(self, start: int = 0, stop: int | None = None) -> np.ndarray:
        """Centres of voxels ``start .. stop - 1`` [m], shape (stop - start, 3)."""
        stop = self.size if stop is None else stop
        flat = np.arange(start, stop, dtype=np.int64)
        idx = np.stack(np.unravel_index(flat, self.shape), axis=-1)
        return self.origin + (idx + 0.5) * self.voxel

    def voxel_of(self, points: npt.ArrayLike) -> np.ndarray:
        """Voxel numbers of points [m] (..., 3); -1 outside the grid, shape (...).

        Raises:
            InputError: ``points`` is not real numbers of shape (..., 3).
        """
        try:
            p = np.asarray(points, dtype=np.float64)
        except (TypeError, ValueError):
            raise InputError("points", f"expected points (..., 3) [m], got "
                             f"{short_repr(points)}") from None
        if p.ndim == 0 or p.shape[-1] != 3:
            raise InputError("points", f"expected points (..., 3) [m], got shape {p.shape}")
        idx = np.floor((p - self.origin) / self.voxel).astype(np.int64)
        inside = ((idx >= 0) & (idx < np.array(self.shape))).all(axis=-1)
        clipped = np.clip(idx, 0, np.array(self.shape) - 1)
        flat = np.ravel_multi_index(tuple(np.moveaxis(clipped, -1, 0)), self.shape)
        return np.where(inside, flat, -1)


def check_voxel(voxel: object) -> float:
    """The voxel edge [m] as a float, or :class:`InputError` naming ``voxel``."""
    try:
        v = check_finite_number(voxel, "voxel")
    except InputError:
        raise InputError("voxel", f"expected an edge length > 0 [m], got "
                                  f"{short_repr(voxel)}") from None
    if not v > 0.0:
        raise InputError("voxel", f"expected an edge length > 0 [m], got {v:g}")
    return v


def check_region(region: npt.ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """Lower and upper corners (3,) [m] of a region, or :class:`InputError`."""
    r = _real_array(region, "region", "[[x0, y0, z0], [x1, y1, z1]] [m]")
    if r.shape != (2, 3):
        raise InputError(
            "region", f"expected [[x0, y0, z0], [x1, y1, z1]] [m], shape (2, 3), got {r.shape}"
        )
    if not np.isfinite(r).all():
        raise InputError("region", "holds a non-finite coordinate")
    lo, hi = r[0], r[1]
    if not (hi > lo).all():
        k = int(np.argmin(hi - lo))
        axis = "xyz"[k]
        raise InputError(
            "region",
            f"is empty: its upper {axis} ({hi[k]:g} m) is not above its lower "
            f"{axis} ({lo[k]:g} m)",
        )
    return lo.copy(), hi.copy()


def tool_orientations(count: int, rolls: int = 1) -> np.ndarray:
    """Tool orientations spread evenly: approach directions times rolls.

    The approach direction (the tool z axis) of orientation ``i * rolls + j`` is
    point ``i`` of a Fibonacci spiral on the unit sphere (``z_i = 1 - (2 i + 1) /
    count``, azimuth ``i`` times the golden angle), and the tool is turned by
    ``2 pi j / rolls`` about it from a reference frame whose x axis is
    perpendicular to the direction and to the world axis least aligned with it.

    Args:
        count: Number of approach directions (>= 1).
        rolls: Rolls about each direction (>= 1).

    Returns:
        Rotation matrices (count * rolls, 3, 3), tool frame in the world.

    Raises:
        InputError: a count or roll number that is not an integer >= 1.
    """
    count, rolls = check_orientation_count(count, rolls)
    i = np.arange(count, dtype=np.float64)
    z = 1.0 - (2.0 * i + 1.0) / count
    r = np.sqrt(np.maximum(0.0, 1.0 - z * z))
    phi = i * _GOLDEN_ANGLE
    d = np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=-1)
    # reference: the world axis least aligned with d (never parallel to it)
    ref = np.zeros((count, 3))
    ref[np.arange(count), np.argmin(np.abs(d), axis=-1)] = 1.0
    x = np.cross(ref, d)
    x /= np.linalg.norm(x, axis=-1, keepdims=True)
    y = np.cross(d, x)
    base = np.stack([x, y, d], axis=-1)  # columns x, y, z
    roll = 2.0 * np.pi * np.arange(rolls) / rolls
    Rz = rotz(roll)[:, :3, :3]
    out = base[:, None] @ Rz[None]
    return np.ascontiguousarray(out.reshape(count * rolls, 3, 3))


def check_orientation_count(count: object, rolls: object = 1, *,
                            names: tuple[str, str] = ("orientations", "rolls")
                            ) -> tuple[int, int]:
    """``(count, rolls)`` as integers >= 1 whose product is at most :data:`MAX_ORIENTATIONS`.

    Checked before anything is allocated (``orientations=10**9`` asked for 72 GB
    of rotation matrices).

    Args:
        count: Approach directions.
        rolls: Rolls about each.
        names: The argument names for messages (the CLI's ``--orientations``).

    Raises:
        InputError: not integers >= 1, or too many orientations (how many, the
            cap).
    """
    count = _positive_int(count, names[0])
    rolls = _positive_int(rolls, names[1])
    if count * rolls > MAX_ORIENTATIONS:
        times = f" x {rolls:,} rolls" if rolls > 1 else ""
        raise InputError(names[0], f"{count:,} orientations{times} = {count * rolls:,} "
                         f"per voxel, more than the {MAX_ORIENTATIONS:,} robokin "
                         "tries (robokin.cell.grid.MAX_ORIENTATIONS)")
    return count, rolls


def _positive_int(value: object, name: str) -> int:
    if isinstance(value, bool) or not isinstance(value, int | np.integer) or value < 1:
        raise InputError(name, f"expected an integer >= 1, got {short_repr(value)}")
    return int(value)
