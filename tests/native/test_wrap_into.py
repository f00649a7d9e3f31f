"""The one wrap-into-limits rule: chain.h ``wrap_into`` (kernel) and Python ``fit_turns``.

Oracle: an exhaustive search over whole turns written here from the rule's statement
(docs/conventions.md "Joint values and limits"): a value within [lo, hi] up to 1e-9
stays; else the candidate ``v + 2 pi k`` within them with the fewest turns |k|; else
``v``. The turn count chosen must match exactly; the value to 1e-12.
"""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from robokin._native import kernels as K
from robokin.kinematics.ik.analytic._common import fit_turns
from robokin.spatial import wrap_angle

SLACK = 1e-9
TP = 2.0 * np.pi
PI = np.pi


def _oracle(v: float, lo: float, hi: float) -> tuple[float, int]:
    """(value, turns) by the rule, searching k in [-40, 40] by increasing |k|."""
    if not np.isfinite(v) or lo - SLACK <= v <= hi + SLACK:
        return v, 0
    for m in range(1, 41):
        for k in (m, -m):
            u = v + k * TP
            if lo - SLACK <= u <= hi + SLACK:
                return u, k
    return v, 0


def _kernel(v: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    out = np.empty(len(v))
    K.wrap_into(np.ascontiguousarray(v, float), np.ascontiguousarray(lo, float),
                np.ascontiguousarray(hi, float), out)
    return out


def _check(v: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> None:
    got = _kernel(v, lo, hi)
    for x, a, b, g in zip(v, lo, hi, got):
        want, k = _oracle(float(x), float(a), float(b))
        if np.isnan(want):
            assert np.isnan(g)
            continue
        assert round((g - x) / TP) == k, (x, a, b, g, want)
        assert abs(g - want) <= 1e-12, (x, a, b, g, want)


# values users hit: angles at +-pi and 0, limits at +-pi, +-2pi, spans over a turn,
# values 1e-12 and 2e-9 outside a limit, an exact turn away, NaN
SPECIAL = [
    (PI, -PI, PI), (-PI, -PI, PI), (PI + 1e-12, -PI, PI), (-PI - 1e-12, -PI, PI),
    (PI + 2e-9, -PI, PI), (-PI - 2e-9, -PI, PI), (2 * PI + 1e-12, -2 * PI, 2 * PI),
    (-2 * PI - 1e-12, -2 * PI, 2 * PI), (2 * PI + 2e-9, -2 * PI, 2 * PI),
    (PI, -2 * PI, 2 * PI), (-PI, 0.0, 2 * PI), (0.0, 0.5, 5.0), (0.0, 0.5, 0.6),
    (1.0 + 1e-12, 0.0, 1.0), (-1e-12, 0.0, 1.0), (1.0 + TP, 0.0, 1.0),
    (1.0 - 3 * TP, 0.0, 1.0), (10.0, -7.0, 7.0), (-10.0, -7.0, 7.0),
    (3.0, 3.5, 3.5 + TP + 1e-3), (np.nan, -PI, PI), (5.0, 1.0, 1.0),
    (PI / 2, -PI / 2 - 1e-12, -PI / 2 + 1e-12), (0.0, 0.0, 0.0),
]


def test_special_values() -> None:
    """The rule on the special values (each row: v, lo, hi)."""
    a = np.array(SPECIAL)
    _check(a[:, 0], a[:, 1], a[:, 2])


def test_slack_keeps_values_just_outside() -> None:
    """1e-12 outside a limit stays put (before: moved by a turn where one fitted)."""
    got = _kernel(np.array([PI + 1e-12, 2 * PI + 1e-12]), np.array([-PI, -2 * PI]),
                  np.array([PI, 2 * PI]))
    assert got[0] == PI + 1e-12 and got[1] == 2 * PI + 1e-12


@settings(max_examples=60, deadline=None, derandomize=True, database=None)
@given(st.integers(0, 2**32 - 1))
def test_random_values(seed: int) -> None:
    """Uniform values and limits, spans from 0 to over two turns."""
    rng = np.random.default_rng(seed)
    n = 64
    lo = rng.uniform(-8.0, 8.0, n)
    hi = lo + rng.choice([0.0, 0.1, 1.0, TP - 1e-3, TP, TP + 1e-3, 3 * TP], n)
    v = rng.uniform(-30.0, 30.0, n)
    edge = rng.integers(0, 4, n)  # also at a limit, 1e-12 and 2e-9 beyond it
    v = np.where(edge == 1, hi + rng.choice([0.0, 1e-12, 2e-9, -1e-12], n), v)
    v = np.where(edge == 2, lo - rng.choice([0.0, 1e-12, 2e-9, -1e-12], n), v)
    _check(v, lo, hi)


def test_fit_turns_is_wrap_then_rule() -> None:
    """Python's fit_turns: revolute values wrapped to [-pi, pi) then the rule;
    prismatic ones untouched (oracle: _oracle on wrap_angle)."""
    rng = np.random.default_rng(7)
    limits = np.array([[-PI, PI], [-2 * PI, 2 * PI], [0.5, 5.0], [-0.2, 0.3],
                       [3.5, 3.5 + TP + 1e-3], [-1.0, 2.0]])
    is_rev = np.array([True, True, True, True, True, False])
    q = rng.uniform(-12.0, 12.0, (50, 3, 6))
    q[0, 0] = [PI, -2 * PI - 1e-12, 0.0, 0.3 + 1e-12, -PI, 7.0]
    got = fit_turns(q, is_rev, limits)
    assert got.shape == q.shape
    w = wrap_angle(q)
    for idx in np.ndindex(q.shape[:-1]):
        for j in range(6):
            if not is_rev[j]:
                assert got[idx][j] == q[idx][j]
                continue
            want, _ = _oracle(float(w[idx][j]), *limits[j])
            assert abs(got[idx][j] - want) <= 1e-12, (idx, j, got[idx][j], want)
