"""The packed chain arrays (``model/chain_arrays.py``): the wrap flags.

Oracle: the definition written out one coordinate at a time with ``np.allclose``
(the form ``_wrap_flags`` had before it was vectorised): coordinate j wraps when it
is revolute and every chain joint it drives is revolute with a whole coefficient.
"""

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

import robokin
from robokin.model.chain_arrays import _wrap_flags
from robokin.robots import names


def _one_at_a_time(M, kind, is_revolute):
    out = np.zeros(M.shape[1])
    for j in range(M.shape[1]):
        col = M[:, j]
        used = col != 0.0
        out[j] = float(is_revolute[j] and np.all(kind[used] == 0.0)
                       and np.allclose(col[used], np.round(col[used])))
    return out


coefficient = st.sampled_from([0.0, -0.0, 1.0, -1.0, 2.0, 0.5, -0.5, 1.0 + 1e-9,
                               1.0 + 1e-4, 1e-9, 3.0, -2.0 + 2e-8, 1e5 + 0.5])


@settings(max_examples=100, deadline=None)
@given(st.integers(1, 8).flatmap(lambda nc: st.integers(1, nc).flatmap(
    lambda n: st.tuples(arrays(np.float64, (nc, n), elements=coefficient),
                        arrays(np.float64, (nc,), elements=st.sampled_from([0.0, 1.0])),
                        arrays(np.bool_, (n,))))))
def test_wrap_flags_follow_the_definition(case):
    M, kind, is_revolute = case
    np.testing.assert_array_equal(_wrap_flags(M, kind, is_revolute),
                                  _one_at_a_time(M, kind, is_revolute))


def test_wrap_flags_of_every_built_in_arm():
    for name in names():
        chain = robokin.load(name).chain
        M = np.asarray(chain.coupling.matrix, dtype=np.float64)
        kind = np.asarray(chain.arrays.kind)
        want = _one_at_a_time(M, kind, np.asarray(chain.is_revolute))
        np.testing.assert_array_equal(chain.arrays.wrap, want)
