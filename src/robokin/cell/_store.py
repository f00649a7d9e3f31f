"""The Zarr layout of a reachability map, written chunk by chunk.

A map is a Zarr (v3) group::

    counts          (V, K) uint8    solutions per voxel and orientation
    index           (V,)   float64  reachability index
    solutions       (V,)   int32    solutions per voxel (sum over orientations)
    manipulability  (V,)   float64  best manipulability (only when computed)
    orientations    (K, 3, 3) float64
    done            (C,)   bool     which task chunks are written
    attrs: format, version, robot, fingerprint, origin, voxel, shape, chunk,
           method, scene, complete

The per-voxel arrays are chunked exactly as the Dask tasks split the voxels,
so each task writes whole Zarr chunks of its own and no two tasks ever write
the same file. Only the driver writes ``done`` and the attributes. A run that
stops part-way leaves ``complete`` False; running the same map into the same
store again computes only the chunks not marked done.
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

import numpy as np

from robokin.exceptions import InputError

__all__ = [
    "FORMAT",
    "create",
    "finish",
    "mark_done",
    "open_map",
    "publish",
    "read_done",
    "write_chunk",
]

FORMAT = "robokin.reach_map"
VERSION = 1
_DONE_CHUNK = 65536


def _zarr() -> Any:
    from robokin.cell._scheduler import require_scale

    require_scale()
    import zarr

    return zarr


def create(path: str | Path, attrs: Mapping[str, Any], *, voxels: int,
           orientations: np.ndarray, chunk: int, with_manipulability: bool,
           argument: str | None = "store") -> None:
    """Create an empty map store at ``path`` (which must not exist).

    Args:
        path: The store folder to create.
        attrs: The map's attributes (see the module docstring).
        voxels: Number of voxels V.
        orientations: Tool orientations (K, 3, 3).
        chunk: Voxels per Zarr chunk (per task).
        with_manipulability: Add the manipulability array.
        argument: The argument named when a file operation fails, or None to
            let the OSError through (inside :func:`publish`, which names the
            user's path instead of its temporary one).

    Raises:
        InputError: the store cannot be created (read-only folder, full disk,
            a name too long...), naming ``argument`` and ``path``.
    """
    try:
        _create(path, attrs, voxels=voxels, orientations=orientations, chunk=chunk,
                with_manipulability=with_manipulability)
    except OSError as exc:
        if argument is None:
            raise
        raise InputError(argument, f"{path}: cannot create the store: "
                         f"{exc.strerror or exc}") from None


def _create(path: str | Path, attrs: Mapping[str, Any], *, voxels: int,
            orientations: np.ndarray, chunk: int, with_manipulability: bool) -> None:
    zarr = _zarr()
    K = orientations.shape[0]
    n_chunks = -(-voxels // chunk)
    g = zarr.open_group(store=str(path), mode="w-")
    g.create_array("counts", shape=(voxels, K), chunks=(chunk, K), dtype="uint8",
                   fill_value=0)
    g.create_array("index", shape=(voxels,), chunks=(chunk,), dtype="float64",
                   fill_value=0.0)
    g.create_array("solutions", shape=(voxels,), chunks=(chunk,), dtype="int32",
                   fill_value=0)
    if with_manipulability:
        g.create_array("manipulability", shape=(voxels,), chunks=(chunk,),
                       dtype="float64", fill_value=0.0)
    o = g.create_array("orientations", shape=orientations.shape,
                       chunks=orientations.shape, dtype="float64", fill_value=0.0)
    o[...] = orientations
    g.create_array("done", shape=(n_chunks,), chunks=(min(n_chunks, _DONE_CHUNK),),
                   dtype="bool", fill_value=False)
    g.attrs.update({"format": FORMAT, "version": VERSION, **attrs, "complete": False})


def write_chunk(path: str, start: int, stop: int,
                arrays: Mapping[str, np.ndarray | None], token: str = "") -> None:
    """Write one task's voxels ``start .. stop - 1`` (whole Zarr chunks).

    The opened arrays are kept per process under ``(path, name, token)`` (opening
    costs more than writing a chunk); ``token`` names one run writing the store,
    so a store replaced at the same path by another run is opened afresh.
    """
    for name, data in arrays.items():
        if data is not None:
            _open_array(path, name, token)[start:stop] = data


def _open_array(path: str, name: str, token: str) -> Any:
    key = (path, name, token)
    arr = _OPENED.get(key)
    if arr is None or not token:
        zarr = _zarr()
        arr = zarr.open_array(store=path, path=name, mode="r+")
        if token:
            while len(_OPENED) >= _OPENED_MAX:
                _OPENED.pop(next(iter(_OPENED)), None)
            _OPENED[key] = arr
    return arr


_OPENED: dict[tuple[str, str, str], Any] = {}
_OPENED_MAX = 32


def mark_done(path: str | Path, chunks: Iterable[int]) -> None:
    """Record task chunks as written (driver only)."""
    idx = np.fromiter(chunks, dtype=np.int64)
    if idx.size == 0:
        return
    zarr = _zarr()
    done = zarr.open_array(store=str(path), path="done", mode="r+")
    flags = done[:]
    flags[idx] = True
    done[:] = flags


def read_done(path: str | Path) -> np.ndarray:
    """(C,) bool: which task chunks are written."""
    zarr = _zarr()
    return np.asarray(zarr.open_array(store=str(path), path="done", mode="r")[:])


def finish(path: str | Path) -> None:
    """Mark the map complete (every chunk written)."""
    zarr = _zarr()
    g = zarr.open_group(store=str(path), mode="r+")
    g.attrs["complete"] = True


def open_map(path: str | Path, argument: str = "path") -> Any:
    """The Zarr group of a map store, or :class:`InputError` naming ``argument``."""
    zarr = _zarr()
    p = Path(path)
    if not p.exists():
        raise InputError(argument, f"{p} does not exist")
    try:
        g = zarr.open_group(store=str(p), mode="r")
        fmt = g.attrs.get("format")
    except Exception as exc:  # zarr raises several kinds for a non-store folder
        raise InputError(
            argument, f"{p} is not a reachability map ({type(exc).__name__}: {exc})"
        ) from None
    if fmt != FORMAT:
        raise InputError(argument, f"{p} is not a reachability map (format {fmt!r})")
    if int(g.attrs.get("version", 0)) > VERSION:
        raise InputError(
            argument,
            f"{p} was written by a newer robokin (map version {g.attrs['version']})",
        )
    return g


def publish(path: str | Path, *, overwrite: bool, argument: str = "path"
            ) -> contextlib.AbstractContextManager[Path]:
    """Write a store into a fresh folder beside ``path``, then rename it into place.

    Zarr writes its many files itself, so the store is built in a temporary
    folder and appears at ``path`` in one rename: a reader sees the old map or
    the new one, never half of one; on any failure the temporary folder goes
    (:func:`robokin.io.atomic.publish_folder`).

    Returns:
        A context manager yielding the path to create the store at.

    Raises:
        InputError: the folder of ``path`` is missing, ``path`` exists (without
            ``overwrite``) or is a file, or a file operation fails (naming
            ``argument`` and ``path``).
    """
    from robokin.io.atomic import publish_folder

    return publish_folder(path, overwrite=overwrite, argument=argument)
