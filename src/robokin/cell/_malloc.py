"""Let glibc's malloc reuse freed memory for the length of a task, on Dask workers.

Dask's nanny starts its workers with ``MALLOC_TRIM_THRESHOLD_=65536`` so that they
hand freed memory back to the system. Setting that variable also turns off
glibc's dynamic mmap threshold: every allocation above 128 KiB is then a fresh
``mmap`` and every ``free`` of it a ``munmap``, so each array a task allocates is
new pages the kernel must fault in and zero. A reach-map task allocates its IK
solutions batch after batch; in a worker this cost 15-20 % of its CPU time
(system time 90-100 ns a target against an IK of ~330 ns; ``docs/scale.md``).

:func:`reuse_freed_memory` raises the two thresholds for the task (so the
batches' arrays come from the heap and go back to it), and on leaving restores
the values the environment set and calls ``malloc_trim(0)``, so between tasks
the worker holds no more memory than Dask asked for. It does nothing where the
thresholds were not pinned by the environment (a plain process keeps glibc's
dynamic threshold, which already reuses memory) and on other C libraries.

Concurrent tasks in one worker share the setting: the first one in raises it,
the last one out restores it.
"""

from __future__ import annotations

import ctypes
import functools
import os
import threading
from collections.abc import Iterator
from contextlib import contextmanager

__all__ = ["TASK_MMAP_THRESHOLD", "TASK_TRIM_THRESHOLD", "pinned_thresholds",
           "reuse_freed_memory"]

_M_TRIM_THRESHOLD = -1  # glibc's mallopt parameter numbers (malloc.h)
_M_MMAP_THRESHOLD = -3
_GLIBC_DEFAULT = 128 * 1024  # both thresholds' default [bytes]
#: mmap threshold during a task [bytes] (glibc's largest: 32 MiB on 64-bit);
#: a reach-map batch's largest array is 6.3 MB.
TASK_MMAP_THRESHOLD = 32 * 2**20
#: Free memory the heap may keep during a task [bytes]: a batch's arrays, twice.
TASK_TRIM_THRESHOLD = 64 * 2**20

_lock = threading.Lock()
_users = 0


def pinned_thresholds(environ: dict[str, str] | os._Environ[str] | None = None
                      ) -> tuple[int, int] | None:
    """The ``(trim, mmap)`` thresholds [bytes] the environment pinned, or None.

    None when neither ``MALLOC_TRIM_THRESHOLD_`` nor ``MALLOC_MMAP_THRESHOLD_`` is
    set to a number (glibc then adjusts the mmap threshold itself). A threshold
    not set is glibc's default, 128 KiB.
    """
    env = os.environ if environ is None else environ
    values = []
    for name in ("MALLOC_TRIM_THRESHOLD_", "MALLOC_MMAP_THRESHOLD_"):
        text = env.get(name, "").strip()
        values.append(int(text) if text.isdigit() else None)
    if values[0] is None and values[1] is None:
        return None
    return (_GLIBC_DEFAULT if values[0] is None else values[0],
            _GLIBC_DEFAULT if values[1] is None else values[1])


@functools.cache
def _libc() -> ctypes.CDLL | None:
    """The process's glibc, or None on another C library."""
    try:
        libc = ctypes.CDLL(None)
        libc.gnu_get_libc_version  # noqa: B018 - glibc only
        libc.mallopt, libc.malloc_trim  # noqa: B018
    except (OSError, AttributeError):
        return None
    libc.mallopt.argtypes = [ctypes.c_int, ctypes.c_int]
    libc.malloc_trim.argtypes = [ctypes.c_size_t]
    return libc


@contextmanager
def reuse_freed_memory() -> Iterator[None]:
    """Raise glibc's trim and mmap thresholds inside the block (see the module)."""
    global _users
    pinned = pinned_thresholds()
    libc = _libc() if pinned is not None else None
    if pinned is None or libc is None:
        yield
        return
    with _lock:
        _users += 1
        if _users == 1:
            libc.mallopt(_M_MMAP_THRESHOLD, max(pinned[1], TASK_MMAP_THRESHOLD))
            libc.mallopt(_M_TRIM_THRESHOLD, max(pinned[0], TASK_TRIM_THRESHOLD))
    try:
        yield
    finally:
        with _lock:
            _users -= 1
            if _users == 0:
                libc.mallopt(_M_TRIM_THRESHOLD, pinned[0])
                libc.mallopt(_M_MMAP_THRESHOLD, pinned[1])
                libc.malloc_trim(0)
