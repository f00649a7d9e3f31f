r"""Denavit-Hartenberg tables derived from any robot's joint axes.

Given a robot (from a URDF, an elementary sequence, another DH table), find the
standard and modified DH tables of its joint axes, plus the base and tool
transforms that remain, so that

.. math::

    T(q) = B_{rem} \cdot \prod_i DH_i(q) \cdot T_{rem}.

A serial chain of 1-DOF joints always has such a table: each pair of successive
joint axes (lines in space) is related by their common normal. What a plain table
cannot carry is the base placement (frame 0 must have z along joint 1's axis) and
the tool (frame n must have z along joint n's axis); with ``virtual_frames=True``
those become fixed rows (virtual frames, one when a single DH row can express the
transform, else two), and the table alone reproduces the robot.

Choices where DH leaves freedom (documented in ``docs/urdf.md``):

* z_i points along the joint's positive direction, so every row has ``sign = +1``;
* frame 0: origin at the foot of the reference frame's origin on joint 1's axis,
  x0 the reference x axis projected onto the plane normal to z0 (the reference is
  ``robot.base`` unless given; :func:`robokin.io.urdf.dh_from_urdf` uses the
  ROS-Industrial ``base`` frame, the vendor's DH frame 0);
* x_i along the common normal, its sense the one closer to x_(i-1) (joint offsets
  ``theta`` stay within +-90 deg, zero where the arm allows — this reproduces
  published tables such as UR's, with their negative ``a``);
* parallel axes: the common normal through the previous origin (``d_i = 0``);
  intersecting axes: x_i = z_(i-1) x z_i (up to sense);
* frame n: on joint n's axis at the foot of the tool point, x_n the tool's x
  projected onto the plane normal to z_n.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
import numpy.typing as npt

from robokin._validation import check_transform
from robokin.exceptions import InputError, ModelError
from robokin.model.chain import Chain
from robokin.model.dh import chain_from_dh
from robokin.spatial import invert, rpy_from_matrix

if TYPE_CHECKING:
    from robokin.model.parts import RobotParts

__all__ = ["DHExtraction", "dh_from_robot", "dh_rows_for_transform", "identity_rows"]

_TOL = 1e-9


def _clean(v: float) -> float:
    v = float(v)
    return 0.0 if abs(v) < 1e-12 else v


def _frame(x: np.ndarray, z: np.ndarray, o: np.ndarray) -> np.ndarray:
    T = np.eye(4)
    T[:3, 0] = x
    T[:3, 1] = np.cross(z, x)
    T[:3, 2] = z
    T[:3, 3] = o
    return T


def _std(theta: float, d: float, a: float, alpha: float) -> np.ndarray:
    ct, st, ca, sa = math.cos(theta), math.sin(theta), math.cos(alpha), math.sin(alpha)
    return np.array([
        [ct, -st * ca, st * sa, a * ct],
        [st, ct * ca, -ct * sa, a * st],
        [0.0, sa, ca, d],
        [0.0, 0.0, 0.0, 1.0],
    ])


def _std_params(T: np.ndarray) -> tuple[tuple[float, float, float, float], float]:
    """``(theta, d, a, alpha)`` of ``T ~ Rz Tz Tx Rx`` and the fit residual."""
    theta = math.atan2(T[1, 0], T[0, 0])
    alpha = math.atan2(T[2, 1], T[2, 2])
    d = T[2, 3]
    a = T[0, 3] * math.cos(theta) + T[1, 3] * math.sin(theta)
    p = (_clean(theta), _clean(d), _clean(a), _clean(alpha))
    return p, float(np.abs(_std(*p) - T).max())


def _pick_sense(x: np.ndarray, x_prev: np.ndarray, z_prev: np.ndarray) -> np.ndarray:
    """The one of ``x`` and ``-x`` closer to ``x_prev`` (on a tie, theta = +90 deg)."""
    dot = float(x @ x_prev)
    if abs(dot) > _TOL:
        return x if dot > 0 else -x
    return x if float(np.cross(x_prev, x) @ z_prev) > 0 else -x


def _next_frame(
    prev: np.ndarray, point: np.ndarray, z: np.ndarray
) -> tuple[np.ndarray, str]:
    """The DH frame on the line ``(point, z)`` after frame ``prev``; and a note."""
    x0, z0, o0 = prev[:3, 0], prev[:3, 2], prev[:3, 3]
    cross = np.cross(z0, z)
    s = float(np.linalg.norm(cross))
    if s < _TOL:  # parallel: the normal through the previous origin
        foot = point + ((o0 - point) @ z) * z
        n = foot - o0
        dist = float(np.linalg.norm(n))
        if dist < _TOL:
            return _frame(x0, z, o0), "coincident"
        return _frame(_pick_sense(n / dist, x0, z0), z, foot), "parallel"
    w0 = o0 - point
    b = float(z0 @ z)
    dd, e = float(z0 @ w0), float(z @ w0)
    den = 1.0 - b * b
    t2 = (e - b * dd) / den
    t1 = (b * e - dd) / den
    c1, c2 = o0 + t1 * z0, point + t2 * z
    n = c2 - c1
    dist = float(np.linalg.norm(n))
    if dist < _TOL:
        return _frame(_pick_sense(cross / s, x0, z0), z, c2), "intersecting"
    return _frame(_pick_sense(n / dist, x0, z0), z, c2), "skew"


def dh_rows_for_transform(
    T: npt.ArrayLike, convention: Literal["standard", "modified"] = "standard"
) -> list[tuple[float, float, float, float]]:
    """Fixed DH rows (virtual frames) whose product is the transform ``T``.

    One row when ``T`` is a single DH transform, else two (always enough).

    Returns:
        ``[(theta, d, a, alpha), ...]`` in SI units; for the modified convention
        the row is ``Rx(alpha) Tx(a) Rz(theta) Tz(d)``.
    """
    T = np.asarray(T, dtype=np.float64)
    if convention == "modified":
        # inv(Rz Tz Tx Rx) = Rx(-alpha) Tx(-a) Rz(-theta) Tz(-d)
        rows = dh_rows_for_transform(invert(T), "standard")
        return [(_clean(-t), _clean(-d), _clean(-a), _clean(-al))
                for t, d, a, al in reversed(rows)]
    if np.allclose(T, np.eye(4), atol=1e-15, rtol=0):
        return []
    p, res = _std_params(T)
    if res < 1e-12:
        return [p]
    mid, _ = _next_frame(np.eye(4), T[:3, 3], T[:3, 2])
    p1, r1 = _std_params(mid)
    p2, r2 = _std_params(invert(mid) @ T)
    if max(r1, r2) > 1e-9:  # pragma: no cover - by construction
        raise ModelError(f"internal: virtual-frame fit residual {max(r1, r2):.3g}")
    return [p1, p2]


@dataclass(frozen=True)
class DHExtraction:
    """A DH table derived from a robot, with what remains.

    Attributes:
        convention: ``"standard"`` or ``"modified"``.
        rows: DH rows as :meth:`robokin.Robot.from_dh` takes them (SI units).
        base: The remaining base transform (4, 4) in the robot's world frame.
        tool: The remaining tool transform (4, 4).
        coordinates: Explicit coordinates for rows with ``depends``, or None.
        virtual_frames: Names of the fixed rows inserted (``virtual_frames=True``).
        needs_virtual_frames: True when the plain table needs a base or tool
            transform besides the identity, i.e. virtual frames to stand alone.
        notes: What was chosen where DH leaves freedom, per frame.
    """

    convention: Literal["standard", "modified"]
    rows: tuple[dict[str, Any], ...]
    base: np.ndarray
    tool: np.ndarray
    coordinates: tuple[dict[str, Any], ...] | None = None
    virtual_frames: tuple[str, ...] = ()
    needs_virtual_frames: bool = False
    notes: tuple[str, ...] = field(default_factory=tuple)

    def chain(self) -> Chain:
        """The chain this table describes (same FK as the source robot's).

        ``robokin.Robot(extraction.chain(), name=...)`` is a robot of it.
        """
        return chain_from_dh(self.rows, self.convention, base=self.base,
                             tool=self.tool, coordinates=self.coordinates)


def identity_rows(chain: Chain) -> dict[int, int]:
    """Chain joint index -> coordinate index for joints that are their coordinate.

    A joint is its coordinate when the coordinate has the joint's name and the
    coupling's row of the joint is that coordinate alone (factor 1, offset 0).
    """
    M, c = chain.coupling.matrix, chain.coupling.offset
    names = [x.name for x in chain.coordinates]
    out = {}
    for k, j in enumerate(chain.joints):
        if j.name in names:
            i = names.index(j.name)
            e = np.zeros(len(names))
            e[i] = 1.0
            if np.array_equal(M[k], e) and c[k] == 0.0:
                out[k] = i
    return out


def dh_from_robot(
    robot: RobotParts,
    convention: Literal["standard", "modified"] = "standard",
    *,
    reference: npt.ArrayLike | None = None,
    virtual_frames: bool = False,
) -> DHExtraction:
    """Derive a DH table from a robot's joint axes (see the module docstring).

    Args:
        robot: Any robot (or robot parts).
        convention: ``"standard"`` or ``"modified"``.
        reference: A frame (4, 4) in the robot's world frame whose origin and x
            axis guide DH frame 0 (default: ``robot.base``).
        virtual_frames: Fold the remaining base and tool transforms into fixed
            rows named ``base_frame*`` / ``tool_frame*``.

    Returns:
        A :class:`DHExtraction`; ``extraction.chain()`` has the same FK as
        ``robot`` (checked here at random configurations).

    Raises:
        InputError: an unknown convention or a bad reference frame.
    """
    if convention not in ("standard", "modified"):
        raise InputError(
            "convention", f"expected 'standard' or 'modified', got {convention!r}"
        )
    chain = robot.chain
    ref = chain.base if reference is None else check_transform(reference, "reference")
    # Axes at zero chain values (each joint at its zero offset).
    at_zero = chain.frames_at(np.zeros(chain.n_chain))
    points = [F[:3, 3] for F in at_zero[:-1]]
    axes = [j.sign * F[:3, 2] for j, F in zip(chain.joints, at_zero)]
    tip = at_zero[-1]
    n = len(axes)
    notes: list[str] = []
    # Frame 0.
    z0 = axes[0]
    o0 = points[0] + ((ref[:3, 3] - points[0]) @ z0) * z0
    for cand in (ref[:3, 0], ref[:3, 1], ref[:3, 2]):
        xp = cand - (cand @ z0) * z0
        if np.linalg.norm(xp) > 1e-6:
            x0 = xp / np.linalg.norm(xp)
            break
    else:  # pragma: no cover - three orthonormal columns cannot all lie on z0
        raise InputError("reference", "its axes do not span space")
    frames = [_frame(x0, z0, o0)]
    for i in range(1, n):
        F, kind = _next_frame(frames[-1], points[i], axes[i])
        frames.append(F)
        if kind in ("parallel", "coincident"):
            notes.append(
                f"axes {i} and {i + 1} are {kind}: the common normal is taken through "
                f"frame {i - 1}'s origin (d{i} = 0)"
            )
    # Frame n: on the last axis, at the foot of the tool point.
    last = frames[-1]
    zn, on_prev = last[:3, 2], last[:3, 3]
    on = on_prev + ((tip[:3, 3] - on_prev) @ zn) * zn
    xt = tip[:3, 0] - (tip[:3, 0] @ zn) * zn
    xn = xt / np.linalg.norm(xt) if np.linalg.norm(xt) > 1e-6 else last[:3, 0]
    frames.append(_frame(xn, zn, on))
    # Standard rows from successive frames.
    std = []
    for i in range(1, n + 1):
        p, res = _std_params(invert(frames[i - 1]) @ frames[i])
        if res > 1e-9:  # pragma: no cover - by construction
            raise ModelError(f"internal: DH fit residual {res:.3g} at row {i}")
        std.append(p)
    base_rem = frames[0]
    tool_rem = invert(frames[-1]) @ tip
    # Rows with names, kinds, limits and dependencies.
    ident = identity_rows(chain)
    M, cvec = chain.coupling.matrix, chain.coupling.offset
    cnames = [x.name for x in chain.coordinates]
    explicit = len(ident) != n or len(cnames) != n
    rows: list[dict[str, Any]] = []
    for k, j in enumerate(chain.joints):
        theta, d, a, alpha = std[k]
        if convention == "modified":
            a, alpha = (std[k - 1][2], std[k - 1][3]) if k > 0 else (0.0, 0.0)
        row: dict[str, Any] = {"name": j.name, "joint": j.kind, "a": a,
                               "alpha": alpha, "d": d, "theta": theta}
        if k in ident:
            lim = chain.coordinates[ident[k]].limits
            if all(math.isfinite(v) for v in lim):
                row["limits"] = [float(lim[0]), float(lim[1])]
        else:
            row["depends"] = {cnames[i]: float(M[k, i]) for i in np.flatnonzero(M[k])}
            row["depends_offset"] = float(cvec[k])
        rows.append(row)
    coordinates = None
    if explicit:
        coordinates = tuple(
            {"name": x.name, "joint": x.kind,
             **({"limits": list(x.limits)} if all(map(math.isfinite, x.limits))
                else {})}
            for x in chain.coordinates
        )
    eye = np.eye(4)
    needs = not (np.allclose(base_rem, eye, atol=1e-12)
                 and np.allclose(tool_rem, eye, atol=1e-12))
    if not np.allclose(base_rem, eye, atol=1e-12):
        notes.append("a base transform remains (frame 0 must have z along joint 1)")
    if not np.allclose(tool_rem, eye, atol=1e-12):
        notes.append("a tool transform remains (frame n must have z along joint n)")
    inserted: list[str] = []
    if virtual_frames:
        def fixed(name: str, p) -> dict[str, Any]:
            theta, d, a, alpha = p
            return {"name": name, "joint": "fixed", "a": a, "alpha": alpha, "d": d,
                    "theta": theta}

        pre = [fixed(f"base_frame{'_' + str(i + 1) if i else ''}", p)
               for i, p in enumerate(dh_rows_for_transform(base_rem, convention))]
        post = [fixed(f"tool_frame{'_' + str(i + 1) if i else ''}", p)
                for i, p in enumerate(dh_rows_for_transform(tool_rem, convention))]
        inserted = [r["name"] for r in pre + post]
        rows = pre + rows + post
        base_rem, tool_rem = eye.copy(), eye.copy()
        if inserted:
            notes.append(f"virtual frames inserted: {inserted}")
    for arr in (base_rem, tool_rem):
        arr[np.abs(arr) < 1e-15] = 0.0
        arr.setflags(write=False)
    out = DHExtraction(
        convention=convention, rows=tuple(rows), base=base_rem, tool=tool_rem,
        coordinates=coordinates, virtual_frames=tuple(inserted),
        needs_virtual_frames=needs, notes=tuple(notes),
    )
    _verify(robot, out)
    return out


def _verify(robot: RobotParts, ext: DHExtraction) -> None:
    """Guard: the table must reproduce the robot's FK (the tool pose)."""
    rng = np.random.default_rng(0)
    lim = np.clip(robot.limits, -math.pi, math.pi)
    ours, theirs = ext.chain(), robot.chain
    for q in rng.uniform(lim[:, 0], lim[:, 1], (8, robot.n)):
        err = np.abs(ours.frames_at(ours.coupling.apply(q))[-1]
                     - theirs.frames_at(theirs.coupling.apply(q))[-1]).max()
        if not err < 1e-9:  # pragma: no cover - a bug, not a user error
            raise ModelError(f"internal: derived DH table misses the FK by {err:.3g}")


def describe(ext: DHExtraction, *, deg: bool = True) -> dict[str, Any]:
    """A plain, JSON-ready summary (angles in degrees when ``deg``), a new dict."""
    A = 180.0 / math.pi if deg else 1.0

    def place(T: np.ndarray) -> dict[str, list[float]]:
        return {"xyz": [float(v) for v in T[:3, 3]],
                "rpy": [float(v) * A for v in rpy_from_matrix(T)]}

    rows = []
    for r in ext.rows:
        rr = dict(r)
        rr["alpha"] *= A
        rr["theta"] *= A
        if "limits" in rr and r["joint"] == "revolute":
            rr["limits"] = [v * A for v in rr["limits"]]
        rows.append(rr)
    return {"convention": ext.convention, "rows": rows, "base": place(ext.base),
            "tool": place(ext.tool), "virtual_frames": list(ext.virtual_frames),
            "needs_virtual_frames": ext.needs_virtual_frames, "notes": list(ext.notes)}
