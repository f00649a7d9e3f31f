r"""6R chains with three consecutive intersecting axes (Pieper's case).

Axes 1, 2, 3 meet in a point S (a spherical shoulder: the Panda, SRS arms such as
the KUKA iiwa) or axes 4, 5, 6 meet in W (a spherical wrist) while the
``spherical_wrist`` family's other condition (axes 2, 3 parallel) does not hold.
The same closed form solves a 7R arm with one joint held at a value when the six
joints left have such a triple: the Panda with joint 4, 5, 6 or 7 held, an SRS
arm with joint 1, 2, 3, 5, 6 or 7 held. Up to 8 solutions.

On the chain's product of exponentials :math:`T = e^{\hat\xi_1\theta_1}\cdots
e^{\hat\xi_6\theta_6} M` (``_geometry``):

1. The triple only rotates about its point, so the point's image depends on the
   other three joints a, b, c alone: :math:`e_a e_b e_c\,p = d` with
   :math:`p = M T^{-1} S,\ d = S` (axes 4-6) or :math:`p = W,\ d = T M^{-1} W`
   (axes 1-3). With :math:`y = e_a^{-1} d` and :math:`z = e_c p`, a rotation about
   axis b takes z to y exactly when their heights along :math:`h_b` and their
   distances to a point :math:`o_b` of the axis agree: two equations
   :math:`P u_a - Q u_c = r`, linear in :math:`u = (\cos\theta, \sin\theta)` of
   joints a and c (Pieper 1968; Raghavan and Roth 1993).
2. :math:`\det Q` is the mutual moment of axes b, c times the squared distance of
   p from axis c (likewise P with axes a, b). When axes b, c are coplanar (they
   meet or are parallel) a fixed combination of the two rows holds
   :math:`\theta_a` alone: two subproblems 4 in turn, at most 2 x 2 solutions.
   The Panda with q7 given is this case (axes 5, 6 meet: He and Liu's closed
   form); so are SRS arms with a wrist joint held. Otherwise :math:`u_c` (or
   :math:`u_a`, whichever matrix is better conditioned) is eliminated and
   :math:`|u_c| = 1` leaves :math:`f(\theta_a) = 0`, a trigonometric polynomial of
   degree 2: a quartic in :math:`t = \tan((\theta_a - \delta)/2)`, the shift
   :math:`\delta` chosen so that the leading coefficient, :math:`f(\delta + \pi)`,
   is the largest of eight samples (never the vanishing leading coefficient of the
   plain half-angle substitution). Real roots are Newton-polished on f; a pair that
   rounding made complex with a small imaginary part (a double root) is restored
   from f's local quadratic at the extremum between them.
3. :math:`\theta_b` by subproblem 1; the triple from the orientation: its middle
   angle by subproblem 4 (two branches), the outer ones by subproblem 1. When the
   outer axes line up (Panda q2 = 0) only a sum (or difference) of the outer angles
   is fixed: the split is taken inside the joint limits, nearest ``q_near`` (or 0),
   and the row flagged ``singular``. The exact singular angle is used only where it
   reproduces the pose (to 1e-13); near-singular triples keep their exact split.

Every solution is checked against the pose (forward kinematics of the remaining
chain) and Newton-polished when its error exceeds 1e-13; one that stays above
1e-10 is not returned. Slots: ``slot = 2 * position + triple`` (``position`` 0-3
numbers the solutions of steps 1-2, in the coplanar case ``2 * first root + second
root``; ``triple`` 0/1 the '+'/'-' root of the middle angle), the same for every
pose and held value in the coplanar case, so a sweep of held values keeps its
branches in place (issue 29's self-motion curves).

A held joint k at value x turns every later axis, point and M about axis k by
x: the compiled kernel (``csrc/pieper.c``) builds the remaining chain per pose,
so a sweep of held values is one batch with no per-value set-up.

References:
    Pieper, "The kinematics of manipulators under computer control", PhD thesis,
    Stanford University, 1968.
    Raghavan and Roth, "Inverse kinematics of the general 6R manipulator and related
    linkages", J. Mech. Des. 115(3), 1993.
    He and Liu, "Analytical inverse kinematics for Franka Emika Panda - a geometrical
    solver for 7-DOF manipulators with unconventional design", ICCRE 2021.
    Elias and Wen, "IK-Geo", arXiv:2211.05737 (2022): subproblems 1-4.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from robokin._native import kernels as K
from robokin.kinematics.arm import Arm, ArmSource, arm_of
from robokin.kinematics.ik.analytic._common import (
    STATUS_TEXT,
    fk_error,
    read_only_joint_data,
)
from robokin.kinematics.ik.analytic._geometry import (
    Poe,
    angle_between_axes,
    closest_point,
    poe_from_chain,
)
from robokin.kinematics.ik.solutions import SolutionSet
from robokin.model.chain import Chain
from robokin.spatial import rotation_from_rotvec

__all__ = ["NAME", "FamilySolver", "Setup", "family_solver", "limit_params", "make_single", "measure",
           "raw_solve", "setup",
           "solve"]

NAME = "pieper"

#: Slot labels: position (0-3) and triple (+1 / -1 root of the middle angle).
LABELS = {
    "position": [0, 0, 1, 1, 2, 2, 3, 3],
    "triple": [1, -1, 1, -1, 1, -1, 1, -1],
}
_PARALLEL_MIN = K.PIEPER_PARALLEL_MIN


@dataclass(frozen=True, eq=False)
class Setup:
    """The kernel parameters of a chain (or of a 7R chain with one joint held).

    Attributes:
        params: The parameter vector (read-only), or None when the family does not
            apply.
        reason: Why it does not apply ("" when it does).
        measured: What was measured, e.g. "axes 1-3 meet within 2.2e-16 m".
        held: The held joint's index, or None.
    """

    params: np.ndarray | None
    reason: str = ""
    measured: str = ""
    held: int | None = None


def _meet(h: np.ndarray, o: np.ndarray) -> tuple[float, np.ndarray]:
    """Largest distance [m] of three lines from their closest common point, and it."""
    c = closest_point(o, h)
    dist = 0.0
    for hk, ok in zip(h, o, strict=True):
        d = c - ok
        dist = max(dist, float(np.linalg.norm(d - np.dot(d, hk) * hk)))
    return dist, c


def _turned(poe: Poe, held: int | None, value: float) -> tuple[np.ndarray, np.ndarray]:
    """Axes and points (6, 3) of the six joints left with joint ``held`` at ``value``.

    (The kernel does the same per pose: ``pk_geometry`` in ``csrc/pieper.c``.)
    """
    if held is None:
        return poe.h, poe.o
    R = rotation_from_rotvec(poe.h[held] * value)
    h = poe.h.copy()
    o = poe.o.copy()
    h[held + 1:] = h[held + 1:] @ R.T
    o[held + 1:] = (o[held + 1:] - poe.o[held]) @ R.T + poe.o[held]
    keep = [j for j in range(len(h)) if j != held]
    return h[keep], o[keep]


def _scale(poe: Poe) -> float:
    """The chain's length scale [m]: the summed distances of its axis points."""
    pts = np.vstack([poe.o, poe.M[:3, 3]])
    return float(max(np.linalg.norm(np.diff(pts, axis=0), axis=1).sum(), 1e-6))


def measure(poe: Poe, held: int | None = None) -> tuple[float, str, str]:
    """Deviation [m] of the best triple from meeting, text, why-not ("" if none).

    ``held``: the index of a joint held (removed) in a 7R chain.
    """
    n = len(poe.h)
    keep = [j for j in range(n) if j != held]
    if len(keep) != 6:
        return np.inf, f"{len(keep)} joints left", "the family needs six revolute joints"
    if poe.prismatic[keep].any():
        return np.inf, "a prismatic joint", "the family needs six revolute joints"
    found = []
    for name, idx in (("1-3", keep[:3]), ("4-6", keep[3:])):
        if held is not None and min(idx) < held < max(idx):
            continue  # a triple across the held joint meets only at some values
        dist, _ = _meet(poe.h[idx], poe.o[idx])
        found.append((dist, name))
    if not found:
        return np.inf, "no triple of consecutive joints left", "no triple"
    found.sort()
    scale = _scale(poe)
    texts = [f"axes {name} meet within {d:.1e} m" for d, name in found]
    return found[0][0] / max(1.0, scale), "; ".join(texts), ""


def setup(chain: Chain, held: int | None = None, *, tol: float = 1e-9,
          singular_tol: float = 1e-9) -> Setup:
    """The kernel parameters of ``chain`` (a 6R chain, or 7R with joint ``held`` held).

    Args:
        chain: The canonical chain (no dependent joints).
        held: Index of the held joint of a 7-joint chain; None for a 6R chain.
        tol: Distance [m, relative to the arm's length scale when that is over 1 m]
            within which three axes meet.
        singular_tol: The triple's singularity: sine of its outer axes' angle.

    Returns:
        A :class:`Setup`; ``params`` is None (with the reason) when the family does
        not apply: no triple meets, both triples meet (the remaining chain then moves
        in a one-parameter family at every reachable pose), or axes coincide.
    """
    if not chain.coupling.is_identity:
        return Setup(None, "dependent joints")
    n = chain.n_chain
    if (held is None and n != 6) or (held is not None and (n != 7 or not 0 <= held < 7)):
        return Setup(None, f"{n} chain joints" + (f", joint {held} held" if held is not None
                                                  else ""))
    poe = poe_from_chain(chain)
    if poe.prismatic.any():
        return Setup(None, "a prismatic joint")
    keep = [j for j in range(n) if j != held]
    scale = _scale(poe)
    lim = tol * max(1.0, scale)
    meets = {}
    for case, idx in ((K.PIEPER_START, keep[:3]), (K.PIEPER_END, keep[3:])):
        if held is not None and min(idx) < held < max(idx):
            continue
        dist, point = _meet(poe.h[idx], poe.o[idx])
        if dist <= lim:
            meets[case] = (dist, point, idx)
    if held is not None:  # an SRS arm: the whole chain's shoulder 1-3 and wrist 5-7 meet
        whole = {case: (dist, point, idx) for case, idx in
                 ((K.PIEPER_START, [0, 1, 2]), (K.PIEPER_END, [4, 5, 6]))
                 for dist, point in [_meet(poe.h[idx], poe.o[idx])] if dist <= lim}
        if len(whole) == 2:
            meets = whole
    if not meets:
        return Setup(None, "no three consecutive axes meet: " + measure(poe, held)[1])
    both = len(meets) == 2
    case, (dist, point, idx) = next(iter(meets.items()))
    h, o = _turned(poe, held, 1.2345)  # a held value where nothing lines up by chance
    for i in range(5):
        if angle_between_axes(h[i], h[i + 1]) < 1e-6 and np.linalg.norm(
                np.cross(o[i + 1] - o[i], h[i])) < lim:
            return Setup(None, f"axes {i + 1} and {i + 2} of the six coincide")
    P = _chain_params(chain, poe, held, scale)
    P[K.PIEPER_CASE] = K.PIEPER_BOTH if both else case
    if both:
        P[K.PIEPER_POINT2:K.PIEPER_POINT2 + 3] = meets[K.PIEPER_END][1]
    P[K.PIEPER_SING_TOL] = singular_tol
    P[K.PIEPER_POINT:K.PIEPER_POINT + 3] = point
    P.setflags(write=False)
    which = "1-3" if case == K.PIEPER_START else "4-6"
    text = f"axes {which} meet within {dist:.1e} m"
    if both:
        text = (f"axes 1-3 and 5-7 meet within {max(d for d, _, _ in meets.values()):.1e}"
                " m (an SRS arm: solved on its swivel)")
    return Setup(P, measured=text, held=held)


def _chain_params(chain: Chain, poe: Poe, held: int | None, scale: float) -> np.ndarray:
    """The chain part of a parameter vector (writable).

    Axes, points, tool, the joints' signs, offsets and limits, the held joint and
    the length scale: what every kernel path reads, triple or not.
    """
    n = chain.n_chain
    P = np.zeros(K.PIEPER_N_PARAMS)
    P[K.PIEPER_N] = n
    P[K.PIEPER_HELD] = -1 if held is None else held
    P[K.PIEPER_SCALE] = scale
    P[K.PIEPER_AXES:K.PIEPER_AXES + 3 * n] = poe.h.ravel()
    P[K.PIEPER_POINTS:K.PIEPER_POINTS + 3 * n] = poe.o.ravel()
    P[K.PIEPER_TOOL_R:K.PIEPER_TOOL_R + 9] = poe.M[:3, :3].ravel()
    P[K.PIEPER_TOOL_T:K.PIEPER_TOOL_T + 3] = poe.M[:3, 3]
    P[K.PIEPER_SIGN:K.PIEPER_SIGN + n] = chain.arrays.sign
    P[K.PIEPER_OFFSET:K.PIEPER_OFFSET + n] = chain.arrays.offset
    lims = np.asarray(chain.limits, dtype=np.float64)
    P[K.PIEPER_LO:K.PIEPER_LO + n] = lims[:, 0]
    P[K.PIEPER_HI:K.PIEPER_HI + n] = lims[:, 1]
    P[K.PIEPER_TAG] = K.PIEPER_TAG_VALUE
    return P


def limit_params(chain: Chain, held: int) -> np.ndarray | None:
    """The parameter vector of ``pieper_limit_rows`` for a 7R chain with joint ``held`` held.

    No meeting triple is needed: the kernel's last resorts (``pk_walk``, ``pk_pin``)
    read only the chain, its limits and the held joint. None for anything but an
    all-revolute 7R chain without dependent joints.
    """
    if not chain.coupling.is_identity or chain.n_chain != 7 or not 0 <= held < 7:
        return None
    poe = poe_from_chain(chain)
    if poe.prismatic.any():
        return None
    P = _chain_params(chain, poe, held, _scale(poe))
    P[K.PIEPER_CASE] = K.PIEPER_START  # read by no last resort
    P.setflags(write=False)
    return P


_NO_VALUE = np.zeros(1)
_NO_VALUE.setflags(write=False)


def raw_solve(params: np.ndarray, T: np.ndarray, values: np.ndarray | None = None,
              qn: np.ndarray | None = None) -> tuple[np.ndarray, ...]:
    """The bare kernel call, without input checks.

    Args:
        params: From :func:`setup`.
        T: Poses (N, 4, 4), C-contiguous float64.
        values: Held values (m,) [rad], pose i taking ``values[i % m]``; None without a
            held joint.
        qn: Preferred coordinates (mq, n) at singularities, row ``i % mq``; None: 0.

    Returns:
        ``(Q (N, 8, n), valid, singular, within_limits (N, 8), status (N,) int8)``.
    """
    n = int(params[K.PIEPER_N])
    x = _NO_VALUE if values is None else values
    return K.pieper_ik(params, T, x, np.zeros((1, n)) if qn is None else qn)


_DEGENERATE = "no solution: the position equations are degenerate at this held value"


def _status(codes: np.ndarray) -> np.ndarray:
    """Status texts of the kernel's codes (0-2 as the 6R closed forms, 5 degenerate)."""
    codes = np.asarray(codes)
    text = np.asarray(STATUS_TEXT[np.minimum(codes, len(STATUS_TEXT) - 1)], dtype=object)
    text[codes == K.PIEPER_DEGENERATE] = _DEGENERATE
    return text


def solve(robot: Arm, T: np.ndarray, q_near: np.ndarray | None, *, params: np.ndarray,
          method: str, info: dict[str, Any], values: np.ndarray | None = None,
          compute_error: bool = False) -> SolutionSet:
    """Every solution for poses T (..., 4, 4), held values broadcast with them.

    Args:
        robot: The robot whose chain ``params`` was set up from.
        T: Validated poses (..., 4, 4).
        q_near: Preferred configurations (..., n) at singularities, or None.
        params: From :func:`setup`.
        method: The set's ``method`` text.
        info: The set's ``info``.
        values: Held values broadcasting with the poses' leading shape (held joint
            only).
        compute_error: Also give each solution's FK error ``hypot(dp, dr)``.

    Returns:
        The :class:`SolutionSet` of the whole chain (the held column holds its value).
    """
    T = np.asarray(T, dtype=np.float64)
    n = int(params[K.PIEPER_N])
    lead = T.shape[:-2]
    x = None
    if values is not None:
        v = np.asarray(values, dtype=np.float64)
        lead = np.broadcast_shapes(lead, v.shape)
        x = np.ascontiguousarray(np.broadcast_to(v, lead).reshape(-1))
    Tf = np.ascontiguousarray(np.broadcast_to(T, lead + (4, 4)).reshape(-1, 4, 4))
    qn = None
    if q_near is not None:
        qa = np.asarray(q_near, dtype=np.float64)
        qn = np.ascontiguousarray(qa.reshape(1, n) if qa.ndim == 1 else
                                  np.broadcast_to(qa, lead + (n,)).reshape(-1, n))
    Q, valid, sing, inside, status = raw_solve(params, Tf, x, qn)
    Q = Q.reshape(lead + (8, n))
    valid = valid.reshape(lead + (8,))
    error = None
    if compute_error:
        dp, dr = fk_error(robot.chain, Q, Tf.reshape(lead + (4, 4)))
        error = np.where(valid, np.hypot(dp, dr), np.inf)
    branches = {k: np.broadcast_to(np.asarray(v, dtype=np.int8), lead + (8,))
                for k, v in LABELS.items()}
    return SolutionSet._trusted(
        Q, valid, np.array(robot.is_revolute, dtype=bool), robot.limits,
        {"within_limits": inside.reshape(lead + (8,)),
         "singular": sing.reshape(lead + (8,))},
        branches, _status(status).reshape(lead), method, error, dict(info))


def make_single(chain: Chain, params: np.ndarray, *, method: str,
                info: dict[str, Any], held: str | None = None) -> Any:
    """The single-pose hot path: ``single(T, x, qn) -> SolutionSet | None``.

    ``T`` (4, 4) float64 is validated inside the compiled call; ``x`` is the held
    value (ignored without a held joint), ``qn`` None or a float64 (n,) array.
    ``None`` means T is not a float64 (4, 4) rigid transform or x not finite (the
    caller re-checks to raise the detailed error). With ``held`` (the held joint's
    name) each set's ``info["held"]`` is ``{held: x}``.
    """
    solve1 = K.pieper_ik1
    is_rev, limits = read_only_joint_data(chain)
    labels = {k: np.asarray(v, dtype=np.int8) for k, v in LABELS.items()}
    for v in labels.values():
        v.setflags(write=False)
    # one read-only 0-d status array per code, shared by the sets (building one per
    # call, np.array(text, dtype=object), was 0.2-0.45 us of a 5 us call)
    texts = tuple(np.array(t, dtype=object) for t in _status(np.arange(K.PIEPER_DEGENERATE + 1)))
    for t in texts:
        t.setflags(write=False)
    trusted = SolutionSet._trusted
    too_far = K.PIEPER_BAD_POSE

    def single(T: np.ndarray, x: float, qn: np.ndarray | None) -> SolutionSet | None:
        code, Q, valid, sing, inside = solve1(T, params, x, qn)
        if code >= too_far or Q is None or valid is None or sing is None or inside is None:
            return None
        out = info.copy()  # each set its own dicts (a caller may change them)
        if held is not None:
            out["held"] = {held: x}
        return trusted(Q, valid, is_rev, limits,
                       {"within_limits": inside, "singular": sing}, labels.copy(),
                       texts[code], method, None, out)

    return single


@dataclass(frozen=True, eq=False)
class FamilySolver:
    """The family's solver for ``detect``: ``solver(robot, T, q_near=None, **options)``.

    Options: ``compute_error`` (bool). :meth:`single` is the dispatcher's
    single-pose hot path.

    Attributes:
        params: From :func:`setup`.
        method: The sets' ``method`` text.
        info: The sets' ``info``.
        one: ``make_single``'s function.
    """

    params: np.ndarray
    method: str
    info: dict[str, Any]
    one: Any

    def __call__(self, robot: ArmSource, T: np.ndarray, q_near: np.ndarray | None = None, *,
                 compute_error: bool = False) -> SolutionSet:
        """Every solution for poses T (..., 4, 4); see :func:`solve`."""
        return solve(arm_of(robot), T, q_near, params=self.params, method=self.method,
                     info=self.info, compute_error=compute_error)

    def single(self, T: np.ndarray, q6: float) -> SolutionSet | None:
        """One pose (4, 4) without ``q_near`` (``q6 == 0``), else None.

        None also means T is not a rigid transform; the dispatcher then takes the
        checked path, which passes the whole ``q_near``.
        """
        return self.one(T, 0.0, None) if q6 == 0.0 else None


def family_solver(chain: Chain, setup: Setup) -> FamilySolver:
    """The :class:`FamilySolver` of a chain set up by :func:`setup`."""
    params = setup.params
    if params is None:
        raise ValueError(f"no Pieper parameters: {setup.reason}")
    method = f"analytic:{NAME}"
    info = {"family": NAME, "measured": setup.measured, "near_family": False}
    return FamilySolver(params, method, info,
                        make_single(chain, params, method=method, info=info))
