"""Denavit-Hartenberg tables and elementary Rot/Trans sequences -> canonical chain.

A DH row is a dict ``{"a", "alpha", "d", "theta", "joint", "limits", "sign",
"name"}`` in SI units (metres, radians). For a revolute joint ``theta`` is its zero
offset; for a prismatic joint ``d`` is. A ``"fixed"`` row is a virtual frame: a
constant transform with no joint.

* standard: ``T_i = Rz(theta) Tz(d) Tx(a) Rx(alpha)``; the link frame i sits at the
  end of the row.
* modified (Craig): ``T_i = Rx(alpha) Tx(a) Rz(theta) Tz(d)`` with ``alpha, a`` of the
  previous link; the link frame i sits on joint axis i.

Rows may be dependent: ``"depends": {"other": coefficient, ...}`` and
``"depends_offset"`` make the chain value an affine function of independent
coordinates (a parallelogram's passive joint, a mimic joint). See ``docs/conventions.md``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any, Literal

import numpy as np

from robokin._text import short_repr
from robokin.exceptions import ModelError
from robokin.model.chain import Chain, ChainBuilder, Joint, JointKind
from robokin.model.coupling import AffineMap
from robokin.spatial import rotx, roty, rotz, trans

__all__ = ["chain_from_dh", "chain_from_elementary", "Convention"]

Convention = Literal["standard", "modified"]

#: The joint fields a DH row and an elementary operation share.
_JOINT_KEYS = {"joint", "limits", "sign", "name", "depends", "depends_offset"}
_DH_KEYS = {"a", "alpha", "d", "theta"} | _JOINT_KEYS
_ELEM_KEYS = {"op", "value"} | _JOINT_KEYS
_OPS = {"rx", "ry", "rz", "tx", "ty", "tz", "frame"}


def _num(row: Mapping[str, Any], key: str, where: str, default: float | None = 0.0) -> float:
    if key not in row or row[key] is None:
        if default is None:
            raise ModelError(f"missing required field '{key}'", field=where)
        return default
    v = row[key]
    if isinstance(v, bool) or not isinstance(v, (int, float, np.floating, np.integer)):
        raise ModelError(f"'{key}' must be a number, got {short_repr(v)}", field=f"{where}.{key}")
    v = float(v)
    if not math.isfinite(v):
        raise ModelError(f"'{key}' must be finite, got {v}", field=f"{where}.{key}")
    return v


def _limits(row: Mapping[str, Any], where: str) -> tuple[float, float]:
    lim = row.get("limits")
    if lim is None:
        return (-math.inf, math.inf)
    if not isinstance(lim, (list, tuple, np.ndarray)) or len(lim) != 2:
        raise ModelError(
            f"limits must be [lower, upper], got {short_repr(lim)}", field=f"{where}.limits"
        )
    if any(isinstance(v, bool) or not isinstance(v, (int, float, np.floating,
                                                      np.integer)) for v in lim):
        raise ModelError(
            f"limits must be numbers, got {short_repr(lim)}", field=f"{where}.limits"
        )
    lo, hi = float(lim[0]), float(lim[1])
    if math.isnan(lo) or math.isnan(hi):
        raise ModelError("limits must not be NaN", field=f"{where}.limits")
    if lo > hi:
        raise ModelError(
            f"limits reversed: lower {lo} > upper {hi}", field=f"{where}.limits"
        )
    return (lo, hi)


def _kind(
    row: Mapping[str, Any], where: str, default: str = "revolute"
) -> JointKind | Literal["fixed"]:
    kind = row.get("joint", default)
    if kind == "revolute":
        return "revolute"
    if kind == "prismatic":
        return "prismatic"
    if kind == "fixed":
        return "fixed"
    raise ModelError(
        f"joint must be 'revolute', 'prismatic' or 'fixed', got {short_repr(kind)}",
        field=f"{where}.joint",
    )


def _sign(row: Mapping[str, Any], where: str) -> float:
    s = row.get("sign", 1)
    if s not in (1, -1, 1.0, -1.0) or isinstance(s, bool):
        raise ModelError(f"sign must be +1 or -1, got {short_repr(s)}", field=f"{where}.sign")
    return float(s)


def _check_row(row: Any, where: str, keys: set[str]) -> Mapping[str, Any]:
    if not isinstance(row, Mapping):
        raise ModelError(
            f"a row must be a mapping of fields, got {type(row).__name__}", field=where
        )
    unknown = set(row) - keys
    if unknown:
        raise ModelError(
            f"unknown field(s) {sorted(unknown)}; allowed: {sorted(keys)}", field=where
        )
    return row


class _Assembler:
    """Collects joints and their dependencies while a builder lays out the chain."""

    def __init__(self, coordinates: Sequence[Mapping[str, Any]] | None, prefix: str) -> None:
        self.builder = ChainBuilder()
        self.prefix = prefix
        self.rows: list[tuple[Joint, Mapping[str, Any] | None, float, str]] = []
        self.explicit = None
        if coordinates is not None:
            self.explicit = []
            for i, c in enumerate(coordinates):
                where = f"coordinates[{i}]"
                c = _check_row(c, where, {"name", "joint", "limits"})
                if "name" not in c:
                    raise ModelError("missing required field 'name'", field=where)
                kind = _kind(c, where)
                if kind == "fixed":
                    raise ModelError(
                        "a coordinate cannot be 'fixed'", field=f"{where}.joint"
                    )
                self.explicit.append(Joint(str(c["name"]), kind, _limits(c, where)))

    def add_joint(
        self, row: Mapping[str, Any], kind: JointKind, offset: float, where: str,
        index: int,
    ) -> None:
        name = str(row.get("name", f"joint{len(self.rows) + 1}"))
        depends = row.get("depends")
        if depends is not None and not isinstance(depends, Mapping):
            raise ModelError(
                "depends must map coordinate names to coefficients",
                field=f"{where}.depends",
            )
        joint = Joint(name, kind, _limits(row, where), _sign(row, where), offset)
        dep_offset = _num(row, "depends_offset", where) if depends is not None else 0.0
        self.rows.append((joint, depends, dep_offset, where))
        self.builder.joint(joint)

    def build(self, base: np.ndarray | None, tool: np.ndarray | None) -> Chain:
        joints = [r[0] for r in self.rows]
        if self.explicit is None:
            coords = [j for j, dep, _, _ in self.rows if dep is None]
        else:
            coords = list(self.explicit)
        index = {c.name: i for i, c in enumerate(coords)}
        if len(index) != len(coords):
            raise ModelError("coordinate names must be unique", field="coordinates")
        M = np.zeros((len(joints), len(coords)))
        c = np.zeros(len(joints))
        for k, (joint, dep, dep_off, where) in enumerate(self.rows):
            if dep is None:
                if joint.name not in index:
                    raise ModelError(
                        f"joint '{joint.name}' is neither a declared coordinate nor "
                        f"dependent; coordinates: {sorted(index)}",
                        field=where,
                    )
                M[k, index[joint.name]] = 1.0
                continue
            for other, coeff in dep.items():
                if other not in index:
                    raise ModelError(
                        f"depends on unknown coordinate '{other}'; known: {sorted(index)}",
                        field=f"{where}.depends",
                    )
                if isinstance(coeff, bool) or not isinstance(coeff, (int, float)):
                    raise ModelError(
                        f"coefficient of '{other}' must be a number",
                        field=f"{where}.depends.{other}",
                    )
                M[k, index[other]] = float(coeff)
            c[k] = dep_off
        coupling = None
        if self.explicit is not None or any(r[1] is not None for r in self.rows):
            coupling = AffineMap(M, c)
            coordinates = tuple(coords)
        else:
            coordinates = None
        return self.builder.build(
            base=base, tool=tool, coordinates=coordinates, coupling=coupling
        )


def chain_from_dh(
    rows: Sequence[Mapping[str, Any]],
    convention: Convention = "standard",
    *,
    base: np.ndarray | None = None,
    tool: np.ndarray | None = None,
    coordinates: Sequence[Mapping[str, Any]] | None = None,
) -> Chain:
    """Compile a DH table (SI units) to the canonical chain.

    Args:
        rows: DH rows (see the module docstring), one per joint or virtual frame.
        convention: ``"standard"`` or ``"modified"``.
        base: Base transform (4, 4), default identity.
        tool: Tool transform (4, 4), default identity.
        coordinates: Optional explicit independent coordinates
            ``[{"name", "joint", "limits"}]`` when rows are dependent on coordinates
            that are not themselves chain joints.

    Returns:
        The canonical :class:`~robokin.model.chain.Chain`.

    Raises:
        ModelError: naming ``rows[i].field`` and the reason.
    """
    if convention not in ("standard", "modified"):
        raise ModelError(
            f"convention must be 'standard' or 'modified', got {short_repr(convention)}",
            field="convention",
        )
    if isinstance(rows, (str, bytes)) or not isinstance(rows, Sequence):
        raise ModelError("rows must be a list of DH rows", field="rows")
    asm = _Assembler(coordinates, "rows")
    b = asm.builder
    for i, row in enumerate(rows):
        where = f"rows[{i}]"
        row = _check_row(row, where, _DH_KEYS)
        a = _num(row, "a", where)
        alpha = _num(row, "alpha", where)
        d = _num(row, "d", where)
        theta = _num(row, "theta", where)
        kind = _kind(row, where)
        if convention == "standard":
            if kind == "fixed":
                b.constant(rotz(theta) @ trans(0, 0, d) @ trans(a, 0, 0) @ rotx(alpha))
                continue
            if kind == "revolute":
                asm.add_joint(row, kind, theta, where, i)
                b.constant(trans(0, 0, d))
            else:
                b.constant(rotz(theta))
                asm.add_joint(row, kind, d, where, i)
            b.constant(trans(a, 0, 0) @ rotx(alpha)).frame()
        else:
            pre = rotx(alpha) @ trans(a, 0, 0)
            if kind == "fixed":
                b.constant(pre @ rotz(theta) @ trans(0, 0, d))
                continue
            if kind == "revolute":
                b.constant(pre)
                asm.add_joint(row, kind, theta, where, i)
                b.constant(trans(0, 0, d)).frame()
            else:
                b.constant(pre @ rotz(theta))
                asm.add_joint(row, kind, d, where, i)
                b.frame()
    return asm.build(base, tool)


# A rotation that takes the local z axis onto x or y, for joints about other axes.
_TO_AXIS = {"x": roty(math.pi / 2), "y": rotx(-math.pi / 2), "z": np.eye(4)}


def chain_from_elementary(
    ops: Sequence[Mapping[str, Any]],
    *,
    base: np.ndarray | None = None,
    tool: np.ndarray | None = None,
    coordinates: Sequence[Mapping[str, Any]] | None = None,
) -> Chain:
    """Compile a sequence of elementary Rot/Trans operators (SI units) to a chain.

    Each op is ``{"op": "rx"|"ry"|"rz"|"tx"|"ty"|"tz", "value": v}`` for a constant,
    or ``{"op": ..., "joint": "revolute"|"prismatic", "name", "limits", "sign",
    "value"}`` for a joint (``value`` is then its zero offset). Rotations are about
    the current (moving) axes. A joint's link frame is the frame right after it,
    unless a ``{"op": "frame"}`` marker before the next joint places it there.

    Raises:
        ModelError: naming ``ops[i].field`` and the reason.
    """
    if isinstance(ops, (str, bytes)) or not isinstance(ops, Sequence):
        raise ModelError(
            "the elementary sequence must be a list of operations", field="ops"
        )
    asm = _Assembler(coordinates, "ops")
    b = asm.builder
    # Joints followed by an explicit frame marker get their link frame there.
    explicit_frame: set[int] = set()
    last_joint = None
    for i, op in enumerate(ops):
        if isinstance(op, Mapping) and op.get("joint", "fixed") != "fixed":
            last_joint = i
        elif (
            isinstance(op, Mapping)
            and op.get("op") == "frame"
            and last_joint is not None
        ):
            explicit_frame.add(last_joint)
    for i, op in enumerate(ops):
        where = f"joints[{i}]"
        op = _check_row(op, where, _ELEM_KEYS)
        name = op.get("op")
        if name not in _OPS:
            raise ModelError(
                f"op must be one of {sorted(_OPS)}, got {short_repr(name)}", field=f"{where}.op"
            )
        if name == "frame":
            b.frame()
            continue
        value = _num(op, "value", where)
        axis = name[1]
        is_rot = name[0] == "r"
        kind = _kind(op, where, default="fixed")
        if kind == "fixed":
            if is_rot:
                b.constant({"x": rotx, "y": roty, "z": rotz}[axis](value))
            else:
                v = [0.0, 0.0, 0.0]
                v["xyz".index(axis)] = value
                b.constant(trans(*v))
            continue
        if (kind == "revolute") != is_rot:
            raise ModelError(
                f"a {kind} joint needs a {'rotation' if kind == 'revolute' else 'translation'}"
                f" op, got {short_repr(name)}",
                field=f"{where}.op",
            )
        A = _TO_AXIS[axis]
        b.constant(A)
        asm.add_joint(op, kind, value, where, i)
        b.constant(A.T.copy())
        if i not in explicit_frame:
            b.frame()
    return asm.build(base, tool)
