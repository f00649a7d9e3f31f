"""Controller profiles: how a controller's joint values relate to the model's.

A :class:`ControllerProfile` gives the joint order, signs, zero offsets, units and
names a real controller expects; :mod:`robokin.trajectory.io` applies it when
writing and undoes it when reading. :func:`load_profile` reads one from YAML/JSON.
"""

from __future__ import annotations

import copy
import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from types import MappingProxyType
from typing import Any, Literal, TypeVar

import numpy as np

from robokin._text import short_repr
from robokin._units import ANGLE_UNITS, LENGTH_UNITS
from robokin.exceptions import InputError, ModelError
from robokin.spatial import pose_from_xyz_rpy

__all__ = ["PROGRAMS", "ControllerProfile", "load_profile"]

_T = TypeVar("_T")

#: Programs a controller profile may name (robokin.trajectory.controllers).
PROGRAMS = ("urscript", "ros2", "waypoints")


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
        programs: What the controller runs, its default first: ``"urscript"``,
            ``"ros2"``, ``"waypoints"`` (:mod:`robokin.trajectory.controllers`);
            None: any but URScript, a waypoint file by default.
        root: The controller's robot root frame (KUKA ``$ROBROOT``, ABB's base
            frame: z up along axis 1, x where the arm reaches at axis 1's zero) in
            the model's base frame: ``(x, y, z, roll, pitch, yaw)`` [m, rad]
            (None: the model's base frame). Used by the post processors
            (:mod:`robokin.trajectory.posts`) for frames and configuration flags.
        flange: The controller's flange frame in the model's last link frame, the
            same six numbers (None: the model's last link frame); tool data are
            written relative to it.
        posts: Options per post processor dialect, ``{dialect: {option: value}}``
            (checked by :func:`robokin.trajectory.posts.write_program`).
    """

    name: str = "default"
    order: tuple[int, ...] | None = None
    signs: tuple[float, ...] | None = None
    offsets: tuple[float, ...] | None = None
    angle_unit: Literal["rad", "deg"] = "rad"
    length_unit: Literal["m", "mm"] = "m"
    names: tuple[str, ...] | None = None
    programs: tuple[str, ...] | None = None
    root: tuple[float, ...] | None = None
    flange: tuple[float, ...] | None = None
    posts: Mapping[str, Mapping[str, Any]] | None = None

    def __post_init__(self) -> None:
        """Check the units and the per-column lists; store them as tuples."""
        if self.angle_unit not in ANGLE_UNITS:
            raise ModelError(f"angle_unit must be 'rad' or 'deg', got {short_repr(self.angle_unit)}",
                             field="angle_unit")
        if self.length_unit not in LENGTH_UNITS:
            raise ModelError(f"length_unit must be 'm' or 'mm', got {short_repr(self.length_unit)}",
                             field="length_unit")
        if self.signs is not None and any(s not in (1, -1) for s in self.signs):
            raise ModelError(f"signs must be +1 or -1, got {list(self.signs)}",
                             field="signs")
        bad = [p for p in self.programs or () if p not in PROGRAMS]
        if bad or (self.programs is not None and not self.programs):
            raise ModelError(f"programs must be a non-empty list of {list(PROGRAMS)}, "
                             f"got {short_repr(self.programs)}", field="programs")
        for f in ("order", "signs", "offsets", "names", "programs", "root", "flange"):
            v = getattr(self, f)
            if v is not None:
                object.__setattr__(self, f, tuple(v))
        for f in ("root", "flange"):
            v = getattr(self, f)
            if v is not None and (len(v) != 6 or not all(
                    isinstance(x, (int, float)) and not isinstance(x, bool)
                    and math.isfinite(x) for x in v)):
                raise ModelError(f"expected six finite numbers (x, y, z, roll, pitch, "
                                 f"yaw), got {short_repr(v)}", field=f)
        if self.posts is not None:
            if not isinstance(self.posts, Mapping) or not all(
                    isinstance(k, str) and isinstance(v, Mapping)
                    for k, v in self.posts.items()):
                raise ModelError("expected a mapping {dialect: {option: value}}, got "
                                 f"{short_repr(self.posts)}", field="posts")
            object.__setattr__(self, "posts", MappingProxyType(
                {k: MappingProxyType(copy.deepcopy(dict(v)))
                 for k, v in self.posts.items()}))

    def frame(self, which: Literal["root", "flange"]) -> np.ndarray:
        """``root`` or ``flange`` as a (4, 4) transform [m] (identity when not set)."""
        v = getattr(self, which)
        if v is None:
            return np.eye(4)
        return pose_from_xyz_rpy(v[:3], v[3:])

    @classmethod
    def from_dict(cls, doc: Mapping[str, Any], *, file: Any = None) -> ControllerProfile:
        """Build from a mapping (a YAML/JSON document).

        Keys: ``name``, ``order`` (indices or joint names, with ``joints`` giving the
        model's names), ``signs``, ``offsets`` (in ``offset_unit``, default the
        profile's units), ``angle_unit``, ``length_unit``, ``names``, ``programs``.
        """
        doc = dict(doc)
        known = {"name", "order", "signs", "offsets", "offset_unit", "angle_unit",
                 "length_unit", "names", "joints", "programs", "root", "flange", "posts"}
        extra = sorted(set(doc) - known)
        if extra:
            raise ModelError(f"unknown key(s) {extra}; known: {sorted(known)}",
                             file=file, field=extra[0])
        order = _list_field(doc, "order", (int, str), file)
        signs = _list_field(doc, "signs", (int, float), file)
        offsets = _list_field(doc, "offsets", (int, float), file)
        names = _list_field(doc, "names", (str,), file)
        programs = _list_field(doc, "programs", (str,), file)
        for key in ("name", "angle_unit", "length_unit", "offset_unit"):
            if key in doc and not isinstance(doc[key], str):
                raise ModelError(f"expected text, got {short_repr(doc[key])}",
                                 file=file, field=key)
        if order is not None and any(isinstance(o, str) for o in order):
            joints = _list_field(doc, "joints", (str,), file)
            if not joints:
                raise ModelError("order by name needs 'joints' (the model's names)",
                                 file=file, field="order")
            try:
                order = [list(joints).index(o) if isinstance(o, str) else int(o)
                         for o in order]
            except ValueError as exc:
                raise ModelError(f"{exc}; joints: {list(joints)}", file=file,
                                 field="order") from None
        if offsets is not None and doc.get("offset_unit", doc.get("angle_unit")) == "deg":
            offsets = [math.radians(o) for o in offsets]
        root = _frame_field(doc, "root", file)
        flange = _frame_field(doc, "flange", file)
        try:
            return cls(name=doc.get("name", "default"), order=_tuple(order),
                       signs=_tuple(signs), offsets=_tuple(offsets),
                       angle_unit=doc.get("angle_unit", "rad"),
                       length_unit=doc.get("length_unit", "m"), names=_tuple(names),
                       programs=_tuple(programs), root=root, flange=flange,
                       posts=doc.get("posts"))
        except ModelError as exc:
            raise ModelError(exc.reason, file=file, field=exc.field) from None

    def parts(self, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The model joint per controller column, the signs and the offsets (n,) each.

        Raises:
            InputError: the order is not a permutation of ``n`` joints, or the
                signs / offsets do not have ``n`` entries.
        """
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
        order, signs, offs = self.parts(q.shape[-1])
        c = q[..., order] * signs
        return c if rates else c + offs

    def undo(self, c: np.ndarray, *, rates: bool = False) -> np.ndarray:
        """Controller columns (m, n) SI -> model values (m, n) SI."""
        order, signs, offs = self.parts(c.shape[-1])
        v = (c if rates else c - offs) * signs
        out = np.empty_like(v)
        out[..., order] = v
        return out

    def column_names(self, model_names: Sequence[str]) -> list[str]:
        """Controller column names (the model's, reordered, unless ``names``)."""
        if self.names is not None:
            return list(self.names)
        order, _, _ = self.parts(len(model_names))
        return [model_names[k] for k in order]

    def column_revolute(self, is_revolute: np.ndarray) -> np.ndarray:
        """Revolute flags in controller order."""
        order, _, _ = self.parts(len(is_revolute))
        return np.asarray(is_revolute, bool)[order]


def _list_field(doc: Mapping[str, Any], key: str, kinds: tuple[type, ...],
                file: Any) -> list[Any] | None:
    """``doc[key]``: None, or a list whose items are of ``kinds``.

    No booleans, finite numbers; a ModelError naming the field otherwise.
    """
    value = doc.get(key)
    if value is None:
        return None

    def ok(v: Any) -> bool:
        if isinstance(v, bool) or not isinstance(v, kinds):
            return False
        return not isinstance(v, float) or math.isfinite(v)

    if not isinstance(value, (list, tuple)) or not all(ok(v) for v in value):
        what = " or ".join(k.__name__ for k in kinds)
        raise ModelError(f"expected a list of {what}, got {short_repr(value)}",
                         file=file, field=key)
    return list(value)


def _frame_field(doc: Mapping[str, Any], key: str, file: Any
                 ) -> tuple[float, ...] | None:
    """``doc[key]`` = ``{xyz_mm: [x, y, z], rpy_deg: [r, p, y]}`` as six SI numbers."""
    value = doc.get(key)
    if value is None:
        return None
    if not isinstance(value, Mapping) or set(value) - {"xyz_mm", "rpy_deg"}:
        raise ModelError("expected {xyz_mm: [x, y, z], rpy_deg: [roll, pitch, yaw]}, "
                         f"got {short_repr(value)}", file=file, field=key)
    xyz = _list_field(value, "xyz_mm", (int, float), file) or [0.0, 0.0, 0.0]
    rpy = _list_field(value, "rpy_deg", (int, float), file) or [0.0, 0.0, 0.0]
    if len(xyz) != 3 or len(rpy) != 3:
        raise ModelError("xyz_mm and rpy_deg need three numbers each", file=file,
                         field=key)
    return tuple([v / 1000.0 for v in xyz] + [math.radians(v) for v in rpy])


def load_profile(path: str | Path) -> ControllerProfile:
    """Read a controller profile from a YAML or JSON file.

    Raises:
        ModelError: missing file, bad syntax or bad fields (naming the file).
    """
    from robokin.io.yaml_reader import read_yaml_document

    path = Path(path)
    ydoc = read_yaml_document(path)  # JSON is YAML
    doc = ydoc.data
    if not isinstance(doc, Mapping):
        raise ModelError("expected a mapping at the top level", file=path)
    try:
        return ControllerProfile.from_dict(doc.get("controller", doc), file=path)
    except ModelError as exc:
        raise ydoc.locate(exc) from None


def _tuple(values: Iterable[_T] | None) -> tuple[_T, ...] | None:
    return None if values is None else tuple(values)
