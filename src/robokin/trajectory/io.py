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

Every writer writes a temporary file next to the target and renames it; an
existing file is replaced only with ``overwrite=True``.
"""

from __future__ import annotations

import json
import math
import os
import re
import tempfile
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

import numpy as np
import numpy.typing as npt

from robokin.exceptions import InputError, ModelError
from robokin.trajectory.samples import Trajectory

__all__ = [
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

_ANGLE = {"rad": 1.0, "deg": math.pi / 180.0}
_LENGTH = {"m": 1.0, "mm": 1e-3}
_TIME = {"s": 1.0, "ms": 1e-3}
_HEADER = re.compile(r"^\s*(?P<name>.*?)\s*(?:\[(?P<unit>[^\]]*)\])?\s*$")


# ------------------------------------------------------------------ atomic writes
def file_mode() -> int:
    """Permissions of a new file under the current umask (mkstemp makes 0600)."""
    mask = os.umask(0)
    os.umask(mask)
    return 0o666 & ~mask


def write_text_atomic(path: str | Path, text: str, *, overwrite: bool = False) -> Path:
    """Write ``text`` to ``path`` through a temporary file and a rename.

    Raises:
        InputError: ``path`` exists and ``overwrite`` is False, or its folder
            does not exist.
    """
    path = Path(path)
    if path.exists() and not overwrite:
        raise InputError("path", f"{path} exists; pass overwrite=True to replace it")
    folder = path.parent if str(path.parent) else Path(".")
    if not folder.is_dir():
        raise InputError("path", f"folder {folder} does not exist")
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=folder)
    try:
        with os.fdopen(fd, "w", encoding="utf-8", newline="") as fh:
            fh.write(text)
        os.chmod(tmp, file_mode())
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise
    return path


# ------------------------------------------------------------- controller profile
@dataclass(frozen=True)
class ControllerProfile:
    """How a controller's joint values relate to the model's.

    For controller column ``k`` holding model joint ``j = order[k]``:
    ``c_k = sign_k * q_j + offset_k`` in SI units, then written in the profile's
    units (``angle_unit`` for revolute joints, ``length_unit`` for prismatic).

    Attributes:
        name: A label (e.g. the controller's name).
        order: Model joint index per controller column (default: same order).
        signs: +1 or -1 per controller column.
        offsets: Controller value at the model's zero, per column [rad or m].
        angle_unit: ``"rad"`` or ``"deg"``.
        length_unit: ``"m"`` or ``"mm"``.
        names: Column names for the controller (default: the model's names).
    """

    name: str = "default"
    order: tuple[int, ...] | None = None
    signs: tuple[float, ...] | None = None
    offsets: tuple[float, ...] | None = None
    angle_unit: Literal["rad", "deg"] = "rad"
    length_unit: Literal["m", "mm"] = "m"
    names: tuple[str, ...] | None = None

    def __post_init__(self) -> None:
        if self.angle_unit not in _ANGLE:
            raise ModelError(f"angle_unit must be 'rad' or 'deg', got {self.angle_unit!r}",
                             field="angle_unit")
        if self.length_unit not in _LENGTH:
            raise ModelError(f"length_unit must be 'm' or 'mm', got {self.length_unit!r}",
                             field="length_unit")
        if self.signs is not None and any(s not in (1, -1) for s in self.signs):
            raise ModelError(f"signs must be +1 or -1, got {list(self.signs)}",
                             field="signs")
        for f in ("order", "signs", "offsets", "names"):
            v = getattr(self, f)
            if v is not None:
                object.__setattr__(self, f, tuple(v))

    @classmethod
    def from_dict(cls, doc: Mapping[str, Any], *, file: Any = None) -> ControllerProfile:
        """Build from a mapping (a YAML/JSON document).

        Keys: ``name``, ``order`` (indices or joint names, with ``joints`` giving the
        model's names), ``signs``, ``offsets`` (in ``offset_unit``, default the
        profile's units), ``angle_unit``, ``length_unit``, ``names``.
        """
        doc = dict(doc)
        known = {"name", "order", "signs", "offsets", "offset_unit", "angle_unit",
                 "length_unit", "names", "joints"}
        extra = sorted(set(doc) - known)
        if extra:
            raise ModelError(f"unknown key(s) {extra}; known: {sorted(known)}",
                             file=file, field=extra[0])
        order = doc.get("order")
        if order is not None and any(isinstance(o, str) for o in order):
            joints = doc.get("joints")
            if not joints:
                raise ModelError("order by name needs 'joints' (the model's names)",
                                 file=file, field="order")
            try:
                order = [list(joints).index(o) if isinstance(o, str) else int(o)
                         for o in order]
            except ValueError as exc:
                raise ModelError(f"{exc}; joints: {list(joints)}", file=file,
                                 field="order") from None
        offsets = doc.get("offsets")
        if offsets is not None and doc.get("offset_unit", doc.get("angle_unit")) == "deg":
            offsets = [math.radians(o) for o in offsets]
        try:
            return cls(name=str(doc.get("name", "default")), order=order,
                       signs=doc.get("signs"), offsets=offsets,
                       angle_unit=doc.get("angle_unit", "rad"),
                       length_unit=doc.get("length_unit", "m"), names=doc.get("names"))
        except ModelError as exc:
            raise ModelError(exc.reason, file=file, field=exc.field) from None

    def _parts(self, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        order = np.arange(n) if self.order is None else np.asarray(self.order, int)
        if sorted(order.tolist()) != list(range(n)):
            raise InputError("profile", f"order {order.tolist()} is not a permutation "
                             f"of the {n} joints")
        signs = np.ones(n) if self.signs is None else np.asarray(self.signs, float)
        offs = np.zeros(n) if self.offsets is None else np.asarray(self.offsets, float)
        if signs.shape != (n,) or offs.shape != (n,):
            raise InputError("profile", f"signs and offsets need {n} entries each")
        return order, signs, offs

    def export(self, q: np.ndarray, *, rates: bool = False) -> np.ndarray:
        """Model values (m, n) SI -> controller columns (m, n) SI (units not applied)."""
        order, signs, offs = self._parts(q.shape[-1])
        c = q[..., order] * signs
        return c if rates else c + offs

    def undo(self, c: np.ndarray, *, rates: bool = False) -> np.ndarray:
        """Controller columns (m, n) SI -> model values (m, n) SI."""
        order, signs, offs = self._parts(c.shape[-1])
        v = (c if rates else c - offs) * signs
        out = np.empty_like(v)
        out[..., order] = v
        return out

    def column_names(self, model_names: Sequence[str]) -> list[str]:
        """Controller column names (the model's, reordered, unless ``names``)."""
        if self.names is not None:
            return list(self.names)
        order, _, _ = self._parts(len(model_names))
        return [model_names[k] for k in order]

    def column_revolute(self, is_revolute: np.ndarray) -> np.ndarray:
        """Revolute flags in controller order."""
        order, _, _ = self._parts(len(is_revolute))
        return np.asarray(is_revolute, bool)[order]


def load_profile(path: str | Path) -> ControllerProfile:
    """Read a controller profile from a YAML or JSON file.

    Raises:
        ModelError: missing file, bad syntax or bad fields (naming the file).
    """
    import yaml

    path = Path(path)
    try:
        doc = yaml.safe_load(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise ModelError("no such file", file=path) from None
    except yaml.YAMLError as exc:
        raise ModelError(f"not valid YAML: {exc}", file=path) from None
    if not isinstance(doc, Mapping):
        raise ModelError("expected a mapping at the top level", file=path)
    return ControllerProfile.from_dict(doc.get("controller", doc), file=path)


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
    return write_text_atomic(path, csv_text(traj, joint_names, rates=rates,
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
    unit = np.array([_ANGLE[profile.angle_unit] if r else _LENGTH[profile.length_unit]
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
            raise InputError("joint_names", f"a name may not hold a comma: {h!r}")
    fmt = "%r" if precision is None else f"%.{int(precision)}g"
    lines = [",".join(header)]
    lines += [",".join(fmt % v for v in row) for row in data.tolist()]
    return "\n".join(lines) + "\n"


def _parse_header(cols: list[str], file: Any) -> list[tuple[str, str | None]]:
    out = []
    for c in cols:
        m = _HEADER.match(c)
        out.append((m.group("name"), m.group("unit").strip() if m.group("unit") else None))
    return out


def _load_table(path: Path) -> tuple[list[str], np.ndarray]:
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise ModelError("no such file", file=path) from None
    lines = [ln for ln in text.splitlines() if ln.strip() and not ln.lstrip().startswith("#")]
    if not lines:
        raise ModelError("empty file", file=path)
    sep = ";" if lines[0].count(";") > lines[0].count(",") else ","
    header = [h.strip() for h in lines[0].split(sep)]
    rows = []
    for k, ln in enumerate(lines[1:], start=2):
        parts = ln.split(sep)
        if len(parts) != len(header):
            raise ModelError(f"line {k} has {len(parts)} values, the header "
                             f"{len(header)}", file=path, field=f"line {k}")
        try:
            rows.append([float(p) for p in parts])
        except ValueError:
            raise ModelError(f"line {k} holds a value that is not a number",
                             file=path, field=f"line {k}") from None
    if not rows:
        raise ModelError("no data rows", file=path)
    data = np.array(rows)
    if not np.isfinite(data).all():
        bad = int(np.argwhere(~np.isfinite(data))[0, 0]) + 2
        raise ModelError(f"line {bad} holds a non-finite value", file=path,
                         field=f"line {bad}")
    return header, data


def _differentiate(t: np.ndarray, x: np.ndarray) -> np.ndarray:
    if len(t) < 2:
        return np.zeros_like(x)
    return np.gradient(x, t, axis=0, edge_order=2 if len(t) > 2 else 1)


def read_csv(
    path: str | Path,
    *,
    profile: ControllerProfile | None = None,
    is_revolute: npt.ArrayLike | None = None,
) -> Trajectory:
    """Read a trajectory CSV (the :func:`write_csv` format, or a logged run).

    The first column is time; the others are joints, optionally followed by
    ``.vel`` and ``.acc`` columns. Units in brackets are converted to SI;
    a column without a unit is taken as SI. Velocities and accelerations missing
    from the file are differentiated from the positions.

    Args:
        path: The file.
        profile: The controller profile the file was written with (undone here).
        is_revolute: (n,) flags when the header has no units (default: angles).

    Returns:
        A :class:`~robokin.trajectory.samples.Trajectory` in model order and SI.

    Raises:
        ModelError: missing file, ragged or non-numeric rows, unknown units,
            times that do not increase (naming the file and line).
    """
    path = Path(path)
    header, data = _load_table(path)
    cols = _parse_header(header, path)
    tname, tunit = cols[0]
    if tunit is not None and tunit not in _TIME:
        raise ModelError(f"unknown time unit [{tunit}]; use [s] or [ms]", file=path,
                         field=header[0])
    t = data[:, 0] * _TIME.get(tunit or "s")
    pos, vel, acc = [], [], []
    for k, (name, unit) in enumerate(cols[1:], start=1):
        kind = pos
        if name.endswith(".vel"):
            kind, name = vel, name[:-4]
        elif name.endswith(".acc"):
            kind, name = acc, name[:-4]
        kind.append((name, unit, k))
    n = len(pos)
    if n == 0:
        raise ModelError("no joint columns after the time column", file=path)
    rev_given = None if is_revolute is None else np.asarray(is_revolute, bool).reshape(-1)
    if rev_given is not None and rev_given.shape != (n,):
        raise InputError("is_revolute", f"expected {n} flags, got {rev_given.shape}")

    def convert(group, rate: int) -> tuple[np.ndarray, np.ndarray]:
        out = np.empty((len(t), len(group)))
        rev = np.ones(len(group), bool)
        for i, (_name, unit, k) in enumerate(group):
            base = None if unit is None else unit.split("/")[0]
            if base is None:
                rev[i] = True if rev_given is None else rev_given[i]
                scale = 1.0
            elif base in _ANGLE:
                scale = _ANGLE[base]
            elif base in _LENGTH:
                rev[i], scale = False, _LENGTH[base]
            else:
                raise ModelError(f"unknown unit [{unit}] in column {header[k]!r}; "
                                 "use rad, deg, m or mm", file=path, field=header[k])
            out[:, i] = data[:, k] * scale
        return out, rev

    q, rev = convert(pos, 0)
    names = [p[0] for p in pos]
    if len(t) > 1 and not (np.diff(t) > 0).all():
        k = int(np.flatnonzero(np.diff(t) <= 0)[0]) + 3
        raise ModelError(f"time does not increase at line {k}", file=path,
                         field=f"line {k}")
    qd = convert(vel, 1)[0] if len(vel) == n else None
    qdd = convert(acc, 2)[0] if len(acc) == n else None
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
    return Trajectory(t, q, qd, qdd, joint_names=tuple(names), is_revolute=rev,
                      via_times=np.array([t[0], t[-1]]))


def read_log(
    path: str | Path,
    *,
    profile: ControllerProfile | None = None,
    is_revolute: npt.ArrayLike | None = None,
) -> Trajectory:
    """Read a logged real run (CSV of time + joint angles) as a Trajectory.

    Like :func:`read_csv`, but tolerant of what loggers write: repeated time
    stamps are dropped (the first is kept) and the start time is kept as logged.

    Raises:
        ModelError: as :func:`read_csv`.
    """
    path = Path(path)
    header, data = _load_table(path)
    t = data[:, 0]
    keep = np.concatenate([[True], np.diff(t) > 0])
    if not keep.all():
        order = np.argsort(t, kind="stable")
        data = data[order]
        t = data[:, 0]
        keep = np.concatenate([[True], np.diff(t) > 0])
        data = data[keep]
        fd, tmp = tempfile.mkstemp(suffix=".csv")
        try:
            with os.fdopen(fd, "w", encoding="utf-8") as fh:
                fh.write(",".join(header) + "\n")
                np.savetxt(fh, data, delimiter=",", fmt="%.17g")
            return read_csv(tmp, profile=profile, is_revolute=is_revolute)
        finally:
            os.unlink(tmp)
    return read_csv(path, profile=profile, is_revolute=is_revolute)


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
    return write_text_atomic(path, json.dumps(doc) + "\n", overwrite=overwrite)


def read_json(path: str | Path) -> Trajectory:
    """Read a trajectory written by :func:`write_json`.

    Raises:
        ModelError: missing file, not JSON, or missing / inconsistent fields.
    """
    path = Path(path)
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise ModelError("no such file", file=path) from None
    except json.JSONDecodeError as exc:
        raise ModelError(f"not valid JSON: {exc}", file=path) from None
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
        raise InputError("mode", f"expected 'servoj' or 'movej', got {mode!r}")
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
    return write_text_atomic(path, ur_script(traj, **options), overwrite=overwrite)

