"""The numeric solver's inputs: the task mask, the kernel's option vector, input checks.

:func:`parse_mask` reads the task mask users write (``"xyz rz"``, six booleans);
:func:`option_vector` packs the options of :func:`~robokin.kinematics.ik.numeric.solve`
into the vector the compiled descent reads (``csrc/lm.c``, indices ``K.O_*``);
the checks name the argument that is wrong.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
import numpy.typing as npt

from robokin import _native
from robokin._validation import _real_array, check_finite, check_transform
from robokin.exceptions import InputError
from robokin.kinematics.ik.restart_seeds import SEED_SHRINK, TABLE_ROT

__all__ = [
    "AXES", "bad_input", "bad_target", "check_count", "check_positive", "flat_targets",
    "mask_names", "option_vector", "parse_mask",
]

#: The task rows, in the kernel's order.
AXES = ("x", "y", "z", "rx", "ry", "rz")

K = _native.kernels  # option indices and result columns


def _fixed_entries() -> np.ndarray:
    """The option vector's entries no argument sets (the rest zero)."""
    opts = np.zeros(K.N_OPTS)
    for index, value in (
        (K.O_PATH_MAX_JUMP, np.inf),  # no jump check (ik_path sets one)
        (K.O_STALL_EVERY, 3),  # a descent stalls when E has not fallen to
        (K.O_STALL_RATIO, 0.3),  # 0.3 times its value of 3 iterations before
        (K.O_MU0, 1e-2),  # initial damping, lambda = mu * E
        (K.O_MU_DOWN, 0.7),  # mu after an accepted step
        (K.O_MU_UP, 16.0),  # ... after a rejected one
        (K.O_SEED_SHRINK, SEED_SHRINK),
    ):
        opts[index] = value
    opts.setflags(write=False)
    return opts


_FIXED = _fixed_entries()

_MASK_CACHE: dict[Any, np.ndarray] = {}


def parse_mask(mask: Any) -> np.ndarray:
    """The task mask as a (6,) bool array over ``(x, y, z, rx, ry, rz)``.

    Args:
        mask: None (the full pose); a sequence of 6 booleans; a string or sequence of
            axis names (``"xyz"``, ``"x y z rz"``, ``["x", "y", "z", "rz"]``); or the
            shorthands ``"pose"``, ``"position"``. Rotation rows are the components
            of the rotation error vector in the base frame, so ``"rz"`` is the yaw
            about the base z axis (a SCARA's or palletizer's tool angle).

    Raises:
        InputError: an unknown axis name, a wrong length, or no axis selected.
    """
    if mask is None:
        return np.ones(6, dtype=bool)
    key = mask if isinstance(mask, str) else None
    if key is not None and key in _MASK_CACHE:
        return _MASK_CACHE[key]
    if isinstance(mask, str):
        s = mask.strip().lower()
        if s in ("pose", "full", "all"):
            out = np.ones(6, dtype=bool)
        elif s in ("position", "pos"):
            out = np.array([1, 1, 1, 0, 0, 0], dtype=bool)
        else:
            names = s.replace(",", " ").split()
            tokens: list[str] = []
            for word in names:  # "xyzrz" -> x y z rz
                i = 0
                while i < len(word):
                    if word[i] == "r" and i + 1 < len(word):
                        tokens.append(word[i:i + 2])
                        i += 2
                    else:
                        tokens.append(word[i])
                        i += 1
            out = _mask_from_names(tokens, mask)
        _MASK_CACHE[key] = out
        return out
    arr = np.asarray(mask)
    if arr.dtype.kind in "US" or (arr.dtype == object and arr.size and isinstance(
            arr.flat[0], str)):
        return _mask_from_names([str(a).lower() for a in arr.ravel()], mask)
    if arr.shape != (6,) or arr.dtype.kind not in "biuf":
        raise InputError(
            "mask", f"expected 6 booleans over (x, y, z, rx, ry, rz) or axis names, "
            f"got {mask!r:.80}"
        )
    out = arr.astype(bool)
    if not out.any():
        raise InputError("mask", "selects no task axis")
    return out


def _mask_from_names(tokens: Sequence[str], original: Any) -> np.ndarray:
    out = np.zeros(6, dtype=bool)
    for t in tokens:
        if t not in AXES:
            raise InputError(
                "mask", f"unknown axis {t!r} in {original!r:.60}; expected names from "
                f"{list(AXES)}, 'pose' or 'position'"
            )
        out[AXES.index(t)] = True
    if not out.any():
        raise InputError("mask", "selects no task axis")
    return out


_OPTS_CACHE: dict[Any, np.ndarray] = {}


def option_vector(mask: Any, weights: Any, tol: Any, tol_rotation: Any,
                  max_iterations: Any, max_step: Any) -> np.ndarray:
    """The kernel option vector (``K.N_OPTS``,), a fresh copy (cached for hashable arguments).

    The arguments are :func:`~robokin.kinematics.ik.numeric.solve`'s, checked here
    (each error names its argument); the caller sets the per-call entries
    (``O_USE_Q0``, ``O_N_SEEDS``, ``O_N_TABLE``, ``O_PATH_MAX_JUMP``).
    """
    key = None
    if weights is None and (mask is None or isinstance(mask, str)):
        key = (mask, tol, tol_rotation, max_iterations, max_step)
        try:
            hit = _OPTS_CACHE.get(key)
        except TypeError:
            key = hit = None
        if hit is not None:
            again: np.ndarray = hit.copy()
            return again
    opts = _make_opts(mask, weights, tol, tol_rotation, max_iterations, max_step)
    if key is not None and len(_OPTS_CACHE) < 256:
        _OPTS_CACHE[key] = opts.copy()
    return opts


def _make_opts(mask: Any, weights: Any, tol: Any, tol_rotation: Any,
               max_iterations: Any, max_step: Any) -> np.ndarray:
    m = parse_mask(mask)
    if weights is None:
        w = np.ones(6)
    else:
        w = np.asarray(weights, dtype=np.float64)
        if w.shape == (2,):
            w = np.repeat(w, 3)
        if w.shape != (6,) or not np.all(np.isfinite(w)) or np.any(w <= 0):
            raise InputError(
                "weights", "expected 6 positive weights over (x, y, z, rx, ry, rz) "
                f"or 2 (position [1/m^2], rotation [1/rad^2]), got {weights!r:.80}"
            )
    tol_p = check_positive(tol, "tol")
    tol_r = tol_p if tol_rotation is None else check_positive(tol_rotation, "tol_rotation")
    opts: np.ndarray = _FIXED.copy()
    opts[K.O_W:K.O_W + 6] = np.where(m, w, 0.0)
    opts[K.O_TOL_P] = tol_p
    opts[K.O_TOL_R] = tol_r
    opts[K.O_MAX_ITER] = check_count(max_iterations, "max_iterations", minimum=1)
    opts[K.O_MAX_STEP] = check_positive(max_step, "max_step")
    # the seed table is searched by position (and rotation when all of it is asked)
    opts[K.O_TABLE_ROT] = -1.0 if not m[:3].all() else (TABLE_ROT if m[3:].all() else 0.0)
    return opts


def check_positive(x: Any, name: str) -> float:
    """``x`` as a float > 0, else an InputError naming argument ``name``."""
    try:
        v = float(x)
    except (TypeError, ValueError) as exc:
        raise InputError(name, f"expected a positive number, got {x!r:.60}") from exc
    if not v > 0.0:
        raise InputError(name, f"expected a positive number, got {x!r:.60}")
    return v


def check_count(x: Any, name: str, minimum: int = 0) -> int:
    """``x`` as an int >= ``minimum`` (bools refused), else an InputError naming ``name``."""
    if isinstance(x, bool | np.bool_) or not isinstance(x, int | np.integer):
        raise InputError(name, f"expected an integer >= {minimum}, got {x!r:.60}")
    if x < minimum:
        raise InputError(name, f"expected an integer >= {minimum}, got {x}")
    return int(x)


def flat_targets(T: npt.ArrayLike) -> tuple[np.ndarray, tuple[int, ...]]:
    """Poses T (..., 4, 4) as a C-contiguous float64 (N, 4, 4) and the leading shape.

    Only the shape is checked here; rigidity is the kernel's (see :func:`bad_target`).
    """
    if type(T) is not np.ndarray or T.dtype != np.float64:
        T = _real_array(T, "T", "a 4x4 matrix")
    if T.ndim < 2 or T.shape[-2:] != (4, 4):
        raise InputError("T", f"expected shape (..., 4, 4), got {T.shape}")
    lead = T.shape[:-2]
    return np.ascontiguousarray(T.reshape(-1, 4, 4)), lead


def bad_input(out: np.ndarray, n: int, Tf: np.ndarray, Q0: np.ndarray,
               lead: tuple[int, ...], i: int, per: int = 1) -> InputError:
    """The error for kernel row ``i`` refused (``per`` rows per target).

    Names ``q0`` (with its index) when the start configuration was refused, else
    the target pose (:func:`bad_target`).
    """
    if out[i, n + K.R_CODE] == K.CODE_BAD_Q0:
        check_finite(Q0, "q0")  # raises, naming the index
    return bad_target(Tf, lead, i // per)


def bad_target(Tf: np.ndarray, lead: tuple[int, ...], i: int) -> InputError:
    """The error naming target ``i`` (flat) the compiled solver refused."""
    try:
        check_transform(Tf.reshape(lead + (4, 4)) if lead else Tf[0], "T")
    except InputError as exc:
        return exc
    return InputError("T", f"target {i} is not a rigid transform")  # pragma: no cover

def mask_names(opts: np.ndarray) -> str:
    """The selected task rows of an option vector as text, e.g. ``"x y z rz"``."""
    return " ".join(a for a, w in zip(AXES, opts[:6], strict=True) if w > 0)

