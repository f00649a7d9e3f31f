"""robokin's compiled kernels: the one C source under ``csrc/``, built at install.

``setup.py`` compiles it once per instruction set: ``_base`` (the compiler's
baseline target), ``_avx2`` (AVX2 + FMA) and ``_avx512`` (AVX-512; both x86-64 with
GCC or clang). :data:`kernels` is the best copy this CPU runs; set ``ROBOKIN_ISA``
to ``baseline`` or ``avx2`` to force a lesser one. Nothing is compiled at run time.
``ROBOKIN_NUM_THREADS`` (or :func:`set_num_threads`) sets how many threads the
batch kernels use (default: the CPUs this process may use).

A bad value of either variable (``ROBOKIN_NUM_THREADS=abc``, ``0``, ``1e3``,
``ROBOKIN_ISA=sse9``, or a copy this CPU cannot run) is not an error, since the
environment may be set for a whole cluster: it is a ``RuntimeWarning`` at import
naming the variable, its value and the value used instead (the default, or 64
threads for a count above 64).

The kernels read a chain's :class:`~robokin.model.chain_arrays.ChainArrays`
``packed`` vector and C-contiguous float64 buffers; the layers above validate what
users pass. See ``csrc/module.c`` for the entry points and :class:`Kernels`
(``_interface.py``) for their types.
"""

from __future__ import annotations

import os
import warnings
from typing import cast

from robokin._native._interface import Kernels

__all__ = ["ISA", "ISA_NAMES", "MAX_THREADS", "Kernels", "kernels", "num_threads",
           "set_num_threads", "single"]

try:
    import robokin._native._base as _base
except ImportError as exc:  # pragma: no cover - a broken install
    raise ImportError(
        f"robokin's compiled kernels (robokin._native._base) are missing from "
        f"{os.path.dirname(__file__)}: this copy of robokin was not built. In the "
        "source tree run `pip install -e .` (or `python setup.py build_ext "
        "--inplace`), which needs a C compiler and the Python headers (README.md, "
        "'Installing'); or install a wheel built by .ci/wheel, which needs neither. "
        f"({exc})"
    ) from exc


#: The values ``ROBOKIN_ISA`` accepts, and the copy each asks for.
ISA_NAMES = {"baseline": "baseline", "base": "baseline", "avx2": "avx2+fma",
             "avx2+fma": "avx2+fma", "avx512": "avx512"}
#: Most threads the batch kernels run (the pool's cap, ``csrc/pool.c``).
MAX_THREADS = 64


def _environment_warning(message: str) -> None:
    """A warning about an environment variable, shown once per process."""
    warnings.warn(message, RuntimeWarning, stacklevel=3)


def _best() -> Kernels:
    """The best copy this CPU runs (and this install has)."""
    if _base.cpu_has_avx512():
        try:
            import robokin._native._avx512 as _avx512
        except ImportError:  # pragma: no cover - built without the AVX-512 copy
            pass
        else:
            return cast(Kernels, _avx512)
    if _base.cpu_has_avx2_fma():
        try:
            import robokin._native._avx2 as _avx2
        except ImportError:  # pragma: no cover - built without the AVX2 copy
            return cast(Kernels, _base)
        return cast(Kernels, _avx2)
    return cast(Kernels, _base)


def _pick() -> Kernels:
    """The copy ``ROBOKIN_ISA`` asks for; the best one when unset or unusable."""
    raw = os.environ.get("ROBOKIN_ISA", "")
    wanted = raw.strip().lower()
    best = _best()
    if not wanted:
        return best
    isa = ISA_NAMES.get(wanted)
    if isa is None:
        _environment_warning(
            f"ROBOKIN_ISA={raw!r} is not one of baseline, avx2, avx512; using "
            f"{best.ISA} (the best copy this CPU runs)")
        return best
    if isa == "baseline":
        return cast(Kernels, _base)
    order = ["baseline", "avx2+fma", "avx512"]
    if order.index(isa) > order.index(best.ISA):
        _environment_warning(
            f"ROBOKIN_ISA={raw!r}: this CPU (or this install) has no {isa} copy; using "
            f"{best.ISA} (the best copy this CPU runs)")
        return best
    if isa == "avx2+fma" and best.ISA == "avx512":
        import robokin._native._avx2 as _avx2

        return cast(Kernels, _avx2)
    return best


kernels: Kernels = _pick()


def _pick_single() -> Kernels:
    """The copy for one configuration.

    On an AVX-512 CPU the AVX2 copy: its 4 lanes cost less than 8 for a lone
    configuration (182 vs 241 ns for the UR5's FK) and give the same bits (the same
    operations per lane; tests/kinematics check it against the batch on every
    built-in arm).
    """
    if getattr(kernels, "ISA", "") == "avx512":
        try:
            from robokin._native import _avx2
        except ImportError:  # pragma: no cover - built without the AVX2 copy
            return kernels
        return cast(Kernels, _avx2)
    return kernels


single: Kernels = _pick_single()
ISA: str = kernels.ISA


def _default_threads() -> int:
    """The CPUs this process may use, at most :data:`MAX_THREADS` (pool.c's rule)."""
    try:
        k = len(os.sched_getaffinity(0))
    except AttributeError:  # pragma: no cover - not Linux
        k = os.cpu_count() or 1
    return max(1, min(k, MAX_THREADS))


def _threads_from_environment() -> None:
    """Apply ``ROBOKIN_NUM_THREADS``: a whole number from 1 to 64, else a warning.

    The pool would read the variable itself with C's ``atoi`` (``1e3`` as 1,
    ``abc`` as the default, silently); here it is parsed once and the count set
    on every copy in use.
    """
    raw = os.environ.get("ROBOKIN_NUM_THREADS")
    if raw is None or not raw.strip():
        return
    text = raw.strip()
    if text.isascii() and text.isdigit() and int(text) >= 1:
        k = int(text)
        if k > MAX_THREADS:
            _environment_warning(f"ROBOKIN_NUM_THREADS={raw!r} is more than "
                                 f"{MAX_THREADS}; using {MAX_THREADS} threads")
            k = MAX_THREADS
    else:
        k = _default_threads()
        _environment_warning(f"ROBOKIN_NUM_THREADS={raw!r} is not a whole number from "
                             f"1 to {MAX_THREADS}; using {k} threads (the CPUs this "
                             "process may use)")
    for copy in {id(kernels): kernels, id(single): single}.values():
        copy.set_num_threads(k)


_threads_from_environment()


def num_threads() -> int:
    """Threads the batch kernels use."""
    return int(kernels.num_threads())


def set_num_threads(k: int) -> int:
    """Set the threads of the batch kernels (1 to 64); returns the number in use."""
    return int(kernels.set_num_threads(int(k)))
