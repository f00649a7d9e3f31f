"""The base of the self-motion families: ``rows(t)`` and the points where a joint is at a value.

Shared by :mod:`~robokin.kinematics.ik.self_motion_families` (the swivel and
held-joint families) and :mod:`~robokin.kinematics.ik.self_motion_continued` (the
continued family of general 7R arms), which import it and not each other.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from robokin.kinematics.arm import Arm, Derived
from robokin.spatial import wrap_angle as _wrap

#: Rows of a slot at the same point are the same configuration within this [rad].
_SAME = 1e-6
_TWO_PI = 2 * np.pi


class _Family:
    """Branches of one pose: ``rows(t)`` and the exact points where a joint is at a value."""

    k = 8
    periodic = False
    domain: tuple[float, float]
    name: str
    joint: int | None
    robot: Arm

    def rows(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Q (m, k, n) (NaN where a branch has no point), valid (m, k), singular (m, k)."""
        raise NotImplementedError

    def slot_rows(self, t: np.ndarray, b: np.ndarray, read: np.ndarray | None = None
                  ) -> tuple[np.ndarray, np.ndarray]:
        """Slot b[i]'s row at t[i]: q (m, n) and valid (m,), for t (m,), b (m,) int.

        ``rows(t)`` read one slot per value, bit for bit; a family may compute less
        (the held closed form refines only these rows: ``_HeldFamily.slot_rows``).
        ``read`` (m,) bool: the rows whose joints the caller reads (default: all); of
        the others only ``valid`` is read, and their rows may come back unrefined.
        """
        q, valid, _ = self.rows(t)
        i = np.arange(len(q))
        return q[i, b], valid[i, b]

    def validity(self, t: np.ndarray) -> np.ndarray:
        """``rows(t)``'s valid (m, k) alone (a family may skip refining the rows)."""
        return self.rows(t)[1]

    def sample_rows(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``rows(t)`` for ``SelfMotion.sample`` and ``inside``.

        A family may follow its branches there instead of solving; the construction
        (intervals, folds, crossings) keeps ``rows``.
        """
        return self.rows(t)

    def candidates(self, j: int, value: float) -> list[tuple[float, np.ndarray | None]]:
        """Parameter values where joint j may equal ``value`` (with the configuration)."""
        raise NotImplementedError

    def param_of(self, q: np.ndarray) -> float:
        """The parameter value of a configuration q (n,) (of this pose or near it)."""
        assert self.joint is not None
        return float(q[self.joint])

    def points(self, queries: list[tuple[int, float]]) -> list[list[tuple[float, int]]]:
        """Per query (joint j, value): every (t, branch) where joint j equals value.

        The candidates of every query are evaluated in one batch; a branch takes a
        candidate when its joint j is at the value there (and its configuration is
        the candidate's, when the candidate has one).
        """
        cands = [self.candidates(j, v) for j, v in queries]
        ts = np.array([t for c in cands for t, _ in c], dtype=np.float64)
        out: list[list[tuple[float, int]]] = [[] for _ in queries]
        if not ts.size:
            return out
        q, valid, _ = self.rows(ts)
        # every candidate at once (elementwise, the same distances as one by one)
        of = [c for c, cand in enumerate(cands) for _ in cand]
        rows = [row for cand in cands for _, row in cand]
        has = np.array([row is not None for row in rows], dtype=bool)
        d = np.full(valid.shape, np.inf)
        with np.errstate(invalid="ignore"):
            if has.any():
                R = np.array([row for row in rows if row is not None])
                d[has] = np.abs(_wrap(q[has] - R[:, None, :])).max(-1)
            if not has.all():
                i = np.flatnonzero(~has)
                j = np.array([queries[of[c]][0] for c in i.tolist()])
                value = np.array([queries[of[c]][1] for c in i.tolist()])
                d[i] = np.abs(_wrap(q[i[:, None], :, j[:, None]][:, 0] - value[:, None]))
        d[~valid] = np.inf
        # a shoulder joint is shared by both wrist roots (and vice versa)
        for c, b in zip(*np.nonzero(d < _SAME), strict=True):
            out[of[c]].append((float(ts[c]), int(b)))
        return out


#: ``_shrunk``'s evaluate: (t (a,), brackets a (a,) int) -> (value (a,), same (a,) bool:
#: t belongs with the bracket's low end, ok (a,) bool: False gives the bracket up).
Side = Callable[[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray, np.ndarray]]
#: ``_shrunk``: every ``_PACE`` steps a bracket not shrunk 2^_PACE times takes a midpoint.
_PACE = 3
#: The width [in t] at which the self-motion's crossing and state brackets are done:
#: 4 ulps of 1 (a joint moving at 1e3 rad per unit of t, next to a singularity, is then
#: within 1e-12 of its value, the kernels' HM_TOL; elsewhere much closer).
FINE_T = 2.0 ** -50


def _shrunk(side: Side, lo: np.ndarray, hi: np.ndarray, f_lo: np.ndarray, f_hi: np.ndarray,
            steps: int, tol: float = 0.0, fine: float = 0.0
            ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Brackets [lo, hi] (p,) of a change of side, shrunk to two adjacent doubles.

    lo is the end of the known side; it may lie above hi (a run's start, bracketed from
    its in-limit node back to the node before).

    ``side(t, a)`` says for brackets a whether t is on the low end's side and gives a
    value that changes sign with the side (f_lo, f_hi (p,): the values at the ends;
    NaN where there is none). Each step takes the Illinois regula falsi point (the
    ends' values interpolated; an end kept twice running has its value halved); the
    midpoint where that point is not strictly inside or an end's value is not finite,
    and where the last ``_PACE`` steps did not shrink the bracket ``2^_PACE`` times
    (so it shrinks at least as fast as bisection's every ``_PACE + 1`` steps: ``steps``
    = 4 x bisection's reaches the same adjacent doubles); next to an end whose value
    is exactly 0 the neighbouring double, once per bracket. A smooth sign change takes ~8-11 steps
    against bisection's ~53, one with rounding noise of 1e-13 ~15 (27 at most in 300
    scratch trials): session 19, the continued family's crossings and state changes,
    each step a held solve (~1 ms next to a near-continuum). The bracket is
    bisection's where the side changes once in it; where rounding changes it several
    times within a few ulps, another of those changes. A bracket whose ends' values
    are both within ``tol`` of 0 is done as it is (the rows' own rounding: its
    remaining steps would pick among the noise's sign changes), and one at most
    ``fine`` wide (next to t = 0 the doubles are much closer than elsewhere; a jump of
    the rows, e.g. between a followed and a solved row, is no sign change regula falsi
    can close in on: measured at the offset iiwa's home pose, 1e-11 across one ulp).
    Returns ``(lo, hi, found)``: found False where ``side`` gave up. The arguments are
    not changed.
    """
    lo, hi = np.array(lo, dtype=np.float64), np.array(hi, dtype=np.float64)
    f_lo, f_hi = np.array(f_lo, dtype=np.float64), np.array(f_hi, dtype=np.float64)
    p = len(lo)
    found = np.ones(p, dtype=bool)
    kept = np.zeros(p, dtype=np.int8)  # the end the last step kept: 1 low, -1 high
    halve = np.zeros(p, dtype=bool)  # the next step at the midpoint
    since = np.zeros(p, dtype=np.int64)  # steps since the last pace check
    probed = np.zeros(p, dtype=bool)  # a zero end's neighbour tried
    width = np.abs(hi - lo)  # the width at the last pace check
    # the ends' own values (f_lo, f_hi are Illinois-halved): within tol at both, done
    near = np.abs(f_lo) <= tol
    near_hi = np.abs(f_hi) <= tol
    for _ in range(steps):
        mid = 0.5 * (lo + hi)
        a = np.flatnonzero(found & (mid != lo) & (mid != hi) & ~(near & near_hi)
                           & (np.abs(hi - lo) > fine))
        if not a.size:
            break
        la, ha, fl, fh = lo[a], hi[a], f_lo[a], f_hi[a]
        with np.errstate(all="ignore"):
            t = (la * fh - ha * fl) / (fh - fl)
            inside = (t > np.minimum(la, ha)) & (t < np.maximum(la, ha))  # (either order)
            t = np.where(halve[a] | ~inside, mid[a], t)  # (NaN: mid)
        # next to an exact zero its neighbouring double, once (a run of exact zeros is
        # then halved, not walked an ulp at a time)
        probe = ~probed[a] & ((fh == 0.0) | (fl == 0.0))
        t = np.where(probe & (fh == 0.0), np.nextafter(ha, la),
                     np.where(probe & (fl == 0.0), np.nextafter(la, ha), t))
        probed[a] |= probe
        f, same, ok = side(t, a)
        found[a] &= ok
        lo_new, hi_new = np.where(same, t, la), np.where(same, ha, t)
        close = np.abs(f) <= tol
        near[a], near_hi[a] = np.where(same, close, near[a]), np.where(same, near_hi[a], close)
        f_lo[a] = np.where(same, f, np.where(kept[a] == 1, 0.5 * fl, fl))
        f_hi[a] = np.where(same, np.where(kept[a] == -1, 0.5 * fh, fh), f)
        kept[a] = np.where(same, -1, 1)
        since[a] += 1
        check = since[a] >= _PACE
        halve[a] = check & (np.abs(hi_new - lo_new) > width[a] / 2.0 ** _PACE)
        width[a] = np.where(check, np.abs(hi_new - lo_new), width[a])
        since[a] = np.where(check, 0, since[a])
        lo[a], hi[a] = lo_new, hi_new
    return lo, hi, found


def seven_joint_serial(arm: Arm) -> bool:
    """Whether ``arm`` has a self-motion of the kind described here.

    Seven independent joints in a serial chain (no coupled or passive joints).
    """
    chain = arm.chain
    return arm.n == 7 and chain.n_chain == 7 and bool(chain.coupling.is_identity)


def _into_limits(robot: Arm, q: np.ndarray) -> np.ndarray:
    """Revolute angles shifted by 2 pi into the limits where that fits."""
    up_cap, down_cap = robot.derived(SHIFT_CAPS)
    if not ((q <= up_cap) | (q >= down_cap)).any():
        return q + 0.0  # (no angle can move: the usual case, 4 numpy calls, not 13)
    lo, hi = robot.limits[:, 0], robot.limits[:, 1]
    rev = np.asarray(robot.is_revolute, bool)
    up = rev & (q < lo) & (q + _TWO_PI <= hi)
    down = rev & (q > hi) & (q - _TWO_PI >= lo)
    # q + 2 pi up - 2 pi down, bit for bit (-0.0 becomes 0.0), the sparse shifts in place
    out: np.ndarray = q + 0.0
    np.add(out, _TWO_PI, out=out, where=up)
    np.subtract(out, _TWO_PI, out=out, where=down)
    return out


def _shift_caps(arm: Arm) -> tuple[np.ndarray, np.ndarray]:
    """(n,) each: ``_into_limits`` moves an angle q only where q <= the first or >= the second.

    A revolute angle moves up only where q < lo and q + 2 pi <= hi, so q <= min(lo,
    hi - 2 pi + 1e-6) (the 1e-6 covers the sum's rounding for |q| up to ~1e9), and
    down only where q >= max(hi, lo + 2 pi - 1e-6); other coordinates never
    (-inf, inf). Kernel rows in [-pi, pi) on limits narrower than 2 pi never reach
    them (the rtb-data iiwa14: -3.32 and 3.32), and ``_into_limits`` is then one
    test and a copy (issue 29, helper iiwapy30).
    """
    lo, hi = arm.limits[:, 0], arm.limits[:, 1]
    rev = np.asarray(arm.is_revolute, bool)
    with np.errstate(invalid="ignore"):
        up = np.where(rev, np.minimum(lo, hi - _TWO_PI + 1e-6), -np.inf)
        down = np.where(rev, np.maximum(hi, lo + _TWO_PI - 1e-6), np.inf)
    return up, down


#: Per arm: ``_shift_caps``' bounds (``_into_limits``' test).
SHIFT_CAPS: Derived[tuple[np.ndarray, np.ndarray]] = Derived("2 pi shift bounds", _shift_caps)
