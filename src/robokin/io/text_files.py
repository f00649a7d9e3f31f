"""Reading user files with bounds: size, binary content, folders, encodings.

Every file robokin reads (robot, scene, motion, profile, URDF, CSV) comes through
:func:`read_file_bytes` or :func:`read_text_file`, so a wrong path gives one clear
:class:`~robokin.exceptions.ModelError` naming the file, and no file can make
robokin read more than a cap (raise it with ``max_bytes=``).
"""

from __future__ import annotations

import os
from pathlib import Path

from robokin.exceptions import ModelError

__all__ = ["MAX_CSV_BYTES", "MAX_TEXT_BYTES", "read_file_bytes", "read_text_file"]

#: Default cap for robot, scene, motion, profile and URDF files [bytes] (16 MiB).
MAX_TEXT_BYTES = 16 * 2**20
#: Default cap for CSV trajectories and logs [bytes] (64 MiB: about a million rows;
#: the reader keeps every value as a Python float while it parses).
MAX_CSV_BYTES = 64 * 2**20


def read_file_bytes(path: str | Path, *, max_bytes: int = MAX_TEXT_BYTES) -> bytes:
    """The bytes of a regular file, refusing folders, devices and oversized files.

    Args:
        path: The file.
        max_bytes: The largest size accepted [bytes].

    Returns:
        The file's content.

    Raises:
        ModelError: no such file, a folder, not a regular file, unreadable, or
            larger than ``max_bytes`` (naming the file and the cap).
    """
    path = Path(path)
    try:
        st = os.stat(path)
    except FileNotFoundError:
        raise ModelError("no such file", file=path) from None
    except OSError as exc:
        raise ModelError(f"cannot read: {exc.strerror}", file=path) from None
    if path.is_dir():
        raise ModelError("is a folder, expected a file", file=path)
    if not path.is_file():
        raise ModelError("is not a regular file", file=path)
    if st.st_size > max_bytes:
        raise ModelError(
            f"is {st.st_size:,} bytes, more than the {max_bytes:,} bytes robokin "
            "reads (pass max_bytes= to raise the cap)",
            file=path,
        )
    try:
        with open(path, "rb") as fh:
            data = fh.read(max_bytes + 1)
    except OSError as exc:
        raise ModelError(f"cannot read: {exc.strerror}", file=path) from None
    if len(data) > max_bytes:  # grew since stat
        raise ModelError(f"is more than the {max_bytes:,} bytes robokin reads",
                         file=path)
    return data


def read_text_file(path: str | Path, *, max_bytes: int = MAX_TEXT_BYTES) -> str:
    """The text of a UTF-8 file (see :func:`read_file_bytes` for the checks).

    Raises:
        ModelError: as :func:`read_file_bytes`, or a binary file (a NUL byte, or
            bytes that are not UTF-8), naming the file and the line.
    """
    data = read_file_bytes(path, max_bytes=max_bytes)
    nul = data.find(b"\0")
    if nul >= 0:
        raise ModelError("is a binary file, expected text",
                         file=path, line=data.count(b"\n", 0, nul) + 1)
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise ModelError("is not UTF-8 text (a binary file?)", file=path,
                         line=data.count(b"\n", 0, exc.start) + 1) from None
    return text.removeprefix("\ufeff")
