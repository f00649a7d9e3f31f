"""Tool-path files: the poses a process path (a weld seam, a glue bead) goes through.

``robokin follow SCENE PATH`` reads one. Two forms, poses in the world frame, in
path order:

CSV, one pose per row, a header naming the columns with their units::

    x [mm],y [mm],z [mm],roll [deg],pitch [deg],yaw [deg]
    600,-100,300,180,0,90

Columns: ``x``, ``y``, ``z`` (``[m]`` or ``[mm]``) and the orientation as ``roll``,
``pitch``, ``yaw`` (``R = Rz(yaw) Ry(pitch) Rx(roll)``, about the fixed axes;
``[rad]`` or ``[deg]``) or as a unit quaternion ``qw``, ``qx``, ``qy``, ``qz``.
A column without a unit is SI. Any order; nothing else.

YAML::

    units: {length: mm, angle: deg}    # default m, rad
    poses:
      - {xyz: [600, -100, 300], rpy: [180, 0, 90]}
      - {xyz: [600, 100, 300], rpy: [180, 0, 90]}

Errors are :class:`~robokin.exceptions.ModelError` naming the file, the line and
the field; files are read through :func:`robokin.io.text_files.read_text_file`
(at most :data:`MAX_PATH_BYTES`) and the one YAML reader; at most
:data:`MAX_PATH_POSES` poses.
"""

from __future__ import annotations

import csv
import io
import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from robokin._text import short_repr
from robokin._units import ANGLE_UNITS, LENGTH_UNITS
from robokin.exceptions import ModelError
from robokin.io.text_files import MAX_CSV_BYTES, read_text_file
from robokin.io.yaml_reader import read_yaml_document
from robokin.spatial import matrix_from_quaternion, pose_from_xyz_rpy

__all__ = ["MAX_PATH_BYTES", "MAX_PATH_POSES", "read_tool_path"]

#: The largest tool-path file read [bytes].
MAX_PATH_BYTES = MAX_CSV_BYTES
#: The most poses a tool-path file may hold.
MAX_PATH_POSES = 1_000_000
_RPY = ("roll", "pitch", "yaw")
_QUAT = ("qw", "qx", "qy", "qz")


def read_tool_path(path: str | Path) -> np.ndarray:
    """The poses of a tool-path file (module docstring), world frame.

    Args:
        path: A ``.csv`` file, or a ``.yaml`` / ``.yml`` file.

    Returns:
        Poses (N, 4, 4) [m].

    Raises:
        ModelError: a missing, binary, oversized or malformed file, unknown or
            missing columns or keys, units, non-finite numbers, a quaternion that
            is not unit, more than :data:`MAX_PATH_POSES` poses (naming the file,
            the line and the field).
    """
    path = Path(path)
    if path.suffix.lower() in (".yaml", ".yml"):
        return _read_yaml(path)
    if path.suffix.lower() != ".csv":
        raise ModelError("expected a .csv or .yaml tool-path file", file=path)
    return _read_csv(path)


def _unit(cell: str, path: Path) -> tuple[str, str | None]:
    name, _, rest = cell.strip().partition("[")
    unit = rest.rstrip().rstrip("]").strip() if rest else None
    return name.strip().lower(), unit


def _scales(header: list[str], path: Path) -> tuple[dict[str, int], dict[str, float]]:
    cols: dict[str, int] = {}
    scale: dict[str, float] = {}
    for k, cell in enumerate(header):
        name, unit = _unit(cell, path)
        if name in cols:
            raise ModelError(f"column {name!r} given twice", file=path, line=1)
        if name in ("x", "y", "z"):
            table, what = LENGTH_UNITS, "a length: m or mm"
        elif name in _RPY:
            table, what = ANGLE_UNITS, "an angle: rad or deg"
        elif name in _QUAT:
            table, what = {"": 1.0}, "a quaternion component: no unit"
            unit = unit or ""
        else:
            raise ModelError(f"unknown column {short_repr(cell)}; expected x, y, z and "
                             "roll, pitch, yaw (or qw, qx, qy, qz)", file=path, line=1)
        if unit is not None and unit not in table:
            raise ModelError(f"column {name!r}: unknown unit [{unit[:20]}] "
                             f"({what})", file=path, line=1)
        cols[name] = k
        scale[name] = table[unit] if unit is not None else 1.0
    missing = [c for c in ("x", "y", "z") if c not in cols]
    has_rpy, has_q = any(c in cols for c in _RPY), any(c in cols for c in _QUAT)
    if has_rpy == has_q:
        missing.append("roll, pitch, yaw or qw, qx, qy, qz (one of them)")
    else:
        missing += [c for c in (_RPY if has_rpy else _QUAT) if c not in cols]
    if missing:
        raise ModelError(f"missing column(s): {', '.join(missing)}", file=path, line=1)
    return cols, scale


def _read_csv(path: Path) -> np.ndarray:
    text = read_text_file(path, max_bytes=MAX_PATH_BYTES)
    rows = [(k, r) for k, r in enumerate(csv.reader(io.StringIO(text)), start=1)
            if r and any(c.strip() for c in r)]
    if not rows:
        raise ModelError("is empty, expected a header line and poses", file=path)
    cols, scale = _scales(rows[0][1], path)
    if len(rows) - 1 > MAX_PATH_POSES:
        raise ModelError(f"holds {len(rows) - 1} poses; at most {MAX_PATH_POSES}",
                         file=path)
    data = np.empty((len(rows) - 1, len(cols)))
    for i, (line, row) in enumerate(rows[1:]):
        if len(row) != len(cols):
            raise ModelError(f"{len(row)} values, the header has {len(cols)}",
                             file=path, line=line)
        try:
            data[i] = [float(v) for v in row]
        except ValueError:
            raise ModelError("holds a value that is not a number", file=path,
                             line=line) from None
        if not np.isfinite(data[i]).all():
            raise ModelError("holds a non-finite value", file=path, line=line)
    if len(data) == 0:
        raise ModelError("holds no poses after its header", file=path)

    def col(name: str) -> np.ndarray:
        return data[:, cols[name]] * scale[name]

    xyz = np.stack([col(c) for c in ("x", "y", "z")], axis=-1)
    if "roll" in cols:
        return pose_from_xyz_rpy(xyz, np.stack([col(c) for c in _RPY], axis=-1))
    q = np.stack([col(c) for c in _QUAT], axis=-1)
    bad = np.flatnonzero(np.abs(np.linalg.norm(q, axis=-1) - 1.0) > 1e-6)
    if bad.size:
        raise ModelError("the quaternion qw, qx, qy, qz is not of unit length",
                         file=path, line=rows[1 + int(bad[0])][0])
    T = np.zeros((len(q), 4, 4))
    T[:, :3, :3] = matrix_from_quaternion(q)[:, :3, :3]
    T[:, :3, 3] = xyz
    T[:, 3, 3] = 1.0
    return T


def _vector(value: Any, n: int, field: str, path: Path) -> list[float]:
    if (not isinstance(value, (list, tuple)) or len(value) != n
            or not all(isinstance(v, (int, float)) and not isinstance(v, bool)
                       and math.isfinite(v) for v in value)):
        raise ModelError(f"expected {n} finite numbers, got {short_repr(value)}",
                         file=path, field=field)
    return [float(v) for v in value]


def _read_yaml(path: Path) -> np.ndarray:
    ydoc = read_yaml_document(path, max_bytes=MAX_PATH_BYTES)
    try:
        return _poses_from_document(ydoc.data, path)
    except ModelError as exc:
        raise ydoc.locate(exc) from None


def _poses_from_document(doc: Any, path: Path) -> np.ndarray:
    if not isinstance(doc, Mapping):
        raise ModelError("expected a mapping with 'poses'", file=path)
    extra = sorted(set(doc) - {"units", "poses"})
    if extra:
        raise ModelError(f"unknown key(s) {extra}; known: ['poses', 'units']",
                         file=path, field=str(extra[0]))
    units = doc.get("units", {})
    if not isinstance(units, Mapping) or set(units) - {"length", "angle"}:
        raise ModelError("expected {length: m|mm, angle: rad|deg}", file=path,
                         field="units")
    length, angle = units.get("length", "m"), units.get("angle", "rad")
    if length not in LENGTH_UNITS or angle not in ANGLE_UNITS:
        raise ModelError(f"expected length m or mm and angle rad or deg, got "
                         f"{short_repr(dict(units))}", file=path, field="units")
    poses = doc.get("poses")
    if not isinstance(poses, list) or not poses:
        raise ModelError("expected a non-empty list of {xyz: [x, y, z], rpy: [r, p, y]}",
                         file=path, field="poses")
    if len(poses) > MAX_PATH_POSES:
        raise ModelError(f"holds {len(poses)} poses; at most {MAX_PATH_POSES}",
                         file=path, field="poses")
    xyz = np.empty((len(poses), 3))
    rpy = np.empty((len(poses), 3))
    for k, item in enumerate(poses):
        where = f"poses[{k}]"
        if not isinstance(item, Mapping) or set(item) != {"xyz", "rpy"}:
            raise ModelError(f"expected {{xyz: [x, y, z], rpy: [roll, pitch, yaw]}}, got "
                             f"{short_repr(item)}", file=path, field=where)
        xyz[k] = _vector(item["xyz"], 3, f"{where}.xyz", path)
        rpy[k] = _vector(item["rpy"], 3, f"{where}.rpy", path)
    return pose_from_xyz_rpy(xyz * LENGTH_UNITS[length], rpy * ANGLE_UNITS[angle])
