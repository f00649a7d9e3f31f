"""Chunks of cell-design work as Dask tasks, on this machine or on a cluster.

One function, :func:`run_chunks`, runs ``fn(job, start, stop)`` for a list of
``(start, stop)`` ranges and hands each result to ``on_result`` as it arrives.
The job object (robot, scene, orientations, ...) enters the graph once, as its
own key, so each worker receives it once and a lost worker's share is
recomputed from the graph, never lost with the worker.

Where it runs (``scheduler``):

* ``None`` or ``"threads"``: Dask's threaded scheduler in this process, one
  thread per CPU this process may use. The compiled kernels release the GIL and
  the per-chunk Python work is small, so threads keep every core busy without
  starting processes or copying results between them (measured in
  ``docs/scale.md``).
* ``"processes"``: Dask's multiprocessing scheduler (for work that holds the
  GIL, such as coal collision queries in a placement search with a scene).
* ``"synchronous"``: one task after the other in this thread (debugging).
* an address (``"tcp://host:8786"``) or a :class:`distributed.Client`: the
  cluster behind it. An address is connected to for the run and closed after; a
  client given is left open.

Inside every task the compiled kernels run on one thread
(:func:`robokin._native.set_num_threads`): Dask's workers provide the
parallelism, so kernels with their own pool would oversubscribe the cores.
"""

from __future__ import annotations

import math
import os
import threading
import time
import uuid
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from typing import Any, TypeVar

from robokin._text import short_repr
from robokin.exceptions import InputError, MissingExtraError

__all__ = ["LOCAL_SCHEDULERS", "describe", "require_scale", "run_chunks"]

LOCAL_SCHEDULERS = ("threads", "processes", "synchronous")
_CONNECT_TIMEOUT = 15.0  # [s] to reach a scheduler given by address

J = TypeVar("J")
R = TypeVar("R")


def require_scale() -> None:
    """Raise :class:`MissingExtraError` unless dask, distributed and zarr import."""
    for package in ("dask", "distributed", "zarr"):
        try:
            __import__(package)
        except ImportError:
            raise MissingExtraError(package, "scale") from None


def _cpu_count() -> int:
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # pragma: no cover - not Linux
        return max(1, os.cpu_count() or 1)


def _is_client(obj: Any) -> bool:
    try:
        from distributed import Client
    except ImportError:  # pragma: no cover - checked by require_scale
        return False
    return isinstance(obj, Client)


def check_scheduler(scheduler: Any) -> None:
    """Raise :class:`InputError` unless ``scheduler`` names a place to run.

    Args:
        scheduler: None, ``"threads"``, ``"processes"``, ``"synchronous"``, an
            address ``"tcp://host:port"`` (or ``"host:port"``) or a
            :class:`distributed.Client`.

    Raises:
        InputError: anything else (naming ``scheduler``).
    """
    if scheduler is None or _is_client(scheduler):
        return
    if isinstance(scheduler, str):
        if scheduler in LOCAL_SCHEDULERS or "://" in scheduler:
            return
        host, sep, port = scheduler.rpartition(":")
        if sep and host and port.isdigit():
            return
    raise InputError(
        "scheduler",
        f"expected None, one of {list(LOCAL_SCHEDULERS)}, an address such as "
        f"'tcp://host:8786' or a distributed.Client, got {short_repr(scheduler)}",
    )


def describe(scheduler: Any) -> str:
    """A short text saying where work with this ``scheduler`` runs."""
    if scheduler is None:
        return f"local threads ({_cpu_count()})"
    if isinstance(scheduler, str):
        if scheduler in LOCAL_SCHEDULERS:
            return f"local {scheduler}"
        return f"cluster at {scheduler}"
    info = scheduler.scheduler_info() if _is_client(scheduler) else {}
    workers = info.get("workers", {})
    threads = sum(int(w.get("nthreads", 0)) for w in workers.values())
    return f"cluster at {scheduler.scheduler.address} ({len(workers)} workers, {threads} threads)"


def _one_kernel_thread() -> None:
    from robokin._native import num_threads, set_num_threads

    if num_threads() != 1:
        set_num_threads(1)


def _task(fn: Callable[[J, int, int], R], job: J, start: int, stop: int) -> R:
    """One chunk, on whatever worker runs it: kernels on one thread, then ``fn``."""
    _one_kernel_thread()
    return fn(job, start, stop)


def run_chunks(
    fn: Callable[[J, int, int], R],
    job: J,
    ranges: Sequence[tuple[int, int]],
    *,
    scheduler: Any,
    on_result: Callable[[int, R], None],
    progress: Callable[[int, int], None] | None = None,
    name: str = "robokin",
) -> None:
    """Run ``fn(job, start, stop)`` for every range as a Dask task.

    Args:
        fn: A module-level function (it travels to the workers by reference).
        job: Everything the chunks share (pickled once into the graph).
        ranges: ``(start, stop)`` per task.
        scheduler: Where to run (see the module docstring).
        on_result: Called in this thread as ``on_result(i, result)`` for task
            ``i``, in completion order; the result is dropped after it.
        progress: Called as ``progress(done, total)`` after each task.
        name: Prefix of the task keys (seen on the Dask dashboard).

    Raises:
        InputError: a bad ``scheduler`` or one that cannot be reached.
        MissingExtraError: dask or distributed is not installed.
    """
    require_scale()
    check_scheduler(scheduler)
    import dask

    total = len(ranges)
    if total == 0:
        return
    token = uuid.uuid4().hex[:12]
    job_key = f"{name}-job-{token}"
    shared = dask.delayed(job, name=job_key, traverse=False, pure=False)
    keys = [f"{name}-{token}-{i}" for i in range(total)]
    tasks = [
        dask.delayed(_task, pure=False)(fn, shared, int(a), int(b), dask_key_name=k)
        for k, (a, b) in zip(keys, ranges)
    ]
    if scheduler is None or scheduler in LOCAL_SCHEDULERS:
        _run_local(tasks, keys, scheduler or "threads", on_result, progress)
        return
    with _client(scheduler) as client:
        _run_distributed(client, tasks, keys, on_result, progress)


def _run_local(
    tasks: list[Any],
    keys: list[str],
    kind: str,
    on_result: Callable[[int, Any], None],
    progress: Callable[[int, int], None] | None,
) -> None:
    import dask
    from dask.callbacks import Callback

    from robokin._native import num_threads, set_num_threads

    index = {k: i for i, k in enumerate(keys)}
    total = len(keys)
    done = [0]

    def posttask(key: Any, result: Any, dsk: Any, state: Any, worker_id: Any) -> None:
        if key in index:
            done[0] += 1
            if progress is not None:
                progress(done[0], total)

    before = num_threads()
    options: dict[str, Any] = {"scheduler": kind}
    if kind != "synchronous":
        options["num_workers"] = _cpu_count()
    try:
        with Callback(posttask=posttask):
            results = dask.compute(*tasks, **options)
    finally:
        if num_threads() != before:
            set_num_threads(before)
    for i, r in enumerate(results):
        on_result(i, r)


def _run_distributed(
    client: Any,
    tasks: list[Any],
    keys: list[str],
    on_result: Callable[[int, Any], None],
    progress: Callable[[int, int], None] | None,
) -> None:
    from distributed import as_completed

    index = {k: i for i, k in enumerate(keys)}
    total = len(keys)
    futures = client.compute(tasks)
    done = 0
    # results are fetched on the client's event loop as tasks finish, all at once
    # (one round trip each in this thread would bound the run by the latency);
    # a result lost with its worker before it was fetched is recomputed by Dask
    # and fetched when ready
    finished = as_completed(futures, loop=client.loop, with_results=True)
    try:
        for batch in finished.batches():
            for fut, result in batch:
                i = index[fut.key]
                futures[i] = None
                fut.release()
                on_result(i, result)
                done += 1
                if progress is not None:
                    progress(done, total)
    finally:
        live = [f for f in futures if f is not None]
        if live:
            client.cancel(live)


@contextmanager
def _client(scheduler: Any) -> Iterator[Any]:
    if _is_client(scheduler):
        yield scheduler
        return
    from distributed import Client

    try:
        client = Client(scheduler, timeout=_CONNECT_TIMEOUT, set_as_default=False)
    except (OSError, TimeoutError) as exc:
        raise InputError(
            "scheduler",
            f"cannot reach the Dask scheduler at {short_repr(scheduler)} within "
            f"{_CONNECT_TIMEOUT:.0f} s ({type(exc).__name__}: {exc}); start one with "
            "'dask scheduler' and 'dask worker ADDRESS' (docs/scale.md)",
        ) from None
    try:
        yield client
    finally:
        client.close()


class Throttle:
    """Calls ``fn`` at most every ``interval`` seconds (and on ``flush``)."""

    def __init__(self, fn: Callable[[], None], interval: float = 1.0) -> None:
        """Wrap ``fn``; ``interval`` in seconds."""
        self._fn = fn
        self._interval = interval
        self._last = -math.inf
        self._lock = threading.Lock()

    def __call__(self) -> None:
        """Call ``fn`` if ``interval`` has passed since the last call."""
        now = time.monotonic()
        with self._lock:
            if now - self._last < self._interval:
                return
            self._last = now
        self._fn()

    def flush(self) -> None:
        """Call ``fn`` now."""
        with self._lock:
            self._last = time.monotonic()
        self._fn()
