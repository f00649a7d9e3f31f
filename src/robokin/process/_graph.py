"""The layered graph of a process path: every IK solution of every sampled tool pose.

Layer i holds the nodes of waypoint i: for each of the K sampled rotations about the
tool's free axis, the k solution slots of the IK (``robot.ik`` on the whole batch
of sampled poses, in chunks), so node ``a * k + s`` is slot s of rotation a. The
compiled kernel ``process_nodes`` turns each node into its canonical joint values,
a status (usable, no solution, outside the limits, singular), its relative
manipulability and its cost (``robokin.process.costs``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from robokin import _native
from robokin.exceptions import InputError

if TYPE_CHECKING:
    from robokin.process._inputs import ToolSamples
    from robokin.process.costs import Costs
    from robokin.robot import Robot

__all__ = ["ArmFacts", "Layers", "arm_facts", "build_layers", "node_costs"]

_REF_SAMPLES = 4096  # configurations the reference manipulability is the best of
_REF_SEED = 20270  # their fixed seed: the same reference on every call
_CHUNK = 32768  # sampled poses per IK call (bounds the temporaries)


@dataclass(frozen=True, eq=False)
class ArmFacts:
    """What the process search needs to know about one arm, derived per call.

    Attributes:
        robot: The robot (in the world frame of the poses).
        packed: Its chain's packed arrays (the kernels' input).
        limits: Joint limits (n, 2) [rad, m].
        wraps: (n,) bool: a whole turn of the coordinate is a symmetry of the chain
            (chain.h's ``wrap``).
        circle: (n,) bool: wraps, and the limits span a turn or more, so every angle
            has a value inside them (searched on the circle; the turn is chosen
            afterwards, ``_turns.py``).
        mu_ref: The largest manipulability on a fixed sample of configurations: the
            reference the relative manipulability divides by.
        spin: +1 or -1 when turning the tool about its own z axis by an angle is
            turning the last joint by (+-) that angle (the tool's z axis is the last
            joint's axis, which wraps: a flange tool, a torch or drill along the
            flange axis); 0 otherwise. Then the IK of a waypoint at every sampled
            tool rotation is the IK at the first one with the last joint shifted
            (``build_layers``).
    """

    robot: Robot
    packed: np.ndarray
    limits: np.ndarray
    wraps: np.ndarray
    circle: np.ndarray
    mu_ref: float
    spin: int = 0

    @property
    def n(self) -> int:
        """Joint coordinates."""
        return int(self.limits.shape[0])

    def modes(self, expanded: frozenset[int] = frozenset()) -> np.ndarray:
        """The kernel's per-coordinate modes; ``expanded`` circle joints are plain."""
        k = _native.kernels
        mode = np.full(self.n, k.PM_PLAIN, dtype=np.uint8)
        mode[self.wraps] = k.PM_TURN
        mode[self.circle] = k.PM_CIRCLE
        for j in expanded:
            mode[j] = k.PM_PLAIN
        return mode


def arm_facts(robot: Robot) -> ArmFacts:
    """The :class:`ArmFacts` of ``robot`` (one batch of 4,096 Jacobians)."""
    arrays = robot.chain.arrays
    limits = np.asarray(robot.limits, dtype=np.float64)
    wraps = np.asarray(arrays.wrap, dtype=bool) & np.asarray(robot.is_revolute, dtype=bool)
    span = limits[:, 1] - limits[:, 0]
    circle = wraps & (span >= 2.0 * math.pi - 1e-12)
    rng = np.random.default_rng(_REF_SEED)
    q = rng.uniform(arrays.seed_lower, arrays.seed_upper, (_REF_SAMPLES, robot.n))
    facts = ArmFacts(robot, arrays.packed, limits, wraps, circle, 1.0)
    mode = np.zeros(robot.n, dtype=np.uint8)
    ok = np.ones(_REF_SAMPLES, dtype=bool)
    weights = np.zeros(_native.kernels.PW_N)
    weights[_native.kernels.PW_MU_REF] = 1.0
    out = node_costs(facts, q, ok, ~ok, mode, weights)
    mu = out[2]
    mu_ref = float(np.nanmax(mu)) if np.isfinite(mu).any() else 0.0
    return ArmFacts(robot, arrays.packed, limits, wraps, circle, mu_ref,
                    _spin(robot, wraps, q[:2]))


def _spin(robot: Robot, wraps: np.ndarray, q: np.ndarray) -> int:
    """+-1 when FK(q + d e_n) = FK(q) Rz(+-d) for the last coordinate n, else 0.

    For a serial chain FK = A(q_1..q_{n-1}) R_n(q_n) C; the identity holds for all q
    and d exactly when C^-1 R_n(d) C = Rz(+-d), a property of the constant C alone,
    so checking it at two configurations and one angle (to 1e-12) decides it. Only
    for arms whose IK returns every solution (closed form, general 6R): a numeric
    IK's answers depend on the pose, so the shifted set would not be its set.
    """
    from robokin.spatial import rotz

    chain = robot.chain
    if (not chain.coupling.is_identity or not bool(wraps[-1])
            or not bool(robot.is_revolute[-1])):
        return 0
    method = str(robot.ik(robot.fk(q[0])).method)
    if not method.startswith(("analytic", "general_6r")):
        return 0
    d = 0.7
    q2 = q.copy()
    q2[:, -1] += d
    T1, T2 = robot.fk(q), robot.fk(q2)
    for sign in (1, -1):
        if np.abs(T1 @ rotz(sign * d) - T2).max() <= 1e-12:
            return sign
    return 0


def node_costs(
    facts: ArmFacts,
    Q: np.ndarray,
    valid: np.ndarray,
    singular: np.ndarray,
    mode: np.ndarray,
    weights: np.ndarray,
    out: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray] | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Run ``process_nodes`` on P nodes: ``(Qc (P, n), cost, mu, code (P,))``.

    ``out`` (views of preallocated, C-contiguous arrays) receives the results when
    given.
    """
    P, n = Q.shape
    if out is None:
        out = (np.empty((P, n)), np.empty(P), np.empty(P), np.empty(P, dtype=np.int8))
    _native.kernels.process_nodes(
        facts.packed, np.ascontiguousarray(Q, dtype=np.float64),
        np.ascontiguousarray(valid, dtype=bool), np.ascontiguousarray(singular, dtype=bool),
        mode, weights, *out)
    return out


@dataclass(frozen=True, eq=False)
class Layers:
    """The nodes of every waypoint (L layers of M = K k nodes).

    Attributes:
        Q: Canonical joint values (L, M, n) [rad, m] (circle joints in [-pi, pi)).
        cost: Node costs (L, M); inf where not usable.
        mu: Relative manipulability (L, M) (NaN where not computed).
        code: Status (L, M) int8: the kernel's ``PN_*``.
        singular_ik: (L, M) bool: flagged singular by the IK.
        slots: k, the IK's solution slots per sampled pose.
        samples: The sampled tool rotations (K of them).
        mode: The kernel modes the layers were computed with (n,).
    """

    Q: np.ndarray
    cost: np.ndarray
    mu: np.ndarray
    code: np.ndarray
    singular_ik: np.ndarray
    slots: int
    samples: ToolSamples
    mode: np.ndarray

    @property
    def shape(self) -> tuple[int, int]:
        """(L, M)."""
        L, M = self.cost.shape
        return int(L), int(M)

    def angle_of(self, node: np.ndarray) -> np.ndarray:
        """The free-axis angle [rad] of node indices (NaN for -1)."""
        a = self.samples.angles[np.clip(node, 0, None) // self.slots]
        return np.where(node >= 0, a, np.nan)


def _solve_chunk(robot: Robot, T: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Every IK solution of poses T (P, 4, 4): q (P, k, n), valid, singular (P, k)."""
    sols = robot.ik(T)
    q = np.asarray(sols.q, dtype=np.float64)
    return q, np.asarray(sols.valid, dtype=bool), np.asarray(sols.singular, dtype=bool)


def _solve_rotated(facts: ArmFacts, poses: np.ndarray, samples: ToolSamples
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Every IK solution of poses (c, 4, 4) at every sampled tool rotation.

    Returns q (c K, k, n), valid and singular (c K, k), rotation-major per pose.
    With ``facts.spin`` the IK runs once per pose (at the first rotation) and the
    last joint is shifted by the other rotations' angles (the same solutions: the
    wrist centre does not move, so reach, branches and singularity are the same;
    the node kernel puts the shifted joint into its turn).
    """
    K = samples.count
    if facts.spin == 0 or K == 1:
        T = poses[:, None] @ samples.rotations  # (c, K, 4, 4)
        return _solve_chunk(facts.robot, T.reshape(-1, 4, 4))
    q0, valid, sing = _solve_chunk(facts.robot, poses @ samples.rotations[0])
    c, k, n = q0.shape
    q = np.repeat(q0[:, None], K, axis=1)  # (c, K, k, n)
    q[..., n - 1] += facts.spin * (samples.angles - samples.angles[0])[None, :, None]
    return (q.reshape(c * K, k, n), np.repeat(valid[:, None], K, axis=1).reshape(c * K, k),
            np.repeat(sing[:, None], K, axis=1).reshape(c * K, k))


def build_layers(
    facts: ArmFacts, poses: np.ndarray, samples: ToolSamples, costs: Costs
) -> Layers:
    """IK of every sampled pose and the node kernel, chunk by chunk.

    Args:
        facts: The arm.
        poses: Tool poses (L, 4, 4) [m] in the robot's world frame.
        samples: The tool rotations tried at each waypoint.
        costs: The objective's weights.

    Returns:
        The :class:`Layers`.
    """
    L, K, n = poses.shape[0], samples.count, facts.n
    mode = facts.modes()
    weights = costs.node_weights(facts.mu_ref)
    per_chunk = max(1, _CHUNK // K)
    arrays: list[np.ndarray] = []
    k = 0
    for a in range(0, L, per_chunk):
        b = min(L, a + per_chunk)
        q, valid, sing = _solve_rotated(facts, poses[a:b], samples)
        if not arrays or q.shape[1] > k:
            arrays = _grow(arrays, L, K, q.shape[1], n)
            k = q.shape[1]
        q, valid, sing = _pad(q, valid, sing, k)
        Qc, cost, mu, code, sing_ik = arrays
        out = (Qc[a:b].reshape(-1, n), cost[a:b].reshape(-1), mu[a:b].reshape(-1),
               code[a:b].reshape(-1))
        node_costs(facts, q.reshape(-1, n), valid.reshape(-1), sing.reshape(-1), mode,
                   weights, out)
        sing_ik[a:b] = sing.reshape(b - a, K * k)
    Qc, cost, mu, code, sing_ik = arrays
    return Layers(Qc, cost, mu, code, sing_ik, k, samples, mode)


def _grow(arrays: list[np.ndarray], L: int, K: int, k: int, n: int) -> list[np.ndarray]:
    """Arrays for k slots per sampled pose, keeping what ``arrays`` already hold."""
    if k == 0:
        k = 1  # an IK that found nothing anywhere: one empty slot
    M = K * k
    if not arrays:
        # every row is written by the node kernel (all its fields, every slot) and
        # sing_ik row by row, chunk by chunk: no fill (it was 40 % of the time of a
        # 5,000-waypoint path with 37 rotations: 107 MB of page faults)
        return [np.empty((L, M, n)), np.empty((L, M)), np.empty((L, M)),
                np.empty((L, M), dtype=np.int8), np.empty((L, M), dtype=bool)]
    new = [np.full((L, M, n), np.nan), np.full((L, M), np.inf), np.full((L, M), np.nan),
           np.full((L, M), _native.kernels.PN_NONE, dtype=np.int8),
           np.zeros((L, M), dtype=bool)]
    k0 = arrays[1].shape[1] // K
    for old, fresh in zip(arrays, new, strict=True):
        shape = (L, K, k0) + old.shape[2:]
        fresh.reshape((L, K, k) + old.shape[2:])[:, :, :k0] = old.reshape(shape)
    return new


def _pad(q: np.ndarray, valid: np.ndarray, sing: np.ndarray,
         k: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The IK output padded with empty slots to k per pose."""
    extra = k - q.shape[1]
    if extra <= 0:
        return q, valid, sing
    P, n = q.shape[0], q.shape[2]
    return (np.concatenate([q, np.full((P, extra, n), np.nan)], axis=1),
            np.concatenate([valid, np.zeros((P, extra), bool)], axis=1),
            np.concatenate([sing, np.zeros((P, extra), bool)], axis=1))


def check_size(L: int, K: int) -> None:
    """Refuse more sampled poses than one call may hold (``MAX_SAMPLES``)."""
    from robokin.process._inputs import MAX_SAMPLES

    if L * K > MAX_SAMPLES:
        raise InputError("poses", f"{L} waypoints x {K} tool rotations = {L * K:,} "
                         f"sampled poses; at most {MAX_SAMPLES:,} per call (split the "
                         "path, or sample the free axis more coarsely)")
