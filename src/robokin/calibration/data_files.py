"""Measurement CSV files: joint values and the measured tool position (and rotation).

One measurement per row; columns are found **by name** in the header line (the
first line that is not a ``#`` comment or blank), units in brackets:

* one column per joint, named as the robot's joints (``robokin show ROBOT``):
  ``[rad]`` (default) or ``[deg]``, ``[m]`` (default) or ``[mm]`` for a
  prismatic joint;
* ``x``, ``y``, ``z``: the measured tool point in the measuring frame, ``[m]``
  (default) or ``[mm]``;
* for poses, one rotation: ``qw, qx, qy, qz`` (a unit quaternion), or ``roll,
  pitch, yaw`` (robokin's RPY: ``Rz(yaw) Ry(pitch) Rx(roll)``), or ``rx, ry, rz``
  (a rotation vector), angles ``[rad]`` or ``[deg]``.

Other columns are ignored. Cells are separated by ``,`` (or ``;``). See
``docs/calibration.md``.
"""

from __future__ import annotations

import math
import re
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt

from robokin._units import ANGLE_UNITS, LENGTH_UNITS
from robokin.exceptions import InputError, ModelError

if TYPE_CHECKING:
    from robokin.robot import Robot

__all__ = ["MAX_BYTES", "read_measurements", "write_measurements"]

#: Largest measurement file read [bytes].
MAX_BYTES = 64 << 20
_HEADER = re.compile(r"^\s*(?P<name>[^\[]*?)\s*(?:\[(?P<unit>[^\]]*)\])?\s*$")
#: Unit name (None: not given, SI) -> factor to SI.
_LENGTH: dict[str | None, float] = {None: 1.0, **dict(LENGTH_UNITS.items())}
_ANGLE: dict[str | None, float] = {None: 1.0, **dict(ANGLE_UNITS.items())}
_ROTATIONS = (("qw", "qx", "qy", "qz"), ("roll", "pitch", "yaw"), ("rx", "ry", "rz"))


def _table(path: Path) -> tuple[list[tuple[str, str | None]], np.ndarray, int]:
    from robokin.io.text_files import read_text_file

    text = read_text_file(path, max_bytes=MAX_BYTES)
    lines = [(k, ln) for k, ln in enumerate(text.splitlines(), start=1)
             if ln.strip() and not ln.lstrip().startswith("#")]
    if len(lines) < 2:
        raise ModelError("expected a header line and at least one row", file=path)
    head = lines[0][1]
    sep = ";" if head.count(";") > head.count(",") else ","
    header = []
    for cell in head.split(sep):
        m = _HEADER.match(cell)
        assert m is not None  # the pattern matches any text
        header.append((m.group("name"), m.group("unit").strip() if m.group("unit")
                       else None))
    rows = []
    for k, ln in lines[1:]:
        parts = ln.split(sep)
        if len(parts) != len(header):
            raise ModelError(f"{len(parts)} values, the header has {len(header)}",
                             file=path, line=k)
        try:
            vals = [float(p) for p in parts]
        except ValueError:
            raise ModelError("a value that is not a number", file=path, line=k) from None
        if not all(math.isfinite(v) for v in vals):
            raise ModelError("a value that is not finite", file=path, line=k)
        rows.append(vals)
    return header, np.array(rows), lines[1][0]


def _column(header: list[tuple[str, str | None]], data: np.ndarray, name: str,
            units: dict[str | None, float], path: Path) -> np.ndarray | None:
    hits = [i for i, (n, _) in enumerate(header) if n == name]
    if not hits:
        return None
    if len(hits) > 1:
        raise ModelError(f"column {name!r} appears {len(hits)} times", file=path)
    unit = header[hits[0]][1]
    if unit not in units:
        raise ModelError(f"column {name!r}: unknown unit [{unit}]; use "
                         f"{sorted(u for u in units if u)}", file=path)
    return data[:, hits[0]] * units[unit]


def read_measurements(path: str | Path, robot: Robot, kind: str = "position"
                      ) -> tuple[np.ndarray, np.ndarray]:
    """Joint values and measurements from a CSV file (see the module docstring).

    Args:
        path: The CSV file.
        robot: The robot (its joint names and kinds).
        kind: ``"position"`` (x, y, z) or ``"pose"`` (also a rotation).

    Returns:
        ``q`` (N, n) [rad, m] and the measurements: points (N, 3) [m] or poses
        (N, 4, 4).

    Raises:
        ModelError: a missing column (listing what is expected), an unknown unit,
            a ragged or non-numeric row (naming the file and line).
    """
    path = Path(path)
    if kind not in ("position", "pose"):
        raise InputError("kind", f"expected 'position' or 'pose', got {kind!r}")
    header, data, _ = _table(path)
    names = [n for n, _ in header]
    q = []
    for name, rev in zip(robot.joint_names, robot.is_revolute):
        col = _column(header, data, name, _ANGLE if rev else _LENGTH, path)
        if col is None:
            raise ModelError(f"no column for joint {name!r}; expected the joints "
                             f"{list(robot.joint_names)} and x, y, z; found {names}",
                             file=path)
        q.append(col)
    xyz = [_column(header, data, c, _LENGTH, path) for c in "xyz"]
    if any(c is None for c in xyz):
        raise ModelError(f"no x, y, z columns (the measured point); found {names}",
                         file=path)
    p = np.stack(xyz, axis=1)  # type: ignore[arg-type]
    if kind == "position":
        return np.stack(q, axis=1), p
    return np.stack(q, axis=1), _poses(header, data, p, path)


def _poses(header: list[tuple[str, str | None]], data: np.ndarray, p: np.ndarray,
           path: Path) -> np.ndarray:
    from robokin.spatial import (
        matrix_from_axis_angle,
        matrix_from_quaternion,
        matrix_from_rpy,
    )

    names = {n for n, _ in header}
    for cols in _ROTATIONS:
        if set(cols) <= names:
            break
    else:
        raise ModelError("kind 'pose' needs a rotation: columns qw, qx, qy, qz, or "
                         "roll, pitch, yaw, or rx, ry, rz", file=path)
    if cols[0] == "qw":
        quat = np.stack([_column(header, data, c, {None: 1.0}, path)  # type: ignore[misc]
                         for c in cols], axis=1)
        norm = np.linalg.norm(quat, axis=1)
        if (np.abs(norm - 1.0) > 1e-3).any():
            k = int(np.argmax(np.abs(norm - 1.0)))
            raise ModelError(f"row {k + 1}: the quaternion's norm is {norm[k]:.6g}, "
                             "expected 1", file=path)
        T = matrix_from_quaternion(quat / norm[:, None])
    else:
        ang = np.stack([_column(header, data, c, _ANGLE, path)  # type: ignore[misc]
                        for c in cols], axis=1)
        T = matrix_from_rpy(ang) if cols[0] == "roll" else matrix_from_axis_angle(ang)
    T[:, :3, 3] = p
    return T


def write_measurements(path: str | Path, robot: Robot, q: npt.ArrayLike,
                       measured: npt.ArrayLike, *, mm: bool = True, deg: bool = True,
                       comment: str = "", overwrite: bool = False) -> Path:
    """Write measurements as CSV (joints, x y z, and qw qx qy qz for poses), atomically.

    Args:
        path: Target file.
        robot: The robot (joint names, kinds).
        q: Joint values (N, n) [rad, m].
        measured: Points (N, 3) or poses (N, 4, 4) [m].
        mm: Lengths in millimetres (else metres).
        deg: Joint angles in degrees (else radians).
        comment: A first ``#`` line.
        overwrite: Replace an existing file.
    """
    from robokin.io.atomic import write_atomic
    from robokin.spatial import quaternion_from_matrix

    qa = np.asarray(q, dtype=float)
    m = np.asarray(measured, dtype=float)
    L, lu = (1e3, "mm") if mm else (1.0, "m")
    A, au = (180.0 / math.pi, "deg") if deg else (1.0, "rad")
    cols: list[str] = []
    vals: list[np.ndarray] = []
    for k, (name, rev) in enumerate(zip(robot.joint_names, robot.is_revolute)):
        cols.append(f"{name} [{au if rev else lu}]")
        vals.append(qa[:, k] * (A if rev else L))
    p = m[:, :3, 3] if m.ndim == 3 else m
    cols += [f"{c} [{lu}]" for c in "xyz"]
    vals += [p[:, i] * L for i in range(3)]
    if m.ndim == 3:
        quat = quaternion_from_matrix(m)
        cols += ["qw", "qx", "qy", "qz"]
        vals += [quat[:, i] for i in range(4)]
    table = np.stack(vals, axis=1)
    lines: Sequence[str] = ([f"# {comment}"] if comment else []) + [",".join(cols)] + [
        ",".join(repr(float(v)) for v in row) for row in table]
    return write_atomic(path, "\n".join(lines) + "\n", overwrite=overwrite)
