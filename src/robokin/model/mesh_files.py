"""Mesh files: whether a path can be read as one, and reading it (with trimesh).

Used by :mod:`robokin.model.geometry` (a shape's mesh) and the readers of robot,
scene and URDF files (:func:`mesh_file_problem`, re-exported by geometry).
"""

from __future__ import annotations

import os
import stat
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from robokin.exceptions import ModelError

if TYPE_CHECKING:
    from trimesh import Trimesh

__all__ = ["load_mesh", "mesh_file_problem"]


_FILE_KINDS = ((stat.S_ISDIR, "a folder"), (stat.S_ISFIFO, "a FIFO (named pipe)"),
               (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"),
               (stat.S_ISSOCK, "a socket"))


def mesh_file_problem(path: str | Path) -> str | None:
    """Why ``path`` cannot be read as a mesh file, or None when it can.

    A mesh is read only from a regular file: a folder, a FIFO, a device
    (``/dev/zero``) or a symlink to one is reported as not a regular file (never
    opened: a FIFO would block, ``/dev/zero`` never ends); a path that does not
    exist as "no such file".
    """
    try:
        st = os.stat(path)  # follows a symlink: its target is what would be read
    except FileNotFoundError:
        return f"no such file {path}"
    except OSError as exc:
        return f"cannot read {path}: {exc.strerror or exc}"
    if stat.S_ISREG(st.st_mode):
        return None
    kind = next((k for test, k in _FILE_KINDS if test(st.st_mode)), "not a file")
    via = " (through a symlink)" if os.path.islink(path) else ""
    return f"{path} is not a regular file: {kind}{via}"


def load_mesh(path: Path | None, scale: float, owner: str, max_bytes: int) -> Trimesh:
    """The mesh file at ``path`` as a Trimesh scaled by ``scale`` (to metres).

    Raises:
        ModelError: a missing file or one that is not a regular file, more than
            ``max_bytes``, not readable as a mesh, without triangles or with
            non-finite vertices (naming the file and the link ``owner``).
    """
    import trimesh

    where = f" (link '{owner}')" if owner else ""
    if path is None:
        raise ModelError(f"mesh file not found{where}", file=path, field=owner or None)
    problem = mesh_file_problem(path)
    if problem is not None:
        what = "not found" if problem.startswith("no such file") else f": {problem}"
        raise ModelError(f"mesh file {what}{where}".replace(" :", ":"), file=path,
                         field=owner or None)
    size = Path(path).stat().st_size
    if size > max_bytes:
        raise ModelError(f"mesh file of {size:,} bytes{where}, more than the "
                         f"{max_bytes:,} robokin loads (robokin.model.geometry."
                         "MAX_MESH_BYTES)", file=path, field=owner or None)
    try:
        loaded = trimesh.load(str(path), force="mesh")
    except Exception as exc:  # trimesh raises many kinds on a bad file
        raise ModelError(
            f"cannot read mesh{where}: {type(exc).__name__}: {exc}"[:300],
            file=path,
            field=owner or None,
        ) from None
    faces = getattr(loaded, "faces", None)
    vertices = getattr(loaded, "vertices", None)
    if faces is None or vertices is None or len(faces) == 0 or len(vertices) < 4:
        raise ModelError(
            f"mesh file holds no triangles{where}", file=path, field=owner or None
        )
    if not np.isfinite(np.asarray(vertices)).all():
        raise ModelError(
            f"mesh file holds non-finite vertices{where}",
            file=path,
            field=owner or None,
        )
    m = trimesh.Trimesh(
        vertices=np.asarray(vertices, dtype=np.float64) * scale,
        faces=np.asarray(faces),
        process=False,
    )
    return m
