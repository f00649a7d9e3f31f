"""Batch forward kinematics on the canonical chain.

``q`` has shape ``(..., n)`` (independent joint coordinates, SI units); results keep
the leading shape. The compiled kernels load on first use.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from robokin._validation import check_finite, check_joints
from robokin.exceptions import InputError
from robokin.model.chain import Chain

__all__ = ["forward_kinematics", "forward_kinematics_all", "link_frames"]

# Below this many configurations one thread beats the parallel launch overhead.
_PARALLEL_MIN = 2048


_KERNELS: list = []
_SINGLE: list = []
_F64 = np.dtype(np.float64)

try:  # the optional C accelerator for one configuration (setup.py builds it)
    from robokin.kinematics._fk_single import fk as fk_single_c
except ImportError:  # no C compiler at install time: the numba kernel serves
    fk_single_c = None


def single_kernel():
    """The compiled single-configuration FK ``fn(q, packed, T_out) -> bool``.

    Calls the compiled entry point directly (skipping numba's type dispatch: the
    signature is fixed), falling back to the dispatcher if numba hides it.
    """
    if not _SINGLE:
        disp = _kernels().fk_packed
        try:
            fn = next(iter(disp.overloads.values())).entry_point
        except (AttributeError, StopIteration):  # pragma: no cover - numba internals
            fn = disp
        _SINGLE.append(fn)
    return _SINGLE[0]


def _kernels():
    if not _KERNELS:
        from robokin.kinematics import _kernels

        _KERNELS.append(_kernels)
    return _KERNELS[0]


def _chain_values(chain: Chain, q: np.ndarray) -> np.ndarray:
    qc = chain.coupling.apply(q)
    return np.ascontiguousarray(qc.reshape(-1, chain.n_chain))


def _raise_nonfinite(q: np.ndarray, name: str) -> None:
    check_finite(q, name)
    raise InputError(
        name, "produced a non-finite chain joint value"
    )  # pragma: no cover


def forward_kinematics(
    chain: Chain, q: npt.ArrayLike, *, name: str = "q"
) -> np.ndarray:
    """Tool pose in the world frame.

    Args:
        chain: The canonical chain.
        q: Joint coordinates [rad or m], shape (..., n).
        name: The argument name used in error messages.

    Returns:
        Poses (..., 4, 4).

    Raises:
        InputError: wrong shape or a non-finite value.
    """
    if fk_single_c is not None and chain._single_shape is not None:
        # One configuration: None unless q is a float64 (n,) array of finite values.
        T = fk_single_c(q, chain._packed)
        if T is not None:
            return T
    elif type(q) is np.ndarray and q.shape == chain._single_shape and q.dtype is _F64:
        # One configuration: validation is the kernel's own finiteness test.
        T = np.empty((4, 4))
        if single_kernel()(q, chain._packed, T):
            return T
    q = check_joints(q, chain.n, name)
    qc = _chain_values(chain, q)
    out = np.empty((qc.shape[0], 4, 4))
    k = _kernels()
    fn = k.fk_parallel if qc.shape[0] >= _PARALLEL_MIN else k.fk_serial
    if not fn(qc, chain._consts, chain._xform, chain._joints, out):
        _raise_nonfinite(q, name)
    return out.reshape(q.shape[:-1] + (4, 4))


def link_frames(chain: Chain, q: npt.ArrayLike, *, name: str = "q") -> np.ndarray:
    """Base, every link frame and the tool pose: (..., n_chain + 2, 4, 4)."""
    q = check_joints(q, chain.n, name)
    qc = _chain_values(chain, q)
    nc = chain.n_chain
    out = np.empty((qc.shape[0], nc + 2, 4, 4))
    first = chain.base @ chain.head
    ok = _kernels().fk_all_serial(
        qc,
        first,
        chain.frame_offsets,
        chain.link_offsets,
        chain.tool,
        chain._joints,
        out,
    )
    if not ok:
        _raise_nonfinite(q, name)
    out[:, 0] = chain.base
    return out.reshape(q.shape[:-1] + (nc + 2, 4, 4))


def forward_kinematics_all(
    chain: Chain, q: npt.ArrayLike, *, name: str = "q"
) -> np.ndarray:
    """The base frame, then the link frame of every chain joint.

    Args:
        chain: The canonical chain.
        q: Joint coordinates, shape (..., n).
        name: The argument name used in error messages.

    Returns:
        Frames (..., n_chain + 1, 4, 4). For arms without dependent joints
        ``n_chain == n``. The tool pose is :func:`forward_kinematics`.
    """
    return link_frames(chain, q, name=name)[..., :-1, :, :]
