"""robokin's compiled kernels: the one C source under ``csrc/``, built at install.

``setup.py`` compiles it once per instruction set: ``_base`` (the compiler's
baseline target), ``_avx2`` (AVX2 + FMA) and ``_avx512`` (AVX-512; both x86-64 with
GCC or clang). :data:`kernels` is the best copy this CPU runs; set ``ROBOKIN_ISA``
to ``baseline`` or ``avx2`` to force a lesser one. Nothing is compiled at run time. ``ROBOKIN_NUM_THREADS`` (or :func:`set_num_threads`) sets
how many threads the batch kernels use (default: the CPUs this process may use).

The kernels read a chain's :class:`~robokin.model.chain_arrays.ChainArrays`
``packed`` vector and C-contiguous float64 buffers; the layers above validate what
users pass. See ``csrc/module.c`` for the entry points and :class:`Kernels`
(``_interface.py``) for their types.
"""

from __future__ import annotations

import os
from typing import cast

from robokin._native._interface import Kernels

__all__ = ["ISA", "Kernels", "kernels", "num_threads", "set_num_threads", "single"]

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


def _pick() -> Kernels:
    wanted = os.environ.get("ROBOKIN_ISA", "").strip().lower()
    if wanted in ("baseline", "base"):
        return _base
    if _base.cpu_has_avx512() and wanted not in ("avx2", "avx2+fma"):
        try:
            import robokin._native._avx512 as _avx512
        except ImportError:  # pragma: no cover - built without the AVX-512 copy
            pass
        else:
            return _avx512
    if _base.cpu_has_avx2_fma():
        try:
            import robokin._native._avx2 as _avx2
        except ImportError:  # pragma: no cover - built without the AVX2 copy
            return _base
        return _avx2
    return _base


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


def num_threads() -> int:
    """Threads the batch kernels use."""
    return int(kernels.num_threads())


def set_num_threads(k: int) -> int:
    """Set the threads of the batch kernels (1 to 64); returns the number in use."""
    return int(kernels.set_num_threads(int(k)))
