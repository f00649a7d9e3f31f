"""The links a URDF hangs on robokin's chain: fixed attachments and the tool's tree.

Used by :mod:`robokin.io.urdf` once the chain is compiled. Every URDF link that
moves rigidly with a chain link is placed in that link's ``fk_all`` frame:

* links hung by **fixed** joints anywhere on the chain move with their link (a
  camera on link 3 stays on link 3);
* below the last movable joint's child link, the **tool's tree**: every link
  rigidly attached below it (the flange, the tip, a gripper's body) and every
  subtree hanging from those through joints that are not on the chain (a
  gripper's fingers), those joints **frozen** at their default positions: 0
  clamped into their limits, a mimic joint at ``multiplier * master + offset``,
  a floating or planar joint at its origin; ``tool_joints={name: value}``
  chooses others.

Ownership (:func:`link_owners`): a link on the base side belongs to ``base``, a
link moving with chain joint k to that joint's name, the last movable joint's
child link to the last joint, and every other link of the tool's tree to
``tool`` (robokin's tool link, adjacent only to the last link).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from robokin._text import short_repr
from robokin.exceptions import InputError, ModelError
from robokin.io.urdf_xml import MOVABLE

__all__ = ["axis_frame", "default_position", "freeze_tool_tree", "joint_motion", "link_owners",
           "resolve_mimic"]


# Exact rotations that take the local z axis onto +x / +y (no cos(pi/2) residue).
_Z_TO_X = np.array([[0.0, 0, 1, 0], [0, 1, 0, 0], [-1, 0, 0, 0], [0, 0, 0, 1]])
_Z_TO_Y = np.array([[1.0, 0, 0, 0], [0, 0, 1, 0], [0, -1, 0, 0], [0, 0, 0, 1]])


def _origin(j: Any) -> np.ndarray:
    return np.eye(4) if j.origin is None else np.asarray(j.origin, dtype=np.float64)


def resolve_mimic(joints: Mapping[str, Any], j: Any, file: Any) -> tuple[Any, float, float]:
    """The independent master of a mimic joint, with the composed multiplier/offset.

    Args:
        joints: Every URDF joint by name.
        j: A joint with a ``<mimic>``.
        file: The URDF, for messages.

    Raises:
        ModelError: a mimic of an unknown or fixed joint, or a loop of mimics.
    """
    mult, off, seen = 1.0, 0.0, {j.name}
    cur = j
    while cur.mimic is not None:
        name = cur.mimic.joint
        master = joints.get(name)
        where = f"joint[{cur.name}].mimic"
        if master is None:
            raise ModelError(f"mimics unknown joint '{name}'", file=file, field=where)
        if master.type not in MOVABLE:
            raise ModelError(f"mimics the {master.type} joint '{name}'", file=file,
                             field=where)
        if name in seen:
            raise ModelError("mimic joints form a loop", file=file, field=where)
        seen.add(name)
        m = 1.0 if cur.mimic.multiplier is None else float(cur.mimic.multiplier)
        o = 0.0 if cur.mimic.offset is None else float(cur.mimic.offset)
        mult, off = mult * m, mult * o + off
        cur = master
    return cur, mult, off


def _bounds(j: Any) -> tuple[float, float]:
    """A joint's position limits (continuous, floating, planar: unbounded)."""
    if j.type in ("revolute", "prismatic") and j.limit is not None:
        lo = -math.inf if j.limit.lower is None else float(j.limit.lower)
        hi = math.inf if j.limit.upper is None else float(j.limit.upper)
        return lo, hi
    return -math.inf, math.inf


def default_position(j: Any) -> float:
    """0 clamped into the joint's limits (MoveIt's default for a single-DOF joint)."""
    lo, hi = _bounds(j)
    return float(min(max(0.0, lo), hi))


def joint_motion(j: Any, value: float) -> np.ndarray:
    """The joint's transform parent -> child (4, 4) at ``value`` [rad, m].

    Revolute and continuous joints rotate about their axis, prismatic ones slide
    along it; fixed, floating and planar joints sit at their origin.
    """
    T = _origin(j)
    if j.type not in MOVABLE or value == 0.0:
        return T
    A, sign = axis_frame(j.axis, where=f"joint[{j.name}].axis")
    M = np.eye(4)
    v = sign * value
    if j.type == "prismatic":
        M[2, 3] = v
    else:
        c, s = math.cos(v), math.sin(v)
        M[:2, :2] = [[c, -s], [s, c]]
    return T @ A @ M @ A.T


def axis_frame(axis: Sequence[float], *, where: str = "axis") -> tuple[np.ndarray, float]:
    """A rotation ``A`` (4, 4) and sign with ``A @ Rz(sign q) @ A.T`` = rotation about ``axis``.

    Axis-aligned axes give exact matrices; a negative axis (``-x``, ``-y``, ``-z``,
    or any axis with a negative z component) gives ``sign = -1``.

    Raises:
        ModelError: a zero or non-finite axis.
    """
    u = np.asarray(axis, dtype=np.float64).reshape(-1)
    norm = float(np.linalg.norm(u)) if u.shape == (3,) else 0.0
    if u.shape != (3,) or not np.isfinite(u).all() or norm < 1e-12:
        raise ModelError(f"the joint axis must be a non-zero 3-vector, got {u.tolist()}",
                         field=where)
    u = u / norm
    nz = np.flatnonzero(np.abs(u) > 1e-15)
    if len(nz) == 1:
        i = int(nz[0])
        sign = 1.0 if u[i] > 0 else -1.0
        return ((_Z_TO_X, _Z_TO_Y, np.eye(4))[i]).copy(), sign
    sign = 1.0
    if u[2] < 0:
        u, sign = -u, -1.0
    # Minimal rotation taking z onto u (Rodrigues, 1 + cos >= 1 here).
    v = np.array([-u[1], u[0], 0.0])
    c = u[2]
    K = np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])
    A = np.eye(4)
    A[:3, :3] = np.eye(3) + K + K @ K / (1.0 + c)
    return A, sign


def _subtree_joints(tree: Any, roots: Sequence[str], placed: set[str]) -> list[Any]:
    """Joints below ``roots`` leading to links not yet placed, parents first."""
    out, stack = [], list(roots)
    while stack:
        link = stack.pop()
        for j in tree.children[link]:
            if j.child in placed:
                continue
            out.append(j)
            stack.append(j.child)
    return out


def _check_values(values: Mapping[str, float], frozen: Mapping[str, Any],
                  file: Any) -> dict[str, float]:
    """``tool_joints`` checked: known, independent, finite, inside the limits."""
    out = {}
    names = sorted(n for n, j in frozen.items() if j.mimic is None)
    for name, value in values.items():
        j = frozen.get(name)
        if j is None:
            shown = ", ".join(names) if names else "none"
            raise InputError("tool_joints", f"{short_repr(name)} is not a joint "
                             f"below the tip; the tool's joints: {shown}")
        if j.mimic is not None:
            raise InputError("tool_joints", f"'{name}' mimics '{j.mimic.joint}': "
                             "give the joint it mimics")
        try:
            v = float(value)
        except (TypeError, ValueError):
            v = math.nan
        lo, hi = _bounds(j)
        if not math.isfinite(v) or not lo - 1e-12 <= v <= hi + 1e-12:
            raise InputError("tool_joints", f"'{name}' = {short_repr(value)}: expected "
                             f"a finite number in its limits [{lo:g}, {hi:g}] "
                             f"({file or 'URDF'})")
        out[name] = v
    return out


def freeze_tool_tree(
    tree: Any,
    frames: dict[str, tuple[int, np.ndarray]],
    n_chain: int,
    chain_joints: set[str],
    values: Mapping[str, float] | None,
    file: Any,
) -> tuple[dict[str, float], list[str]]:
    """Place the tool's tree: the subtrees below links rigid with the last link.

    ``frames`` (URDF link -> ``(k, T)`` in ``fk_all`` frame k) already holds the
    chain's links and everything hung by fixed joints; this adds the links
    below joints that are not on the chain and hang from a link of frame
    ``n_chain`` (in place).

    Args:
        tree: The URDF tree (``robokin.io.urdf._Tree``).
        frames: Placed links, updated in place.
        n_chain: The number of chain joints (the last link's frame index).
        chain_joints: Names of the chain's joints and coordinates: a joint below
            the tip that mimics one of them moves with the arm and cannot be
            frozen (its subtree is left out, with a warning).
        values: ``tool_joints`` given by the caller (None: defaults).
        file: The URDF, for messages.

    Returns:
        The position of every frozen joint (mimic joints included), and a
        message per subtree left out.

    Raises:
        InputError: a bad ``tool_joints`` entry (naming the joint).
    """
    roots = [link for link, (k, _) in frames.items() if k == n_chain]
    joints = _subtree_joints(tree, roots, set(frames))
    frozen = {j.name: j for j in joints if j.type != "fixed"}
    given = _check_values(values or {}, frozen, file)
    positions: dict[str, float] = {}
    dropped: list[str] = []
    skip: set[str] = set()  # links below a joint that cannot be frozen
    for j in joints:  # parents first
        if j.parent in skip:
            skip.add(j.child)
            continue
        value = 0.0
        if j.type != "fixed":
            if j.mimic is not None:
                master, mult, off = resolve_mimic(tree.joints, j, file)
                if master.name in chain_joints:
                    dropped.append(f"links below joint '{j.name}' (it mimics the arm's "
                                   f"joint '{master.name}')")
                    skip.add(j.child)
                    continue
                base = given.get(master.name, default_position(master))
                value = mult * base + off
            elif j.name in chain_joints:
                dropped.append(f"links below joint '{j.name}' (a coordinate of the arm)")
                skip.add(j.child)
                continue
            else:
                value = given.get(j.name, default_position(j))
            positions[j.name] = value
        try:
            motion = joint_motion(j, value)
        except ModelError as exc:
            raise ModelError(exc.reason, file=file, field=exc.field) from None
        k, T = frames[j.parent]
        frames[j.child] = (k, T @ motion)
    return positions, dropped


def link_owners(frames: Mapping[str, tuple[int, np.ndarray]],
                joint_names: Sequence[str], last_child: str) -> dict[str, str]:
    """The robokin link (``base``, a chain joint's name, ``tool``) of each placed link.

    Args:
        frames: URDF link -> ``(k, T)`` (every placed link).
        joint_names: The chain joints' names (link k moves with joint k).
        last_child: The last movable joint's child link (robokin's last link).
    """
    n = len(joint_names)
    out = {}
    for link, (k, _) in frames.items():
        if k == 0:
            out[link] = "base"
        elif k == n and link != last_child:
            out[link] = "tool"
        else:
            out[link] = joint_names[k - 1]
    return out
