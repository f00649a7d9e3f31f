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

__all__ = ["CONNECT_TIMEOUT", "LOCAL_SCHEDULERS", "describe", "probe_scheduler",
           "require_scale", "run_chunks"]

LOCAL_SCHEDULERS = ("threads", "processes", "synchronous")
#: Seconds to reach a scheduler given by address and hear it answer as one.
CONNECT_TIMEOUT = 10.0

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
    """One chunk, on whatever worker runs it.

    The kernels on one thread, then ``fn`` with freed memory reused
    (:mod:`robokin.cell._malloc`: on a Dask worker glibc otherwise maps fresh
    pages for every array).
    """
    from robokin.cell._malloc import reuse_freed_memory

    _one_kernel_thread()
    with reuse_freed_memory():
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


def _unreachable(scheduler: Any, timeout: float, why: str, argument: str) -> InputError:
    return InputError(
        argument,
        f"cannot reach the Dask scheduler at {short_repr(scheduler, 200)} within "
        f"{timeout:g} s: {why}; start one with 'dask scheduler' and 'dask worker "
        "ADDRESS' (docs/scale.md)")


async def _identity(address: str, timeout: float) -> Any:
    """The scheduler's answer to ``identity`` (each step bounded by ``timeout``)."""
    import asyncio

    from distributed.comm import connect

    # a plain TCP connect first: distributed's connect retries a refused port until
    # its timeout and, on a loaded machine, may end on a timed-out attempt instead
    # of the refusal (a closed port then read as silence)
    await _tcp_open(address, timeout)
    # distributed's connect retries until its timeout, then reads the handshake
    # with no bound at all (a port that accepts and stays silent hangs there)
    # (the outer bound a little later than connect's own: a refused connection
    # is reported as refused, not as silence)
    comm = await asyncio.wait_for(connect(address, timeout=timeout), 1.5 * timeout + 0.5)
    try:
        await asyncio.wait_for(comm.write({"op": "identity", "reply": True}), timeout)
        return await asyncio.wait_for(comm.read(), timeout)
    finally:
        comm.abort()


async def _tcp_open(address: str, timeout: float) -> None:
    """Open and close a TCP connection to a ``tcp://host:port`` address.

    Other schemes are left to distributed; a refused connection raises at once.
    """
    import asyncio

    scheme, _, rest = address.partition("://")
    host, sep, port = rest.rpartition(":")
    if scheme != "tcp" or not sep or not port.isdigit():
        return
    _, writer = await asyncio.wait_for(
        asyncio.open_connection(host.strip("[]"), int(port)), timeout)
    writer.close()


def _os_reason(exc: OSError) -> str:
    """The innermost system error of a failed connect (``Connection refused``)."""
    inner: BaseException = exc
    while inner.__cause__ is not None:
        inner = inner.__cause__
    if isinstance(inner, OSError) and (inner.errno or inner.strerror):
        # the system's words for the errno (asyncio's strerror is "Connect call failed")
        text = os.strerror(inner.errno) if inner.errno else str(inner.strerror)
        return text.lower() + " (no Dask scheduler listens there)"
    return " ".join(str(exc).split())[:200] or type(exc).__name__


def probe_scheduler(scheduler: Any, timeout: float = CONNECT_TIMEOUT, *,
                    argument: str = "scheduler") -> None:
    """Raise unless a Dask scheduler answers at the address within ``timeout``.

    A closed port, an address nothing answers from (a firewall, an unroutable
    network) and a server that answers but is no Dask scheduler each end in at
    most about ``timeout`` seconds (twice that for a server that is slow at every
    step, plus up to half of it for the connection) with one
    :class:`InputError` naming the address. ``None``, a local
    scheduler name and a :class:`distributed.Client` are not probed.

    Args:
        scheduler: As :func:`run_chunks` takes it.
        timeout: Seconds to connect, and again to hear the answer (> 0).
        argument: The argument named in the error (``--scheduler`` on the CLI).

    Raises:
        InputError: the scheduler cannot be reached (naming ``argument``), or a
            bad ``scheduler`` or ``timeout``.
    """
    import asyncio
    import concurrent.futures

    if not (isinstance(timeout, int | float) and math.isfinite(timeout) and timeout > 0):
        raise InputError("timeout", f"expected seconds > 0, got {short_repr(timeout)}")
    if scheduler is None or _is_client(scheduler) or scheduler in LOCAL_SCHEDULERS:
        return
    try:
        check_scheduler(scheduler)
    except InputError as exc:
        raise InputError(argument, exc.reason) from None
    address = scheduler if "://" in scheduler else f"tcp://{scheduler}"
    # a thread of its own: the caller may be inside an event loop (a notebook)
    with concurrent.futures.ThreadPoolExecutor(1) as pool:
        job = pool.submit(asyncio.run, _identity(address, timeout))
        try:
            reply = job.result(timeout=3 * timeout + 1)
        except (TimeoutError, asyncio.TimeoutError, concurrent.futures.TimeoutError):
            raise _unreachable(scheduler, timeout, "no answer (a firewall, an "
                               "unroutable network, or not a Dask scheduler)",
                               argument) from None
        except OSError as exc:
            raise _unreachable(scheduler, timeout, _os_reason(exc), argument) from None
        except Exception as exc:  # garbage on the wire: any decoding error
            raise _unreachable(scheduler, timeout, "something answers there, but not "
                               f"as a Dask scheduler ({type(exc).__name__})",
                               argument) from None
    if not (isinstance(reply, dict) and reply.get("type") == "Scheduler"):
        raise _unreachable(scheduler, timeout, "something answers there, but not as a "
                           "Dask scheduler", argument)


@contextmanager
def _client(scheduler: Any) -> Iterator[Any]:
    if _is_client(scheduler):
        yield scheduler
        return
    from distributed import Client

    probe_scheduler(scheduler, CONNECT_TIMEOUT)
    try:
        client = Client(scheduler, timeout=CONNECT_TIMEOUT, set_as_default=False)
    except Exception as exc:  # it answered the probe a moment ago
        raise _unreachable(scheduler, CONNECT_TIMEOUT, f"{type(exc).__name__}: "
                           f"{' '.join(str(exc).split())[:200]}", "scheduler") from None
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
