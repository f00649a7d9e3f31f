r"""The chain as a product of exponentials: joint axes and points at zero joint value.

With every chain joint value ``v_k = 0`` (``J_k`` the identity) the frame just before
joint ``k`` is ``P_k = C_0 C_1 ... C_{k-1}`` (``Chain.frames_at``, the model's walk); its z axis is the joint's unit axis
``h_k`` and its origin a point ``o_k`` on it (base frame). Then

.. math::

    T(v) = e^{\hat\xi_1 v_1} \cdots e^{\hat\xi_n v_n} M, \qquad M = T(v = 0),

so a revolute joint rotates everything after it about the line ``(o_k, h_k)`` and a
prismatic one translates it along ``h_k``. Base and tool transforms are inside ``C_0``
and ``C_n`` (hence inside ``M``), so the closed forms never see them.

References:
    Lynch and Park, *Modern Robotics*, ch. 4 (product of exponentials);
    Elias and Wen, "IK-Geo: unified robot inverse kinematics using subproblem
    decomposition", arXiv:2211.05737 (2022).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from robokin.model.chain import Chain

__all__ = [
    "Poe",
    "angle_between_axes",
    "closest_point",
    "cross3",
    "line_distance",
    "poe_from_chain",
    "rotate_about",
    "subproblem_1",
    "subproblem_3",
    "subproblem_4",
]


@dataclass(frozen=True, eq=False)
class Poe:
    """Zero-configuration screw description of a chain.

    Attributes:
        h: Unit joint axes (n_chain, 3), base frame.
        o: A point on each axis (n_chain, 3) [m], base frame.
        prismatic: (n_chain,) bool.
        M: Tool pose at chain values 0, (4, 4).
    """

    h: np.ndarray
    o: np.ndarray
    prismatic: np.ndarray
    M: np.ndarray


def poe_from_chain(chain: Chain) -> Poe:
    """The chain's axes and points at ``v = 0`` (see the module docstring).

    The frames come from the model's one walk along the chain
    (:meth:`~robokin.model.chain.Chain.frames_at`), at the chain values that put
    every joint at ``v = 0`` (``q_chain = -sign * offset``, exact: signs are +-1),
    which exist for coupled chains too (no coordinates ``q`` need give them).
    """
    arr = chain.arrays
    frames = chain.frames_at(-arr.sign * arr.offset)
    nc = chain.n_chain
    h = np.empty((nc, 3))
    for k in range(nc):
        h[k] = frames[k, :3, 2] / np.linalg.norm(frames[k, :3, 2])
    o = frames[:nc, :3, 3].copy()
    return Poe(h, o, np.asarray(arr.kind, dtype=bool).copy(), frames[nc].copy())


def cross3(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The cross product of two 3-vectors (3,): ``np.cross(a, b)``, the same bits.

    The same products and differences in the same order as numpy's, on Python
    floats: about 1 µs where ``np.cross`` takes about 10 µs for one pair (the set-up
    of every new chain calls it a dozen times; ``tests/kinematics/ik/analytic``).
    """
    a0, a1, a2 = a.tolist()
    b0, b1, b2 = b.tolist()
    return np.array([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0])


def angle_between_axes(a: np.ndarray, b: np.ndarray) -> float:
    """Angle [rad] between two lines' directions, ignoring orientation (0..pi/2)."""
    s = np.linalg.norm(cross3(a, b))
    c = abs(float(np.dot(a, b)))
    return float(np.arctan2(s, c))


def line_distance(o1: np.ndarray, h1: np.ndarray, o2: np.ndarray, h2: np.ndarray) -> float:
    """Shortest distance [m] between the lines ``o1 + t h1`` and ``o2 + s h2``."""
    n = cross3(h1, h2)
    nn = np.linalg.norm(n)
    d = o2 - o1
    if nn < 1e-12:  # parallel lines
        return float(np.linalg.norm(d - np.dot(d, h1) * h1))
    return float(abs(np.dot(d, n)) / nn)


def closest_point(origins: np.ndarray, axes: np.ndarray) -> np.ndarray:
    """The point with the least summed squared distance to several lines, (3,)."""
    A = np.zeros((3, 3))
    b = np.zeros(3)
    for o, h in zip(origins, axes):
        P = np.eye(3) - np.outer(h, h)
        A += P
        b += P @ o
    return np.linalg.lstsq(A, b, rcond=None)[0]


def unit_perpendicular(h: np.ndarray) -> np.ndarray:
    """A unit vector perpendicular to ``h``."""
    e = np.eye(3)[int(np.argmin(np.abs(h)))]
    v: np.ndarray = e - np.dot(e, h) * h
    unit: np.ndarray = v / np.linalg.norm(v)
    return unit


def rotate_about(h: np.ndarray, ang: np.ndarray, v: np.ndarray) -> np.ndarray:
    """rot(h, ang) v for a fixed unit h; ang (...), v (..., 3) or (3,)."""
    c = np.cos(ang)[..., None]
    s = np.sin(ang)[..., None]
    out: np.ndarray = v * c + np.cross(h, v) * s + h * (v @ h)[..., None] * (1.0 - c)
    return out


def subproblem_1(h: np.ndarray, u: np.ndarray, d: np.ndarray) -> np.ndarray:
    """Paden-Kahan subproblem 1: the angle about ``h`` taking ``u`` towards ``d``.

    Onto ``d``'s direction, components along ``h`` ignored; broadcasts over
    leading axes.
    """
    ang: np.ndarray = np.arctan2(np.einsum("...i,...i", d, np.cross(h, u)),
                                 np.einsum("...i,...i", d, u) - (u @ h) * (d @ h))
    return ang


def subproblem_3(h: np.ndarray, a: np.ndarray, b: np.ndarray,
                 d: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Paden-Kahan subproblem 3: angles v with |a + rot(h, v) b| = |d|.

    Squared, it is subproblem 4: ``a . rot(h, v) b = (|d|^2 - |a|^2 - |b|^2) / 2``.

    Args:
        h: Unit axis, shape (3,).
        a: First link vector [m], shape (3,).
        b: Second link vector [m], shape (3,).
        d: Targets [m], shape (..., 3).

    Returns:
        ``(v (..., 2), disc (...), r2)`` as :func:`subproblem_4`.
    """
    return subproblem_4(h, a, b, 0.5 * (np.einsum("...i,...i", d, d) - a @ a - b @ b))


def subproblem_4(h: np.ndarray, p: np.ndarray, q: np.ndarray,
                 d: np.ndarray | float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Paden-Kahan subproblem 4: angles v with ``p . rot(h, v) q = d``.

    With ``A = p.q - (p.h)(h.q)``, ``B = p.(h x q)``, ``C = (p.h)(h.q)`` the
    equation is ``A cos v + B sin v = d - C``: ``v = atan2(B, A) +- atan2(sqrt(disc),
    d - C)`` with ``disc = A^2 + B^2 - (d - C)^2`` (the C twin: ``six_r.c``).

    Args:
        h: Unit axis, shape (3,).
        p: Vectors [m], shape (..., 3).
        q: Vector [m], shape (3,).
        d: Right-hand sides, shape (...).

    Returns:
        ``(v (..., 2), disc (...), r2)``: both roots (equal when ``disc`` = 0), the
        discriminant (< 0: no solution; the roots are then the nearest angles) and
        its scale ``r2 = A^2 + B^2``.
    """
    kq = h @ q
    A = p @ q - (p @ h) * kq
    B = p @ np.cross(h, q)
    C = (p @ h) * kq
    rhs = d - C
    r2 = A * A + B * B
    disc = r2 - rhs * rhs
    gam = np.arctan2(np.sqrt(np.maximum(disc, 0.0)), rhs)
    phi = np.arctan2(B, A)
    return np.stack([phi + gam, phi - gam], axis=-1), disc, r2
