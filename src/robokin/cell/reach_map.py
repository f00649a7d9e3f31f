"""Reachability maps: which positions the tool reaches, in how many orientations.

A map covers a region with cubic voxels and tries the same K tool orientations
at every voxel centre (the capability map of Zacharias, Borst and Hirzinger,
"Capturing robot workspace structure: representing robot capabilities", IROS
2007). Per voxel and orientation it counts the IK solutions inside the joint
limits (and, with a scene, free of collision); per voxel it keeps the
reachability index (the fraction of orientations with a solution), the number
of solutions and the best manipulability.

The work is split into chunks of voxels that run as Dask tasks (see
:mod:`robokin.cell._scheduler` for where), and with ``store=`` each task writes
its voxels straight into a Zarr store, so memory stays bounded whatever the
map's size. The result does not depend on the scheduler or the chunking, bit
for bit (see :mod:`robokin.cell._evaluate`).

.. code-block:: python

    from robokin import cell

    m = cell.reach_map(robot, voxel=0.05, orientations=32)
    m.index          # (V,) reachability index
    m.plot_sections(path="sections.png")
"""

from __future__ import annotations

import hashlib
import math
import shutil
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal, Protocol

import numpy as np
import numpy.typing as npt

from robokin._text import short_repr
from robokin.cell import _store
from robokin.cell import plots as _plots
from robokin.cell._evaluate import ReachChunk, ReachJob, evaluate_reach
from robokin.cell._inputs import (
    Progress,
    ik_method,
    manifold_sweep,
    placed_robot,
    progress_callback,
)
from robokin.cell._scheduler import Throttle, check_scheduler, run_chunks
from robokin.cell.grid import VoxelGrid, tool_orientations
from robokin.exceptions import InputError

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from robokin.collision.scene import Scene
    from robokin.robot import Robot

__all__ = ["ReachMap", "reach_map"]

# Per task: ~0.1-0.3 s of closed-form IK on one core and ~100 MB of temporaries
# (benchmarks/bench_cell.py --sweep: 8,192 targets a task run at 72 % of 131,072's
# rate, 524,288 at 103 %); at most 50,000 tasks, so a scheduler spends about a
# minute on a map of any size.
_POSES_PER_TASK = 131072
_MAX_TASKS = 50_000
_REGION_SAMPLES = 200_000
_REGION_MARGIN = 0.05  # of the extent, on each side
#: Largest map :func:`reach_map` builds in memory (``store=None``) [bytes]: its
#: arrays, V x K counts (1 B each) and 20 B per voxel (12 B without
#: manipulability). A larger map needs ``store=`` (see ``docs/scale.md``).
MAX_IN_MEMORY_BYTES = 2 * 2**30


class ArrayLike(Protocol):
    """A NumPy array or a Zarr array: sliced to get NumPy arrays."""

    @property
    def shape(self) -> tuple[int, ...]:
        """The array's shape."""
        ...

    def __getitem__(self, key: Any) -> Any:
        """A slice of the array (a NumPy array)."""
        ...


@dataclass(frozen=True, eq=False)
class ReachMap:
    """A reachability map: V voxels times K tool orientations.

    The arrays are NumPy arrays, or Zarr arrays for a map read lazily from a
    store (slice them: ``m.index[:1000]``); the derived properties read them
    whole.

    Attributes:
        robot_name: The robot's name.
        grid: The voxel grid (:class:`~robokin.cell.grid.VoxelGrid`).
        orientations: Tool orientations (K, 3, 3) tried in every voxel, world
            frame.
        counts: IK solutions per voxel and orientation, inside the joint limits
            (and collision-free with a scene), (V, K) uint8. Closed-form arms
            count their distinct solutions (not the 2 pi copies of a joint with
            more than one turn of travel); numerically solved arms 0 or 1 (a
            7-axis arm: 1 when any part of the pose's self-motion manifold is
            inside the limits).
        index: Reachability index per voxel, the fraction of orientations with a
            solution, (V,) float64 in [0, 1].
        solutions: Solutions per voxel summed over its orientations, (V,) int32.
        manipulability: Best Yoshikawa manipulability over every solution in the
            voxel (0 where none), (V,) float64; None when not computed.
        method: The IK used (``"analytic:three_parallel"``, ``"numeric"``...).
        scene: The scene's name when collisions counted, else None.
        base: The robot's base pose in the world (4, 4) [m].
        path: The Zarr store the map lives in, or None.
    """

    robot_name: str
    grid: VoxelGrid
    orientations: np.ndarray
    counts: ArrayLike
    index: ArrayLike
    solutions: ArrayLike
    manipulability: ArrayLike | None
    method: str
    scene: str | None = None
    base: np.ndarray | None = None
    path: Path | None = None

    # ------------------------------------------------------------ derived
    @property
    def centers(self) -> np.ndarray:
        """Voxel centres (V, 3) [m] in the world."""
        return self.grid.centers()

    @property
    def reachable(self) -> np.ndarray:
        """(V, K) bool: a valid solution within limits (and collision-free) exists."""
        return np.asarray(self.counts[...]) > 0

    @property
    def voxel(self) -> float:
        """Voxel edge [m]."""
        return self.grid.voxel

    @property
    def size(self) -> int:
        """Number of voxels V."""
        return self.grid.size

    def volume(self, threshold: float = 0.0) -> float:
        """Volume [m^3] of the voxels whose index exceeds ``threshold``.

        With ``threshold=0``: the voxels whose centre the tool reaches in at
        least one of the K orientations, a midpoint cubature of the position
        workspace whose volume
        :func:`~robokin.kinematics.workspace.sample_workspace` estimates with
        its uncertainty (low by the boundary voxels reachable only between the
        K orientations; see ``docs/scale.md``).
        """
        idx = np.asarray(self.index[...])
        return float(np.count_nonzero(idx > threshold)) * self.grid.voxel**3

    def as_grid(self, values: npt.ArrayLike) -> np.ndarray:
        """Per-voxel values (V, ...) arranged on the grid, (nx, ny, nz, ...).

        Raises:
            InputError: ``values`` is not V values along its first axis.
        """
        v = np.asarray(values)
        if v.ndim == 0 or v.shape[0] != self.size:
            raise InputError("values", f"expected one value per voxel, shape ({self.size}, "
                             f"...), got shape {v.shape}")
        return v.reshape(self.grid.shape + v.shape[1:])

    def section(
        self,
        axis: Literal["x", "y", "z"],
        at: float,
        quantity: Literal["index", "manipulability", "solutions"] = "index",
    ) -> tuple[np.ndarray, np.ndarray]:
        """A plane of voxels normal to ``axis`` through coordinate ``at`` [m].

        Args:
            axis: The plane's normal.
            at: Its coordinate [m]; the layer of voxels containing it (the
                nearest layer when outside the grid).
            quantity: The per-voxel array to cut.

        Returns:
            ``(values, extent)``: the section, rows along the first remaining
            axis (x for ``"y"`` and ``"z"``, y for ``"x"``), and the
            ``[[u0, v0], [u1, v1]]`` [m] it spans.

        Raises:
            InputError: an unknown axis or quantity, no manipulability, or an
                ``at`` that is not a finite number.
        """
        from robokin._validation import check_finite_number

        if axis not in ("x", "y", "z"):
            raise InputError("axis", f"expected 'x', 'y' or 'z', got {short_repr(axis)}")
        at = check_finite_number(at, "at")
        arr = self._quantity(quantity)
        k = "xyz".index(axis)
        layer = int(np.clip(math.floor((at - self.grid.origin[k]) / self.grid.voxel),
                            0, self.grid.shape[k] - 1))
        cube = self.as_grid(np.asarray(arr[...]))
        plane = np.take(cube, layer, axis=k)
        keep = [i for i in range(3) if i != k]
        bounds = self.grid.bounds
        return plane, bounds[:, keep]

    def _quantity(self, quantity: str) -> ArrayLike:
        if quantity == "index":
            return self.index
        if quantity == "solutions":
            return self.solutions
        if quantity == "manipulability":
            if self.manipulability is None:
                raise InputError("quantity", "this map was computed without manipulability")
            return self.manipulability
        raise InputError(
            "quantity",
            f"expected 'index', 'manipulability' or 'solutions', got {short_repr(quantity)}",
        )

    def summary(self) -> dict[str, Any]:
        """Plain numbers for reports and JSON."""
        idx = np.asarray(self.index[...])
        K = int(self.orientations.shape[0])
        w = None if self.manipulability is None else np.asarray(self.manipulability[...])
        return {
            "robot": self.robot_name,
            "method": self.method,
            "scene": self.scene,
            "voxel_m": self.grid.voxel,
            "grid": list(self.grid.shape),
            "bounds_m": self.grid.bounds.tolist(),
            "voxels": self.size,
            "orientations": K,
            "ik_evaluations": self.size * K,
            "reachable_voxels": int(np.count_nonzero(idx)),
            "dexterous_voxels": int(np.count_nonzero(idx >= 1.0)),
            "mean_index_reachable": float(idx[idx > 0].mean()) if (idx > 0).any() else 0.0,
            "reachable_volume_m3": self.volume(),
            "manipulability_max": None if w is None else float(w.max(initial=0.0)),
        }

    # ------------------------------------------------------------- plots
    def plot_sections(self, path: str | Path | None = None, **kwargs: Any) -> Figure:
        """Sections through the map as heatmaps (see :func:`robokin.cell.plots.plot_sections`)."""
        return _plots.plot_sections(self, path=path, **kwargs)

    # ------------------------------------------------------------- files
    def save(self, path: str | Path, *, overwrite: bool = False) -> Path:
        """Write the map as a Zarr store (a folder), atomically.

        Args:
            path: The store folder to create.
            overwrite: Replace an existing store.

        Returns:
            ``path``.

        Raises:
            InputError: ``path`` exists (without ``overwrite``), is a file, its
                folder does not exist, or the store cannot be written there
                (read-only folder, full disk...).
            MissingExtraError: zarr is not installed.
        """
        target = Path(path)
        if self.path is not None and target.resolve() == self.path.resolve():
            raise InputError("path", f"the map already lives in {target}")
        chunk = int(getattr(self.counts, "chunks", (0,))[0] or 0) or _default_chunk(
            self.size, self.orientations.shape[0])
        attrs = self._attrs(chunk)
        with _store.publish(target, overwrite=overwrite) as tmp:
            _store.create(tmp, attrs, voxels=self.size, orientations=self.orientations,
                          chunk=chunk, with_manipulability=self.manipulability is not None,
                          argument=None)
            for a in range(0, self.size, chunk):
                b = min(a + chunk, self.size)
                _store.write_chunk(str(tmp), a, b, {
                    "counts": np.asarray(self.counts[a:b]),
                    "index": np.asarray(self.index[a:b]),
                    "solutions": np.asarray(self.solutions[a:b]),
                    "manipulability": None if self.manipulability is None
                    else np.asarray(self.manipulability[a:b]),
                })
            _store.mark_done(tmp, range(-(-self.size // chunk)))
            _store.finish(tmp)
        return target

    def _attrs(self, chunk: int, fingerprint: str = "") -> dict[str, Any]:
        return {
            "robot": self.robot_name,
            "fingerprint": fingerprint,
            "origin": self.grid.origin.tolist(),
            "voxel": self.grid.voxel,
            "shape": list(self.grid.shape),
            "chunk": int(chunk),
            "method": self.method,
            "scene": self.scene,
            "base": None if self.base is None else np.asarray(self.base).tolist(),
        }

    @classmethod
    def load(cls, path: str | Path, *, lazy: bool = False) -> ReachMap:
        """Read a map written by :meth:`save` or by ``reach_map(..., store=path)``.

        Args:
            path: The store folder.
            lazy: Keep the arrays in the store (Zarr arrays, read when sliced)
                instead of reading them into memory.

        Returns:
            The :class:`ReachMap`.

        Raises:
            InputError: not a map store, or an incomplete one (a run that
                stopped: the message says how to finish it).
            MissingExtraError: zarr is not installed.
        """
        g = _store.open_map(path)
        a = g.attrs
        if not a.get("complete", False):
            done = _store.read_done(path)
            raise InputError(
                "path",
                f"{path} is an incomplete map ({int(done.sum())} of {done.size} chunks "
                f"written): run reach_map(...) again with store='{path}' and the same "
                "arguments to finish it",
            )

        def get(name: str) -> Any:
            if name not in g:
                return None
            arr = g[name]
            return arr if lazy else np.asarray(arr[...])

        return cls(
            robot_name=str(a["robot"]),
            grid=VoxelGrid(np.array(a["origin"]), float(a["voxel"]), tuple(a["shape"])),
            orientations=np.asarray(g["orientations"][...]),
            counts=get("counts"),
            index=get("index"),
            solutions=get("solutions"),
            manipulability=get("manipulability"),
            method=str(a["method"]),
            scene=a.get("scene"),
            base=None if a.get("base") is None else np.array(a["base"], dtype=np.float64),
            path=Path(path),
        )


# ------------------------------------------------------------------ building
def reach_map(
    robot: Robot,
    region: npt.ArrayLike | None = None,
    voxel: float = 0.05,
    orientations: int | npt.ArrayLike = 32,
    scene: Scene | None = None,
    scheduler: Any = None,
    store: str | Path | None = None,
    *,
    rolls: int = 1,
    method: Literal["auto", "analytic", "numeric"] = "auto",
    manipulability: bool = True,
    chunk: int | None = None,
    progress: Progress = None,
    overwrite: bool = False,
) -> ReachMap:
    """Compute the reachability map of a robot over a region.

    Args:
        robot: The robot. Without a scene the map is in its world frame (its
            base transform applied); with one, the scene places it and adds its
            tool.
        region: ``[[x0, y0, z0], [x1, y1, z1]]`` [m] to cover; default the
            arm's workspace bounds (Monte-Carlo, 200,000 joint samples, seed 0)
            grown by 5 % on each side.
        voxel: Voxel edge [m].
        orientations: Number of approach directions (times ``rolls``, see
            :func:`~robokin.cell.grid.tool_orientations`), or rotation matrices
            (K, 3, 3) of the tool in the world.
        scene: A :class:`~robokin.collision.Scene`: solutions that touch it (or
            the robot itself) do not count.
        scheduler: Where the chunks run: None (this machine, threads), an
            address ``"tcp://host:8786"`` or a :class:`distributed.Client` (see
            ``docs/scale.md``).
        store: A Zarr store folder the chunks stream into (memory then stays
            bounded); the map returned reads from it lazily. An incomplete store
            of the same map is resumed. Without one the map is built in memory,
            at most :data:`MAX_IN_MEMORY_BYTES` (2 GiB: V x K bytes of counts
            and 20 bytes per voxel).
        rolls: Rolls about each approach direction (with an integer
            ``orientations``).
        method: ``"auto"`` (the closed form when the arm has one, every
            solution; else the numeric solver, one solution per target from its
            deterministic seed-table restarts; a 7-axis arm with a held-joint
            closed form then searches the self-motion manifold of every target
            the numeric sample missed: ``docs/scale.md``), ``"analytic"`` or
            ``"numeric"`` (the numeric sample alone).
        manipulability: Compute the best manipulability per voxel (for a
            6-joint arm ``|det J|`` per solution in compiled code, about a tenth
            of the IK's cost; a Jacobian and its singular values per solution
            for other arms).
        chunk: Voxels per Dask task (default: about 131,000 IK targets, and at
            most 50,000 tasks).
        progress: True for a progress bar on stderr, or ``progress(done, total)``
            called after each task.
        overwrite: Replace a store that holds a different map.

    Returns:
        The :class:`ReachMap`.

    Raises:
        InputError: an empty or malformed region, a voxel <= 0, bad
            orientations, an unknown method (or ``"analytic"`` for an arm
            without a closed form), a bad scheduler or one that cannot be
            reached, a store holding another map or that cannot be written,
            a map larger than 2 GiB without a store (naming ``store``).
        MissingExtraError: dask, distributed or zarr is not installed (``pip
            install 'robokin[scale]'``), or coal with a scene.
    """
    from robokin.cell._facts import default_region
    from robokin.cell._scheduler import require_scale

    require_scale()
    check_scheduler(scheduler)
    world, bare = placed_robot(robot, scene)
    R = _orientations(orientations, rolls)
    if region is None:
        grid_region = default_region(world, _REGION_SAMPLES, _REGION_MARGIN)
        grid = VoxelGrid.from_region(grid_region, voxel)
    else:
        grid = VoxelGrid.from_region(region, voxel)
    numeric, method_name = ik_method(world, method)
    sweep = manifold_sweep(world, method) if numeric else None
    if sweep is not None:
        method_name = f"numeric + self-motion ({sweep} swept)"
    V, K = grid.size, R.shape[0]
    if store is None:
        _check_in_memory(V, K, bool(manipulability))
    B = _chunk(chunk, V, K)
    ranges = [(a, min(a + B, V)) for a in range(0, V, B)]
    job = ReachJob(world, bare, scene, grid, R, numeric, bool(manipulability), sweep=sweep)
    shell = ReachMap(world.name, grid, R, np.zeros((0, K), np.uint8), np.zeros(0),
                     np.zeros(0, np.int32), None, method_name,
                     None if scene is None else scene.name, np.array(world.base))
    fingerprint = _fingerprint(job, B)
    if store is None:
        return _run_in_memory(job, shell, ranges, scheduler, progress)
    return _run_into_store(job, shell, ranges, Path(store), fingerprint, scheduler,
                           progress, overwrite)


def _in_memory_bytes(V: int, K: int, with_manipulability: bool) -> int:
    """Bytes of a map's arrays held in memory: V voxels x K orientations.

    ``counts`` (V, K) uint8, ``index`` (V,) float64, ``solutions`` (V,) int32
    and ``manipulability`` (V,) float64.
    """
    return V * K + V * (8 + 4 + (8 if with_manipulability else 0))


def _check_in_memory(V: int, K: int, with_manipulability: bool) -> None:
    """Refuse an in-memory map above :data:`MAX_IN_MEMORY_BYTES` (before allocating)."""
    need = _in_memory_bytes(V, K, with_manipulability)
    if need > MAX_IN_MEMORY_BYTES:
        raise InputError(
            "store",
            f"the map ({V:,} voxels x {K} orientations) needs {need / 2**30:.1f} GiB "
            f"in memory, more than the {MAX_IN_MEMORY_BYTES / 2**30:g} GiB limit; pass "
            "store= a folder to stream the map into Zarr (or a larger voxel, fewer "
            "orientations, a smaller region)",
        )


def _run_in_memory(job: ReachJob, shell: ReachMap, ranges: list[tuple[int, int]],
                   scheduler: Any, progress: Progress) -> ReachMap:
    V, K = job.grid.size, job.orientations.shape[0]
    counts = np.zeros((V, K), np.uint8)
    index = np.zeros(V)
    solutions = np.zeros(V, np.int32)
    best = np.zeros(V) if job.with_manipulability else None

    def on_result(i: int, r: ReachChunk) -> None:
        a, b = r.start, r.stop
        if r.counts is None or r.index is None or r.solutions is None:
            raise RuntimeError(f"chunk {i} returned no arrays")  # pragma: no cover
        counts[a:b] = r.counts
        index[a:b] = r.index
        solutions[a:b] = r.solutions
        if best is not None and r.manipulability is not None:
            best[a:b] = r.manipulability

    with progress_callback(progress, len(ranges), "reach map", scheduler) as tick:
        run_chunks(evaluate_reach, job, ranges, scheduler=scheduler,
                   on_result=on_result, progress=tick, name="robokin-reach")
    for arr in (counts, index, solutions, best):
        if arr is not None:
            arr.setflags(write=False)
    return ReachMap(shell.robot_name, shell.grid, shell.orientations, counts, index,
                    solutions, best, shell.method, shell.scene, shell.base)


def _run_into_store(job: ReachJob, shell: ReachMap, ranges: list[tuple[int, int]],
                    path: Path, fingerprint: str, scheduler: Any, progress: Progress,
                    overwrite: bool) -> ReachMap:
    import uuid
    from dataclasses import replace

    B = ranges[0][1] - ranges[0][0]
    done = _prepare_store(path, shell, job, B, fingerprint, overwrite)
    todo = [i for i in range(len(ranges)) if not done[i]]
    path = path.resolve()
    job = replace(job, store=str(path), store_token=uuid.uuid4().hex)
    finished: list[int] = []

    def record() -> None:
        _store.mark_done(path, finished)
        finished.clear()

    flush = Throttle(record, 2.0)

    def on_result(k: int, r: ReachChunk) -> None:
        finished.append(todo[k])  # the k-th task run is chunk todo[k]
        flush()

    with progress_callback(progress, len(todo), f"reach map -> {path.name}", scheduler) as tick:
        try:
            run_chunks(evaluate_reach, job, [ranges[i] for i in todo],
                       scheduler=scheduler, on_result=on_result, progress=tick,
                       name="robokin-reach")
        finally:
            flush.flush()
    _store.finish(path)
    return ReachMap.load(path, lazy=True)


def _prepare_store(path: Path, shell: ReachMap, job: ReachJob, chunk: int,
                   fingerprint: str, overwrite: bool) -> np.ndarray:
    """The done flags of the store at ``path``: created empty, or resumed."""
    try:
        done = _resume_store(path, fingerprint, overwrite)
    except OSError as exc:
        raise InputError("store", f"{path}: cannot use it as a store: "
                         f"{exc.strerror or exc}") from None
    if done is not None:
        return done
    if not path.parent.is_dir():
        raise InputError("store", f"{path}: the folder {path.parent} does not exist")
    _store.create(path, shell._attrs(chunk, fingerprint), voxels=job.grid.size,
                  orientations=job.orientations, chunk=chunk,
                  with_manipulability=job.with_manipulability, argument="store")
    return np.zeros(-(-job.grid.size // chunk), dtype=bool)


def _resume_store(path: Path, fingerprint: str, overwrite: bool) -> np.ndarray | None:
    """The done flags of the same map at ``path``, or None once ``path`` is free.

    An empty folder is removed, another map replaced (with ``overwrite``).
    """
    if not path.exists():
        return None
    if path.is_dir() and not any(path.iterdir()):
        path.rmdir()
        return None
    g = _store.open_map(path, argument="store")
    if g.attrs.get("fingerprint") == fingerprint:
        return _store.read_done(path)
    if not overwrite:
        raise InputError(
            "store",
            f"{path} holds a different map (robot {g.attrs.get('robot')!r}, "
            f"voxel {float(g.attrs.get('voxel', 0)) * 1000:g} mm, grid "
            f"{g.attrs.get('shape')}); choose another store or pass "
            "overwrite=True",
        )
    shutil.rmtree(path)
    return None


# ------------------------------------------------------------------ helpers
def _orientations(orientations: int | npt.ArrayLike, rolls: int) -> np.ndarray:
    if isinstance(orientations, int | np.integer) and not isinstance(orientations, bool):
        return tool_orientations(int(orientations), rolls)
    from robokin._validation import check_transform

    try:
        R = np.asarray(orientations, dtype=np.float64)
    except (TypeError, ValueError):
        raise InputError(
            "orientations",
            f"expected a count or rotation matrices (K, 3, 3), got {short_repr(orientations)}",
        ) from None
    if R.ndim != 3 or R.shape[1:] != (3, 3) or R.shape[0] == 0:
        raise InputError(
            "orientations",
            f"expected a count or rotation matrices (K, 3, 3) with K >= 1, got shape {R.shape}",
        )
    T = np.zeros((R.shape[0], 4, 4))
    T[:, :3, :3] = R
    T[:, 3, 3] = 1.0
    check_transform(T, "orientations")
    out = np.ascontiguousarray(R)
    return out


def _default_chunk(V: int, K: int) -> int:
    B = max(1, _POSES_PER_TASK // max(K, 1))
    B = max(B, -(-V // _MAX_TASKS))
    return min(B, max(V, 1))


def _chunk(chunk: int | None, V: int, K: int) -> int:
    if chunk is None:
        return _default_chunk(V, K)
    if isinstance(chunk, bool) or not isinstance(chunk, int | np.integer) or chunk < 1:
        raise InputError("chunk", f"expected voxels per task >= 1, got {short_repr(chunk)}")
    return min(int(chunk), V)


def _fingerprint(job: ReachJob, chunk: int) -> str:
    """What the map's content depends on, hashed (for resuming a store)."""
    from robokin.cell._facts import describe_robot, describe_scene

    h = hashlib.sha256()
    for part in (
        describe_robot(job.robot),
        describe_scene(job.scene) if job.scene is not None else b"",
        job.grid.origin.tobytes(),
        np.float64(job.grid.voxel).tobytes(),
        np.array(job.grid.shape, np.int64).tobytes(),
        job.orientations.tobytes(),
        b"numeric" if job.numeric else b"analytic",
        (job.sweep or "").encode(),
        b"w" if job.with_manipulability else b"-",
        np.int64(chunk).tobytes(),
    ):
        h.update(part)
        h.update(b"|")
    return h.hexdigest()
