"""Trajectory files: CSV, JSON, UR script, controller profiles, logged real runs.

CSV (the format other tools read and write)::

    t [s],shoulder [rad],upper_arm [rad],...,slide [m]
    0,0.1,0.2,...,0.05

One header line (name and unit in brackets per column), comma separated, one row
per sample. Units accepted on read: ``[s]``/``[ms]`` for time, ``[rad]``/``[deg]``
for angles, ``[m]``/``[mm]`` for lengths; values are converted to SI once, here.
Optional velocity and acceleration columns are named ``<joint>.vel [rad/s]`` and
``<joint>.acc [rad/s^2]`` (``write_csv(..., rates=True)``); without them the reader
differentiates positions numerically.

A :class:`ControllerProfile` describes what a real controller expects (joint order,
signs, zero offsets between the model's zero and the controller's, degrees or
radians, mm or m); :func:`write_csv` applies it and :func:`read_csv` undoes it, so
the file a controller reads is right the first time.

Every writer goes through :func:`robokin.io.atomic.write_atomic` (a temporary
file next to the target, fsynced, renamed); an existing file is replaced only with
``overwrite=True``.

Reading: joint columns are matched to the robot's joints by their header names
when ``joint_names=`` is given (any column order; unknown, missing or extra
names are refused, listing the expected ones); a file without a header line is
read by position, with a warning saying so. Times must increase: a log whose time
goes backwards is refused, never sorted. Files are read through
:func:`robokin.io.text_files.read_text_file` (at most
:data:`~robokin.io.text_files.MAX_CSV_BYTES`).
"""

from __future__ import annotations

import json
import re
import warnings
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any, Literal, TypedDict

import numpy as np
import numpy.typing as npt
from typing_extensions import Unpack

from robokin._text import short_repr
from robokin._units import ANGLE_UNITS, LENGTH_UNITS
from robokin.exceptions import InputError, ModelError
from robokin.io.atomic import write_atomic
from robokin.io.text_files import MAX_CSV_BYTES, read_text_file
from robokin.trajectory.controller_profile import (
    PROGRAMS,
    ControllerProfile,
    load_profile,
)
from robokin.trajectory.samples import Trajectory

__all__ = [
    "PROGRAMS",
    "ControllerProfile",
    "load_profile",
    "read_csv",
    "read_json",
    "read_log",
    "ur_script",
    "write_csv",
    "write_json",
    "write_ur_script",
]

_TIME = {"s": 1.0, "ms": 1e-3}
_HEADER = re.compile(r"^\s*(?P<name>.*?)\s*(?:\[(?P<unit>[^\]]*)\])?\s*$")


# ------------------------------------------------------------------------- CSV
def _unit_label(unit: str, rate: int) -> str:
    return unit + ("", "/s", "/s^2")[rate]


def write_csv(
    traj: Trajectory,
    path: str | Path,
    joint_names: Sequence[str] | None = None,
    *,
    rates: bool = False,
    profile: ControllerProfile | None = None,
    precision: int | None = None,
    overwrite: bool = False,
) -> Path:
    """Write a trajectory as CSV (see the module docstring for the format).

    Args:
        traj: The trajectory.
        path: Target file.
        joint_names: Column names (default: ``traj.joint_names``, else q1..qn).
        rates: Also write velocity and acceleration columns.
        profile: Controller profile applied to the values (order, signs,
            offsets, units); default radians and metres in model order.
        precision: Significant digits (default: the shortest text that reads
            back to the same float).
        overwrite: Replace an existing file.

    Returns:
        The path written.

    Raises:
        InputError: wrong number of names, or the file exists and ``overwrite``
            is False.
    """
    return write_atomic(path, csv_text(traj, joint_names, rates=rates,
                                            profile=profile, precision=precision),
                             overwrite=overwrite)


def csv_text(traj: Trajectory, joint_names: Sequence[str] | None = None, *,
             rates: bool = False, profile: ControllerProfile | None = None,
             precision: int | None = None) -> str:
    """The CSV text :func:`write_csv` writes."""
    names = list(joint_names) if joint_names is not None else list(traj.names())
    if len(names) != traj.n:
        raise InputError("joint_names", f"expected {traj.n} names, got {len(names)}")
    profile = profile or ControllerProfile()
    rev = traj.revolute()
    cols_names = profile.column_names(names)
    crev = profile.column_revolute(rev)
    unit = np.array([ANGLE_UNITS[profile.angle_unit] if r else LENGTH_UNITS[profile.length_unit]
                     for r in crev])
    ulab = [profile.angle_unit if r else profile.length_unit for r in crev]
    blocks = [traj.t[:, None], profile.export(traj.q) / unit]
    header = ["t [s]"] + [f"{nm} [{u}]" for nm, u in zip(cols_names, ulab)]
    if rates:
        blocks += [profile.export(traj.qd, rates=True) / unit,
                   profile.export(traj.qdd, rates=True) / unit]
        header += [f"{nm}.vel [{_unit_label(u, 1)}]" for nm, u in zip(cols_names, ulab)]
        header += [f"{nm}.acc [{_unit_label(u, 2)}]" for nm, u in zip(cols_names, ulab)]
    data = np.hstack(blocks)
    for h in header:
        if "," in h:
            raise InputError("joint_names", f"a name may not hold a comma: {short_repr(h)}")
    fmt = "%r" if precision is None else f"%.{int(precision)}g"
    lines = [",".join(header)]
    lines += [",".join(fmt % v for v in row) for row in data.tolist()]
    return "\n".join(lines) + "\n"


def _parse_header(cols: list[str]) -> list[tuple[str, str | None]]:
    out = []
    for c in cols:
        m = _HEADER.match(c)
        if m is None:  # pragma: no cover - the pattern matches any text
            raise ModelError(f"unreadable column header {short_repr(c)}")
        out.append((m.group("name"), m.group("unit").strip() if m.group("unit") else None))
    return out


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def _load_table(path: Path, max_bytes: int) -> tuple[list[str] | None, np.ndarray, int]:
    """The header (None when the file has none), the numbers, the first data line.

    The line number of the first data row is for messages.
    """
    text = read_text_file(path, max_bytes=max_bytes)
    numbered = [(k, ln) for k, ln in enumerate(text.splitlines(), start=1)
                if ln.strip() and not ln.lstrip().startswith("#")]
    if not numbered:
        raise ModelError("empty file", file=path)
    first = numbered[0][1]
    sep = ";" if first.count(";") > first.count(",") else ","
    fields = [h.strip() for h in first.split(sep)]
    header: list[str] | None = fields
    if all(_is_number(f) for f in fields):
        header = None  # no header line: the first line is data
    else:
        numbered = numbered[1:]
    width = len(fields)
    rows = []
    for k, ln in numbered:
        parts = ln.split(sep)
        if len(parts) != width:
            raise ModelError(f"{len(parts)} values, the {'header' if header else 'first line'}"
                             f" has {width}", file=path, line=k)
        try:
            rows.append([float(p) for p in parts])
        except ValueError:
            raise ModelError("holds a value that is not a number", file=path,
                             line=k) from None
    if not rows:
        raise ModelError("no data rows", file=path)
    data = np.array(rows)
    if not np.isfinite(data).all():
        bad = numbered[int(np.argwhere(~np.isfinite(data))[0, 0])][0]
        raise ModelError("holds a non-finite value", file=path, line=bad)
    return header, data, numbered[0][0]


def _differentiate(t: np.ndarray, x: np.ndarray) -> np.ndarray:
    if len(t) < 2:
        return np.zeros_like(x)
    return np.gradient(x, t, axis=0, edge_order=2 if len(t) > 2 else 1)


def _columns(header: list[str] | None, width: int, path: Path,
             joint_names: Sequence[str] | None
             ) -> tuple[list[tuple[str, str | None]], list[list[int]]]:
    """Parsed header cells and the column indices of positions, rates, accelerations.

    The indices are ordered as ``joint_names`` when given.
    """
    if header is None:
        n = width - 1
        if n == 0:
            raise ModelError("no joint columns after the time column", file=path)
        if joint_names is not None and n != len(joint_names):
            raise ModelError(f"has {n} joint columns and no header, the robot "
                             f"{len(joint_names)} joints: {list(joint_names)}",
                             file=path)
        names = list(joint_names) if joint_names is not None else \
            [f"q{i + 1}" for i in range(n)]
        warnings.warn(f"{path} has no header line: its columns are read by position "
                      f"(time [s], then {', '.join(names[:8])}"
                      f"{' ...' if len(names) > 8 else ''} in SI units)", UserWarning,
                      stacklevel=4)
        cells: list[tuple[str, str | None]] = [(nm, None) for nm in ["t", *names]]
        return cells, [list(range(1, len(names) + 1)), [], []]
    cells = _parse_header(header)
    groups: list[dict[str, int]] = [{}, {}, {}]
    for k, (name, _unit) in enumerate(cells[1:], start=1):
        rate = 1 if name.endswith(".vel") else 2 if name.endswith(".acc") else 0
        base = name[:-4] if rate else name
        if base in groups[rate]:
            raise ModelError(f"column {short_repr(header[k])} repeats the joint "
                             f"{short_repr(base)}", file=path, line=1)
        groups[rate][base] = k
    pos = groups[0]
    if not pos:
        raise ModelError("no joint columns after the time column", file=path)
    if joint_names is None:
        order = list(pos)
    else:
        order = list(joint_names)
        unknown = [nm for nm in pos if nm not in order]
        missing = [nm for nm in order if nm not in pos]
        if unknown or missing:
            what = []
            if unknown:
                what.append(f"unknown {short_repr(unknown, 120)}")
            if missing:
                what.append(f"missing {short_repr(missing, 120)}")
            raise ModelError(
                f"{len(pos)} joint columns do not match the {len(order)} joints: "
                f"{'; '.join(what)}; expected the names {list(order)} (any order, "
                "optionally with units such as [rad])", file=path, line=1)
    index = [[g[nm] for nm in order] if all(nm in g for nm in order) else []
             for g in groups]
    return cells, index


def _trajectory_from_table(header: list[str] | None, data: np.ndarray, path: Path,
                           profile: ControllerProfile | None,
                           is_revolute: npt.ArrayLike | None,
                           joint_names: Sequence[str] | None) -> Trajectory:
    cells, (pos, vel, acc) = _columns(header, data.shape[1], path,
                                      None if profile is not None else joint_names)
    tunit = cells[0][1]
    if tunit is not None and tunit not in _TIME:
        raise ModelError(f"unknown time unit [{short_repr(tunit, 20)}]; use [s] or "
                         "[ms]", file=path, line=1)
    t = data[:, 0] * _TIME.get(tunit or "s")
    n = len(pos)
    rev_given = None if is_revolute is None else np.asarray(is_revolute, bool).reshape(-1)
    if rev_given is not None and rev_given.shape != (n,):
        raise InputError("is_revolute", f"expected {n} flags, got {rev_given.shape}")

    def convert(cols: list[int]) -> tuple[np.ndarray, np.ndarray]:
        out = np.empty((len(t), len(cols)))
        rev = np.ones(len(cols), bool)
        for i, k in enumerate(cols):
            unit = cells[k][1]
            base = None if unit is None else unit.split("/")[0]
            if base is None:
                rev[i] = True if rev_given is None else rev_given[i]
                scale = 1.0
            elif base in ANGLE_UNITS:
                scale = ANGLE_UNITS[base]
            elif base in LENGTH_UNITS:
                rev[i], scale = False, LENGTH_UNITS[base]
            else:
                raise ModelError(f"unknown unit [{short_repr(unit, 20)}] in column "
                                 f"{short_repr(cells[k][0])}; use rad, deg, m or mm",
                                 file=path, line=1)
            out[:, i] = data[:, k] * scale
        return out, rev

    q, rev = convert(pos)
    names = [cells[k][0] for k in pos]
    qd = convert(vel)[0] if vel else None
    qdd = convert(acc)[0] if acc else None
    if profile is not None:
        q = profile.undo(q)
        qd = None if qd is None else profile.undo(qd, rates=True)
        qdd = None if qdd is None else profile.undo(qdd, rates=True)
        order = np.arange(n) if profile.order is None else np.asarray(profile.order)
        model_names = [""] * n
        model_rev = np.ones(n, bool)
        for col, j in enumerate(order):
            model_names[j] = names[col]
            model_rev[j] = rev[col]
        names, rev = model_names, model_rev
    if qd is None:
        qd = _differentiate(t, q)
    if qdd is None:
        qdd = _differentiate(t, qd)
    return Trajectory(t, q, qd, qdd,
                      joint_names=None if header is None and joint_names is None
                      else tuple(names),
                      is_revolute=rev, via_times=np.array([t[0], t[-1]]))


def _check_times(t: np.ndarray, path: Path, first_line: int, *,
                 allow_repeats: bool) -> np.ndarray:
    """Rows to keep, refusing time that goes backwards (naming the line).

    Repeated time stamps are refused too unless ``allow_repeats`` (then the first
    of each is kept).
    """
    step = np.diff(t)
    back = np.flatnonzero(step < 0 if allow_repeats else step <= 0)
    if back.size:
        k = int(back[0]) + 1
        what = "goes backwards" if step[k - 1] < 0 else "does not increase"
        raise ModelError(f"time {what} ({t[k - 1]:g} s, then {t[k]:g} s); robokin "
                         "refuses it rather than reorder the samples",
                         file=path, line=first_line + k)
    return np.concatenate([[True], step > 0])


class _TableKeywords(TypedDict, total=False):
    """The keywords of :func:`read_csv` and :func:`read_log`."""

    profile: ControllerProfile | None
    is_revolute: npt.ArrayLike | None
    joint_names: Sequence[str] | None
    max_bytes: int


def _read_table(path: Path, *, allow_repeats: bool,
                profile: ControllerProfile | None = None,
                is_revolute: npt.ArrayLike | None = None,
                joint_names: Sequence[str] | None = None,
                max_bytes: int = MAX_CSV_BYTES) -> Trajectory:
    """A trajectory table read and checked (see :func:`read_csv`)."""
    header, data, first = _load_table(path, max_bytes)
    keep = _check_times(data[:, 0], path, first, allow_repeats=allow_repeats)
    return _trajectory_from_table(header, data[keep], path, profile, is_revolute,
                                  joint_names)


def read_csv(path: str | Path, **options: Unpack[_TableKeywords]) -> Trajectory:
    """Read a trajectory CSV (the :func:`write_csv` format, or a logged run).

    The first column is time; the others are joints, optionally followed by
    ``.vel`` and ``.acc`` columns. Units in brackets are converted to SI;
    a column without a unit is taken as SI. Velocities and accelerations missing
    from the file are differentiated from the positions.

    Args:
        path: The file.
        profile: The controller profile the file was written with (undone here;
            columns are then taken in the profile's order, not by name).
        is_revolute: (n,) flags for columns without units (default: angles), in
            the order of ``joint_names`` when given.
        joint_names: The robot's joint names: columns are matched by header
            name, in any order, and returned in this order. A file without a
            header is read by position (with a warning).
        max_bytes: The largest file accepted [bytes].

    Returns:
        A :class:`~robokin.trajectory.samples.Trajectory` in model order and SI.

    Raises:
        ModelError: missing, binary or too large file, ragged or non-numeric
            rows, unknown units, joint columns that do not match
            ``joint_names``, times that do not increase (naming the file and
            line).
    """
    return _read_table(Path(path), allow_repeats=False, **options)


def read_log(path: str | Path, **options: Unpack[_TableKeywords]) -> Trajectory:
    """Read a logged real run (CSV of time + joint angles) as a Trajectory.

    Like :func:`read_csv`, but tolerant of what loggers write: repeated time
    stamps are dropped (the first is kept) and the start time is kept as logged.
    Time going backwards is refused: a reordered log is a broken log.

    Raises:
        ModelError: as :func:`read_csv`.
    """
    return _read_table(Path(path), allow_repeats=True, **options)


# ------------------------------------------------------------------------ JSON
def write_json(
    traj: Trajectory, path: str | Path, *, robot_name: str | None = None,
    overwrite: bool = False,
) -> Path:
    """Write a trajectory as JSON (SI units; times, q, qd, qdd, names, via times).

    Raises:
        InputError: the file exists and ``overwrite`` is False.
    """
    doc = {
        "format": "robokin-trajectory",
        "version": 1,
        "robot": robot_name,
        "units": {"time": "s", "angle": "rad", "length": "m"},
        "space": traj.space,
        "joint_names": list(traj.names()),
        "is_revolute": [bool(r) for r in traj.revolute()],
        "via_times": traj.via_times.tolist(),
        "labels": list(traj.labels),
        "t": traj.t.tolist(),
        "q": traj.q.tolist(),
        "qd": traj.qd.tolist(),
        "qdd": traj.qdd.tolist(),
    }
    return write_atomic(path, json.dumps(doc) + "\n", overwrite=overwrite)


def read_json(path: str | Path, *, max_bytes: int = MAX_CSV_BYTES) -> Trajectory:
    """Read a trajectory written by :func:`write_json` (at most ``max_bytes``).

    Raises:
        ModelError: missing file, not JSON, or missing / inconsistent fields.
    """
    path = Path(path)
    try:
        doc = json.loads(read_text_file(path, max_bytes=max_bytes))
    except json.JSONDecodeError as exc:
        raise ModelError(f"not valid JSON: {exc.msg}", file=path,
                         line=exc.lineno) from None
    if not isinstance(doc, Mapping):
        raise ModelError("expected a JSON object at the top level", file=path)
    for key in ("t", "q", "qd", "qdd"):
        if key not in doc:
            raise ModelError(f"missing field '{key}'", file=path, field=key)
    try:
        return Trajectory(doc["t"], doc["q"], doc["qd"], doc["qdd"],
                          joint_names=doc.get("joint_names"),
                          via_times=np.asarray(doc.get("via_times", []), float),
                          space=doc.get("space", "joint"),
                          is_revolute=doc.get("is_revolute"),
                          labels=tuple(doc.get("labels", ())))
    except InputError as exc:
        raise ModelError(exc.reason, file=path, field=exc.argument) from None


# ---------------------------------------------------------------------- UR script
def ur_script(
    traj: Trajectory,
    *,
    mode: Literal["servoj", "movej"] = "servoj",
    program: str = "robokin_motion",
    lookahead_time: float = 0.1,
    gain: float = 300.0,
    speed: float = 1.05,
    acceleration: float = 1.4,
    blend_radius: float = 0.0,
    profile: ControllerProfile | None = None,
) -> str:
    """A URScript program that plays the trajectory.

    ``servoj`` streams every sample (``t = dt``), the way a 200 Hz plan is played;
    ``movej`` lists only the via points (the controller plans between them).

    Args:
        traj: Joint-space trajectory (radians).
        mode: ``"servoj"`` or ``"movej"``.
        program: The ``def`` name.
        lookahead_time: servoj lookahead [s].
        gain: servoj gain.
        speed: movej joint speed [rad/s].
        acceleration: movej joint acceleration [rad/s^2].
        blend_radius: movej blend radius [m].
        profile: Joint order / signs / offsets (URScript always takes radians).

    Raises:
        InputError: unknown mode, or a trajectory in actuator space.
    """
    if mode not in ("servoj", "movej"):
        raise InputError("mode", f"expected 'servoj' or 'movej', got {short_repr(mode)}")
    if traj.space != "joint":
        raise InputError("traj", "URScript takes joint angles: convert to joint space")
    prof = profile or ControllerProfile()
    q = prof.export(traj.q)

    def fmt(row: np.ndarray) -> str:
        return "[" + ", ".join(f"{v:.9f}" for v in row) + "]"

    lines = [f"def {program}():",
             f"  # generated by robokin: {len(traj)} samples, {traj.duration:.4f} s"]
    if mode == "servoj":
        dt = traj.dt
        lines.append(f"  movej({fmt(q[0])}, a={acceleration:g}, v={speed:g})")
        for row in q[1:]:
            lines.append(f"  servoj({fmt(row)}, t={dt:.6g}, lookahead_time="
                         f"{lookahead_time:g}, gain={gain:g})")
        lines.append("  stopj(2.0)")
    else:
        idx = np.unique(np.searchsorted(traj.t, traj.via_times - 1e-9).clip(0, len(traj) - 1))
        if idx.size == 0:
            idx = np.array([0, len(traj) - 1])
        for k, i in enumerate(idx):
            r = blend_radius if 0 < k < len(idx) - 1 else 0.0
            lines.append(f"  movej({fmt(q[i])}, a={acceleration:g}, v={speed:g}, "
                         f"r={r:g})")
    lines.append("end")
    return "\n".join(lines) + "\n"


def write_ur_script(traj: Trajectory, path: str | Path, *, overwrite: bool = False,
                    **options: Any) -> Path:
    """Write :func:`ur_script` to a file (``.script``).

    Raises:
        InputError: the file exists and ``overwrite`` is False.
    """
    return write_atomic(path, ur_script(traj, **options), overwrite=overwrite)

