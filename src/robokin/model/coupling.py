"""Affine joint maps: dependent chain joints and actuator (motor) coordinates.

Both are the same object, ``y = A @ x + b`` (:class:`AffineMap`):

* dependent joints: ``q_chain = M @ q + c`` maps the robot's independent joint
  coordinates ``q`` (n) to the values of every chain joint (n_chain);
* actuators: ``q = A @ phi + b`` maps motor coordinates ``phi`` (m) to joint
  coordinates ``q`` (n); ``phi = A^+ (q - b)`` goes back where ``A`` has full
  column rank.

Named constructors build the usual mechanisms, all in SI units (rad, m):

* actuators: :func:`direct`, :func:`gear` (a reduction), :func:`screw` (a lead
  screw driving a prismatic joint), :func:`ball_screw_spline` (the SCARA shaft
  whose rotation and lift are both set by two motors, :class:`BallScrewSpline`),
  assembled with :func:`block_diagonal` or :func:`actuator_map`;
* dependent joints: :func:`mimic` (URDF ``<mimic>``), :func:`parallelogram` (the
  palletizer linkages that keep the tool level), assembled into a chain coupling
  with :func:`coupling_from_dependencies`.

See ``docs/conventions.md``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Literal

import numpy as np
import numpy.typing as npt

from robokin._text import short_repr
from robokin.exceptions import ModelError

__all__ = [
    "AffineMap",
    "BallScrewSpline",
    "Dependency",
    "ShaftMotion",
    "actuator_map",
    "ball_screw_spline",
    "block_diagonal",
    "coupling_from_dependencies",
    "direct",
    "gear",
    "mimic",
    "parallelogram",
    "screw",
]

_TWO_PI = 2.0 * math.pi


def _frozen(a: npt.ArrayLike, ndim: int, name: str) -> npt.NDArray[np.float64]:
    arr = np.array(a, dtype=np.float64)
    if arr.ndim != ndim:
        raise ModelError(f"{name} must have {ndim} dimensions, got shape {arr.shape}")
    if not np.isfinite(arr).all():
        raise ModelError(f"{name} holds a non-finite value")
    arr.setflags(write=False)
    return arr


@dataclass(frozen=True, eq=False, init=False)
class AffineMap:
    """The affine map ``y = matrix @ x + offset``.

    Attributes:
        matrix: Shape (n_out, n_in).
        offset: Shape (n_out,).
    """

    matrix: npt.NDArray[np.float64]
    offset: npt.NDArray[np.float64]
    is_identity: bool = field(init=False)

    def __init__(self, matrix: npt.ArrayLike, offset: npt.ArrayLike) -> None:
        """Check and freeze the map.

        Args:
            matrix: Shape (n_out, n_in), finite.
            offset: Shape (n_out,), finite.

        Raises:
            ModelError: a wrong number of dimensions, a non-finite value, or an
                offset that does not match the matrix rows.
        """
        A = _frozen(matrix, 2, "matrix")
        b = _frozen(offset, 1, "offset")
        if b.shape[0] != A.shape[0]:
            raise ModelError(
                f"offset has {b.shape[0]} entries but the matrix has {A.shape[0]} rows"
            )
        object.__setattr__(self, "matrix", A)
        object.__setattr__(self, "offset", b)
        ident = (A.shape[0] == A.shape[1] and np.array_equal(A, np.eye(A.shape[0]))
                 and not b.any())
        object.__setattr__(self, "is_identity", bool(ident))

    @classmethod
    def identity(cls, n: int) -> AffineMap:
        """The identity map on n coordinates."""
        return cls(np.eye(n), np.zeros(n))

    @property
    def n_in(self) -> int:
        """Number of input coordinates."""
        return int(self.matrix.shape[1])

    @property
    def n_out(self) -> int:
        """Number of output coordinates."""
        return int(self.matrix.shape[0])

    @property
    def is_invertible(self) -> bool:
        """True when the matrix has full column rank (a left inverse exists)."""
        return bool(np.linalg.matrix_rank(self.matrix) == self.n_in)

    def apply(self, x: np.ndarray) -> np.ndarray:
        """Map inputs ``(..., n_in)`` to outputs ``(..., n_out)``."""
        if self.is_identity:
            return x
        result: np.ndarray = x @ self.matrix.T + self.offset
        return result

    def apply_rate(self, xd: np.ndarray) -> np.ndarray:
        """Map velocities or accelerations (the offset drops out)."""
        if self.is_identity:
            return xd
        result: np.ndarray = xd @ self.matrix.T
        return result

    def inverse(self, y: np.ndarray, *, what: str = "map") -> np.ndarray:
        """Solve ``matrix @ x + offset = y`` for x, ``(..., n_out) -> (..., n_in)``.

        When ``n_out > n_in`` this is the least-squares solution; use
        :meth:`residual` to see whether ``y`` is in the map's range.

        Raises:
            ModelError: the matrix has no left inverse (rank below n_in), naming ``what``.
        """
        if self.is_identity:
            return y
        result: np.ndarray = (y - self.offset) @ self.pseudo_inverse(what=what).T
        return result

    def inverse_rate(self, yd: np.ndarray, *, what: str = "map") -> np.ndarray:
        """Inverse map of velocities or accelerations, ``(..., n_out) -> (..., n_in)``.

        Raises:
            ModelError: the matrix has no left inverse, naming ``what``.
        """
        if self.is_identity:
            return yd
        result: np.ndarray = yd @ self.pseudo_inverse(what=what).T
        return result

    def residual(self, y: np.ndarray, *, what: str = "map") -> np.ndarray:
        """``(...)`` largest entry of ``|matrix @ inverse(y) + offset - y|``.

        Zero (to rounding) exactly where ``y`` is an output of the map.
        """
        y = np.asarray(y, dtype=np.float64)
        if self.is_identity:
            return np.zeros(y.shape[:-1])
        back = self.apply(self.inverse(y, what=what))
        result: np.ndarray = np.abs(back - y).max(axis=-1, initial=0.0)
        return result

    def pseudo_inverse(self, *, what: str = "map") -> np.ndarray:
        """The left inverse ``(n_in, n_out)``; raises ModelError when rank-deficient."""
        cached = self.__dict__.get("_pinv")
        if cached is not None:
            result: np.ndarray = cached
            return result
        A = self.matrix
        rank = np.linalg.matrix_rank(A)
        if rank < A.shape[1]:
            raise ModelError(
                f"the {what} matrix (shape {A.shape}) has rank "
                f"{rank} < {A.shape[1]}: it cannot be inverted"
            )
        pinv = np.linalg.pinv(A)
        pinv.setflags(write=False)
        object.__setattr__(self, "_pinv", pinv)
        return pinv

    def inverse_map(self, *, what: str = "map") -> AffineMap:
        """The map ``x = P (y - offset)`` with ``P`` the left inverse, as an AffineMap.

        Raises:
            ModelError: the matrix has no left inverse, naming ``what``.
        """
        P = self.pseudo_inverse(what=what)
        return AffineMap(P, -P @ self.offset)

    def compose(self, inner: AffineMap) -> AffineMap:
        """The map ``x -> self(inner(x))``.

        Raises:
            ModelError: ``inner`` has a different number of outputs than ``self`` inputs.
        """
        if inner.n_out != self.n_in:
            raise ModelError(
                f"cannot compose: the inner map has {inner.n_out} outputs, "
                f"the outer one takes {self.n_in} inputs"
            )
        return AffineMap(self.matrix @ inner.matrix, self.matrix @ inner.offset + self.offset)

    def allclose(self, other: AffineMap, *, atol: float = 1e-12) -> bool:
        """Same shape, matrix and offset (to ``atol``)."""
        return (self.matrix.shape == other.matrix.shape
                and np.allclose(self.matrix, other.matrix, rtol=0.0, atol=atol)
                and np.allclose(self.offset, other.offset, rtol=0.0, atol=atol))

    def __repr__(self) -> str:
        """The map as a constructor call with plain lists."""
        return f"AffineMap(matrix={self.matrix.tolist()!r}, offset={self.offset.tolist()!r})"


# --------------------------------------------------------------------- actuators
def _number(value: float, name: str, *, nonzero: bool = False) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ModelError(f"{name} must be a number, got {short_repr(value)}") from None
    if not math.isfinite(v):
        raise ModelError(f"{name} must be finite, got {v}")
    if nonzero and v == 0.0:
        raise ModelError(f"{name} must not be zero")
    return v


def direct(n: int = 1) -> AffineMap:
    """``n`` motors that drive ``n`` joints one to one (``q = phi``)."""
    return AffineMap.identity(int(n))


def gear(ratio: float, *, offset: float = 0.0) -> AffineMap:
    """A motor driving one revolute joint through a reduction.

    ``q = phi / ratio + offset``: the motor turns ``ratio`` times per joint turn.
    A negative ratio reverses the direction (a belt or gear stage that flips it).

    Args:
        ratio: Reduction ratio (motor turns per joint turn), non-zero.
        offset: Joint value [rad] at motor zero.

    Returns:
        A 1x1 :class:`AffineMap`.
    """
    r = _number(ratio, "ratio", nonzero=True)
    return AffineMap([[1.0 / r]], [_number(offset, "offset")])


def screw(lead: float, *, ratio: float = 1.0, offset: float = 0.0) -> AffineMap:
    """A motor driving one prismatic joint through a lead screw.

    ``q = lead / (2 pi ratio) * phi + offset``: one screw turn moves the joint by
    ``lead``; the motor turns ``ratio`` times per screw turn.

    Args:
        lead: Screw lead [m per revolution], non-zero; negative for a left-hand
            thread (or a reversed mounting).
        ratio: Reduction from the motor to the screw, non-zero.
        offset: Joint value [m] at motor zero.

    Returns:
        A 1x1 :class:`AffineMap` from motor angle [rad] to joint position [m].
    """
    L = _number(lead, "lead", nonzero=True)
    r = _number(ratio, "ratio", nonzero=True)
    return AffineMap([[L / (_TWO_PI * r)]], [_number(offset, "offset")])


MotionType = Literal["still", "vertical", "rotation", "helix", "combined"]


@dataclass(frozen=True)
class ShaftMotion:
    """How a ball-screw / ball-spline shaft moves for given nut rotations.

    Attributes:
        rotation: Shaft rotation [rad] (or rate), shape (...).
        lift: Shaft lift [m] (or rate), shape (...).
        kind: (...) str array: ``"still"``, ``"vertical"`` (lift only: the
            spline nut is held, N2 = 0), ``"rotation"`` (rotation only: both nuts
            turn together, N1 = N2), ``"helix"`` (the fixed-lead helix: the screw
            nut is held, N1 = 0, the shaft advances one lead per turn) or
            ``"combined"`` (rotation and lift at another ratio).
        lead: (...) lift per shaft revolution [m] (nan when the shaft does not
            rotate).
    """

    rotation: np.ndarray
    lift: np.ndarray
    kind: np.ndarray
    lead: np.ndarray


@dataclass(frozen=True)
class BallScrewSpline:
    r"""A ball-screw / ball-spline shaft driven by two motors (the SCARA's axes 3-4).

    The shaft carries a ball-screw groove and a spline groove. Motor 3 turns the
    screw nut through a reduction ``i``, motor 4 turns the spline nut through a
    reduction ``j``. The spline nut sets the shaft's rotation; a rotation of the
    screw nut relative to the shaft lifts it by one lead per turn. In the
    tensor-method SCARA paper's notation (degrees, mm; ``l`` the lead in mm/rev):

    .. math::

        \varphi_3 = (\theta_3 - l_4 \cdot 360 / l) \cdot i, \qquad
        \varphi_4 = \theta_3 \cdot j

    and back, ``theta3 = phi4 / j``, ``l4 = (phi4 / j - phi3 / i) * l / 360``. In SI
    units (rad, m) the 360 becomes 2 pi. With the nut rotations ``N1 = phi3 / i``
    (screw nut) and ``N2 = phi4 / j`` (spline nut): ``N2 = 0`` gives a vertical
    motion only, ``N1 = N2`` a rotation only, ``N1 = 0`` a helix whose lead is the
    screw lead.

    Attributes:
        lead: Screw lead [m per revolution], non-zero.
        i: Reduction from motor 3 to the screw-nut pulley (motor turns per nut
            turn), non-zero; negative reverses the motor.
        j: Reduction from motor 4 to the spline-nut pulley, non-zero.
        lift_sign: +1 (the paper's convention: holding the spline, turning the
            screw nut positively lowers the shaft, i.e. positive lift is
            ``(theta3 - N1) * lead / 2pi``) or -1 (the opposite thread hand).
    """

    lead: float
    i: float = 1.0
    j: float = 1.0
    lift_sign: float = 1.0

    def __post_init__(self) -> None:
        """Check the lead, ratios and sign."""
        object.__setattr__(self, "lead", _number(self.lead, "lead", nonzero=True))
        object.__setattr__(self, "i", _number(self.i, "i", nonzero=True))
        object.__setattr__(self, "j", _number(self.j, "j", nonzero=True))
        if self.lift_sign not in (1, -1, 1.0, -1.0) or isinstance(self.lift_sign, bool):
            raise ModelError(f"lift_sign must be +1 or -1, got {short_repr(self.lift_sign)}")
        object.__setattr__(self, "lift_sign", float(self.lift_sign))

    @property
    def _k(self) -> float:
        """Lift [m] per radian of shaft-relative screw-nut rotation, signed."""
        return self.lift_sign * self.lead / _TWO_PI

    def affine_map(self) -> AffineMap:
        """``(rotation [rad], lift [m]) = A (phi_screw, phi_spline) [rad]``, 2x2."""
        k = self._k
        return AffineMap(
            [[0.0, 1.0 / self.j],
             [-k / self.i, k / self.j]],
            [0.0, 0.0],
        )

    def motors_from_shaft(self, rotation: npt.ArrayLike, lift: npt.ArrayLike) -> np.ndarray:
        """Motor angles ``(..., 2)`` = (phi3 screw, phi4 spline) [rad].

        Args:
            rotation: Shaft rotation theta3 [rad], shape (...).
            lift: Shaft lift l4 [m], shape (...).
        """
        th = np.asarray(rotation, dtype=np.float64)
        lf = np.asarray(lift, dtype=np.float64)
        phi3 = (th - lf / self._k) * self.i
        phi4 = th * self.j
        return np.stack(np.broadcast_arrays(phi3, phi4), axis=-1)

    def shaft_from_motors(self, phi: npt.ArrayLike) -> np.ndarray:
        """Shaft ``(..., 2)`` = (rotation [rad], lift [m]) from motor angles (..., 2) [rad]."""
        phi = np.asarray(phi, dtype=np.float64)
        n1 = phi[..., 0] / self.i
        n2 = phi[..., 1] / self.j
        return np.stack([n2, self._k * (n2 - n1)], axis=-1)

    def motion(self, n_screw: npt.ArrayLike, n_spline: npt.ArrayLike, *,
               tol: float = 1e-12) -> ShaftMotion:
        """The shaft's motion for nut rotations (or rates) N1 (screw) and N2 (spline).

        Args:
            n_screw: Screw-nut rotation N1 [rad] (or rad/s), shape (...).
            n_spline: Spline-nut rotation N2 [rad] (or rad/s), shape (...).
            tol: Rotations below this count as zero.

        Returns:
            A :class:`ShaftMotion` (rotation, lift, kind, lead per shaft turn).
        """
        n1, n2 = np.broadcast_arrays(np.asarray(n_screw, dtype=np.float64),
                                     np.asarray(n_spline, dtype=np.float64))
        rotation = n2.copy()
        lift = self._k * (n2 - n1)
        z1, z2 = np.abs(n1) <= tol, np.abs(n2) <= tol
        same = np.abs(n1 - n2) <= tol
        kind = np.full(n1.shape, "combined", dtype=object)
        kind[z1 & ~z2] = "helix"
        kind[same & ~z2] = "rotation"
        kind[z2 & ~z1] = "vertical"
        kind[z1 & z2] = "still"
        with np.errstate(divide="ignore", invalid="ignore"):
            lead = np.where(z2, np.nan, lift / np.where(z2, 1.0, n2) * _TWO_PI)
        return ShaftMotion(rotation, lift, kind, lead)


def ball_screw_spline(lead: float, i: float = 1.0, j: float = 1.0, *,
                      lift_sign: float = 1.0) -> AffineMap:
    """The 2x2 actuator map of a ball-screw / ball-spline shaft (see :class:`BallScrewSpline`).

    Inputs (motor 3 on the screw nut, motor 4 on the spline nut) [rad]; outputs
    (shaft rotation [rad], shaft lift [m]).

    Args:
        lead: Screw lead [m per revolution].
        i: Reduction motor 3 -> screw-nut pulley.
        j: Reduction motor 4 -> spline-nut pulley.
        lift_sign: +1 (the paper's convention) or -1.

    Example:
        The tensor-method SCARA paper's shaft, lead 20 mm, i = 1, j = 15:
        ``ball_screw_spline(0.020, 1, 15)``.
    """
    return BallScrewSpline(lead, i, j, lift_sign).affine_map()


def block_diagonal(*maps: AffineMap) -> AffineMap:
    """Stack maps acting on disjoint coordinates: inputs and outputs concatenate in order."""
    if not maps:
        raise ModelError("block_diagonal needs at least one map")
    n_out = sum(m.n_out for m in maps)
    n_in = sum(m.n_in for m in maps)
    A = np.zeros((n_out, n_in))
    b = np.zeros(n_out)
    r = c = 0
    for m in maps:
        A[r:r + m.n_out, c:c + m.n_in] = m.matrix
        b[r:r + m.n_out] = m.offset
        r += m.n_out
        c += m.n_in
    return AffineMap(A, b)


def actuator_map(
    joint_names: Sequence[str],
    drives: Sequence[tuple[Sequence[str] | str, AffineMap]],
) -> AffineMap:
    """Assemble ``q = A phi + b`` from drives, each acting on named joints.

    Motor coordinates are numbered in drive order (a drive with a 2x2 map brings two
    motors). A joint driven by no drive is an error; a joint may be driven by only
    one drive.

    Args:
        joint_names: The robot's joint (coordinate) names, in order (n).
        drives: ``(joints, map)`` pairs: the joint name(s) the drive moves, and its
            map from its motors to those joints (``map.n_out == len(joints)``).

    Returns:
        The n x m :class:`AffineMap`.

    Raises:
        ModelError: an unknown or doubly driven joint, an undriven joint, or a
            map whose size does not match its joint list.

    Example:
        ``actuator_map(["j1", "j2", "rot", "lift"], [(["j1", "j2"], direct(2)),
        (["rot", "lift"], ball_screw_spline(0.02, 1, 15))])``
    """
    names = list(joint_names)
    index = {nm: k for k, nm in enumerate(names)}
    m = sum(d[1].n_in for d in drives)
    A = np.zeros((len(names), m))
    b = np.zeros(len(names))
    owner: dict[str, int] = {}
    col = 0
    for d, (joints, amap) in enumerate(drives):
        joints = [joints] if isinstance(joints, str) else list(joints)
        if amap.n_out != len(joints):
            raise ModelError(
                f"drive {d} moves {len(joints)} joint(s) {joints} but its map has "
                f"{amap.n_out} output(s)")
        for r, nm in enumerate(joints):
            if nm not in index:
                raise ModelError(f"drive {d}: unknown joint {short_repr(nm)}; joints: {names}")
            if nm in owner:
                raise ModelError(f"drive {d}: joint {short_repr(nm)} is already driven by drive "
                                 f"{owner[nm]}")
            owner[nm] = d
            A[index[nm], col:col + amap.n_in] = amap.matrix[r]
            b[index[nm]] = amap.offset[r]
        col += amap.n_in
    missing = [nm for nm in names if nm not in owner]
    if missing:
        raise ModelError(f"joint(s) {missing} are driven by no actuator")
    return AffineMap(A, b)


# --------------------------------------------------------------- dependent joints
@dataclass(frozen=True)
class Dependency:
    """A dependent chain joint: ``value = sum(coefficients[c] * q[c]) + offset``.

    Values in SI units (rad or m) of the chain joint; coefficients carry the unit
    ratio when a revolute joint follows a prismatic coordinate (or the reverse).

    Attributes:
        coefficients: Coordinate name -> coefficient.
        offset: Constant term [rad or m].
    """

    coefficients: Mapping[str, float]
    offset: float = 0.0

    def __post_init__(self) -> None:
        """Check the coefficients are finite numbers; freeze them."""
        coeffs = {str(k): _number(v, f"coefficient of {short_repr(k)}")
                  for k, v in dict(self.coefficients).items()}
        object.__setattr__(self, "coefficients", coeffs)
        object.__setattr__(self, "offset", _number(self.offset, "offset"))

    def row_fields(self) -> dict[str, object]:
        """The ``depends`` / ``depends_offset`` fields of a DH or elementary row."""
        return {"depends": dict(self.coefficients), "depends_offset": self.offset}


def mimic(joint: str, multiplier: float = 1.0, offset: float = 0.0) -> Dependency:
    """A joint that mimics another (URDF ``<mimic>``): ``value = multiplier * q[joint] + offset``.

    Args:
        joint: Name of the independent coordinate followed.
        multiplier: Factor (the URDF ``multiplier``).
        offset: Constant [rad or m] (the URDF ``offset``).
    """
    return Dependency({str(joint): multiplier}, offset)


def parallelogram(
    pitch: Sequence[str],
    *,
    relative: Sequence[str] | None = None,
    level: str | None = "level",
    level_offset: float = 0.0,
) -> dict[str, Dependency]:
    """The dependent joints of a palletizer's parallelogram linkages.

    A palletizing arm's pitch motors drive *absolute* elevations (a parallelogram
    carries the forearm drive past the elbow), and a second parallelogram keeps the
    tool flange level. With parallel pitch axes of the same sense, absolute pitch
    coordinates ``a_1 .. a_k`` (proximal first) give relative chain joints
    ``r_1 = a_1``, ``r_m = a_m - a_(m-1)``, and the passive level joint
    ``r_level = -a_k + level_offset``, so that the pitch angles sum to the constant
    ``level_offset``: the tool keeps its attitude whatever the pitch.

    Args:
        pitch: Names of the absolute pitch coordinates, proximal first.
        relative: Names of the chain joints those pitch motions happen at (default:
            the coordinate names). A chain joint named like its coordinate with
            coefficient 1 is simply that coordinate and is left out of the result.
        level: Name of the passive joint that keeps the tool level, or None when
            the arm has none.
        level_offset: The constant sum of the pitch chain joints [rad].

    Returns:
        Chain joint name -> :class:`Dependency`, for the dependent joints only;
        pass it to :func:`coupling_from_dependencies` (or splice
        :meth:`Dependency.row_fields` into the robot's rows).

    Example:
        The QFMD010 (upper-arm elevation theta2, forearm elevation theta3, chain
        joints ``theta2``, ``forearm``, ``level``):
        ``parallelogram(["theta2", "theta3"], relative=["theta2", "forearm"])``
        gives ``forearm = theta3 - theta2`` and ``level = -theta3``.
    """
    pitch = [str(p) for p in pitch]
    if not pitch:
        raise ModelError("parallelogram needs at least one pitch coordinate")
    relative = list(pitch) if relative is None else [str(r) for r in relative]
    if len(relative) != len(pitch):
        raise ModelError(
            f"parallelogram: {len(pitch)} pitch coordinate(s) but {len(relative)} "
            f"relative joint name(s)")
    out: dict[str, Dependency] = {}
    for k, name in enumerate(relative):
        coeffs = {pitch[k]: 1.0}
        if k > 0:
            coeffs[pitch[k - 1]] = -1.0
        if name == pitch[k] and len(coeffs) == 1:
            continue  # the joint is its coordinate
        out[name] = Dependency(coeffs)
    if level is not None:
        out[str(level)] = Dependency({pitch[-1]: -1.0}, level_offset)
    return out


def coupling_from_dependencies(
    joints: Sequence[str],
    coordinates: Sequence[str],
    dependencies: Mapping[str, Dependency],
) -> AffineMap:
    """The chain coupling ``q_chain = M q + c`` from named dependencies.

    Args:
        joints: Chain joint names in order (n_chain).
        coordinates: Independent coordinate names in order (n).
        dependencies: Chain joint name -> Dependency for the dependent joints; every
            other chain joint must be a coordinate of the same name.

    Returns:
        The (n_chain x n) :class:`AffineMap`.

    Raises:
        ModelError: a dependency on an unknown coordinate or of an unknown joint,
            or a chain joint that is neither dependent nor a coordinate.
    """
    joints = [str(j) for j in joints]
    coords = [str(c) for c in coordinates]
    index = {c: i for i, c in enumerate(coords)}
    unknown = sorted(set(dependencies) - set(joints))
    if unknown:
        raise ModelError(f"dependencies of unknown joint(s) {unknown}; joints: {joints}")
    M = np.zeros((len(joints), len(coords)))
    c = np.zeros(len(joints))
    for k, name in enumerate(joints):
        dep = dependencies.get(name)
        if dep is None:
            if name not in index:
                raise ModelError(
                    f"joint {short_repr(name)} is neither a coordinate nor dependent; "
                    f"coordinates: {coords}")
            M[k, index[name]] = 1.0
            continue
        for other, coeff in dep.coefficients.items():
            if other not in index:
                raise ModelError(
                    f"joint {short_repr(name)} depends on unknown coordinate {short_repr(other)}; "
                    f"coordinates: {coords}")
            M[k, index[other]] += coeff
        c[k] = dep.offset
    return AffineMap(M, c)
