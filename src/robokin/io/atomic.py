"""The one atomic writer: every file robokin writes goes through :func:`write_atomic`.

A file is written to a temporary file made with :func:`tempfile.mkstemp` in the
target's folder (a fresh random name, opened with ``O_EXCL``: a planted file or
symlink is never followed), flushed and fsynced, given the permissions an
ordinary new file would have (or the replaced file's), then renamed over the
target. A reader sees the old content or the new, never a half-written file; a
crash or a kill leaves the old file intact; on any failure the temporary file
is removed. A symlink at the target itself is replaced, not written through.

A folder of many files written by another library (a Zarr store) is built in a
fresh temporary folder beside the target and renamed into place the same way
(:func:`publish_folder`).

Errors are :class:`~robokin.exceptions.InputError` naming the user's path (never
the temporary one), one line: a missing folder, a folder given as the file, a
read-only folder, a full disk.
"""

from __future__ import annotations

import contextlib
import os
import re
import shutil
import stat
import tempfile
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from typing import IO, Any

from robokin.exceptions import InputError

__all__ = [
    "check_distinct",
    "file_stem",
    "new_file_mode",
    "publish_folder",
    "save_figure_atomic",
    "staged_outputs",
    "write_atomic",
]

Content = str | bytes | Callable[[IO[bytes]], Any]


def file_stem(name: str, limit: int = 80) -> str:
    """A file-name stem made from a name (a robot's, from a file).

    Letters, digits, ``.``, ``-`` and ``_`` are kept, anything else (``/``,
    ``..``) becomes ``_``, at most ``limit`` characters; never empty or hidden.
    """
    stem = re.sub(r"[^A-Za-z0-9._-]", "_", str(name))[:limit].lstrip(".")
    return stem or "robot"


def new_file_mode() -> int:
    """Permissions of a new file under the current umask (mkstemp makes 0600)."""
    mask = os.umask(0)
    os.umask(mask)
    return 0o666 & ~mask


def _check_target(path: Path, overwrite: bool, argument: str,
                  how: str = "pass overwrite=True") -> Path:
    folder = path.parent if str(path.parent) else Path(".")
    if path.is_dir():
        raise InputError(argument, f"{path} is a folder, expected a file name")
    if not folder.is_dir():
        raise InputError(argument, f"{path}: the folder {folder} does not exist")
    if not overwrite and os.path.lexists(path):
        raise InputError(argument, f"{path} exists; {how} to replace it")
    return folder


def _target_mode(path: Path) -> int:
    try:
        st = os.lstat(path)
    except OSError:
        return new_file_mode()
    return stat.S_IMODE(st.st_mode) if stat.S_ISREG(st.st_mode) else new_file_mode()


def write_atomic(
    path: str | Path, content: Content, *, overwrite: bool = True,
    argument: str = "path", encoding: str = "utf-8",
) -> Path:
    """Write ``content`` to ``path`` atomically (see the module docstring).

    Args:
        path: The target file.
        content: Text (written in ``encoding``, newlines as given), bytes, or a
            function ``write(fh)`` that writes to a binary file object (e.g.
            ``fig.savefig``).
        overwrite: Replace an existing file (False: refuse).
        argument: The argument or option name used in error messages.
        encoding: Encoding of text content.

    Returns:
        ``path``.

    Raises:
        InputError: the folder is missing or read-only, ``path`` is a folder, it
            exists and ``overwrite`` is False, or the write fails (naming
            ``path``).
    """
    path = Path(path)
    folder = _check_target(path, overwrite, argument)
    mode = _target_mode(path)
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=folder)
    except OSError as exc:
        raise InputError(argument, f"{path}: cannot write in {folder}: "
                         f"{exc.strerror or exc}") from None
    try:
        with os.fdopen(fd, "wb") as fh:
            if callable(content):
                content(fh)
            else:
                fh.write(content.encode(encoding) if isinstance(content, str)
                         else content)
            fh.flush()
            os.fsync(fh.fileno())
        os.chmod(tmp, mode)
        os.replace(tmp, path)
    except BaseException as exc:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        if isinstance(exc, OSError):
            raise InputError(argument, f"{path}: cannot write: "
                             f"{exc.strerror or exc}") from None
        raise
    _sync_folder(folder)
    return path


def _sync_folder(folder: Path) -> None:
    """Make the rename durable (best effort: not every system can open a folder)."""
    try:
        fd = os.open(folder, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def save_figure_atomic(
    fig: Any, path: str | Path, *, overwrite: bool = True, argument: str = "path",
    **savefig: Any,
) -> Path:
    """Save a matplotlib figure through :func:`write_atomic`.

    The format comes from the suffix of ``path`` (``savefig(format=...)``), since
    the temporary file's name ends in ``.tmp``.

    Args:
        fig: A matplotlib ``Figure``.
        path: The target file (``.png``, ``.svg``, ``.pdf``, ...).
        overwrite: Replace an existing file.
        argument: The argument or option name used in error messages.
        **savefig: Passed to ``fig.savefig`` (``dpi``, ...).

    Raises:
        InputError: as :func:`write_atomic`.
    """
    path = Path(path)
    fmt = savefig.pop("format", None) or path.suffix[1:].lower() or "png"
    return write_atomic(path, lambda fh: fig.savefig(fh, format=fmt, **savefig),
                        overwrite=overwrite, argument=argument)


@contextlib.contextmanager
def staged_outputs(
    targets: Sequence[tuple[str | Path, str, bool]], *, how: str = "pass overwrite=True"
) -> Iterator[list[Path]]:
    """Write several files all or none: a command's outputs are never left half-made.

    Every target is checked first (its folder exists, it is not a folder, it does
    not exist unless it may be replaced). The body writes each file to the staging
    path yielded for it (in a fresh private folder next to the target, so the final
    rename stays on one file system); when the body returns, every staged file is
    renamed onto its target. If the body raises, nothing is moved and the staging
    folders are removed: the targets are as they were.

    Args:
        targets: ``(path, argument, overwrite)`` per output: the file, the option
            naming it in messages, and whether an existing file may be replaced.
        how: What the user does to allow replacing (``"pass --force"``), for the
            message of a target that exists.

    Yields:
        The staging path of each target, in order (write there, not to the target).

    Raises:
        InputError: a target cannot be written (named with its argument), or two
            targets are the same file.
    """
    checked = [(Path(p), arg, over) for p, arg, over in targets]
    check_distinct([(path, arg) for path, arg, _ in checked])
    for path, arg, over in checked:
        _check_target(path, over, arg, how)
    stages: dict[Path, Path] = {}
    staged: list[Path] = []
    try:
        for path, arg, _ in checked:
            folder = path.parent if str(path.parent) else Path(".")
            if folder not in stages:
                try:
                    stages[folder] = Path(tempfile.mkdtemp(prefix=".robokin-", dir=folder))
                except OSError as exc:
                    raise InputError(arg, f"{path}: cannot write in {folder}: "
                                     f"{exc.strerror or exc}") from None
            staged.append(stages[folder] / path.name)
        yield staged
        for (path, _, _), tmp in zip(checked, staged):
            if tmp.exists():
                os.chmod(tmp, _target_mode(path))
                os.replace(tmp, path)
        for folder in stages:
            _sync_folder(folder)
    finally:
        for stage in stages.values():
            shutil.rmtree(stage, ignore_errors=True)


def _output_key(path: Path) -> tuple[str, ...]:
    """What identifies the file a write to ``path`` replaces.

    The folder resolved (symlinks, ``..``) and the name; an existing file also
    by device and inode (a hard link is the same file), and a symlink also by
    its target (a write replaces the link, which the user made to name it).
    """
    keys = [os.path.join(os.path.realpath(path.parent if str(path.parent) else "."),
                         path.name)]
    with contextlib.suppress(OSError):
        st = os.lstat(path)
        keys.append(f"{st.st_dev}:{st.st_ino}")
    if os.path.islink(path):
        keys.append(os.path.realpath(path))
    return tuple(keys)


def _input_keys(path: Path) -> tuple[str, ...]:
    """What identifies the file read from ``path``: the link and its target."""
    keys = list(_output_key(path))
    keys.append(os.path.realpath(path))
    with contextlib.suppress(OSError):
        st = os.stat(path)
        keys.append(f"{st.st_dev}:{st.st_ino}")
    return tuple(keys)


def check_distinct(outputs: Sequence[tuple[str | Path, str]],
                   inputs: Sequence[tuple[str | Path | None, str]] = ()) -> None:
    """Refuse two outputs that are one file, and an output that is an input.

    A command with several outputs (``robokin traj -o X.csv --ros2 X.csv``)
    would write the second over the first, and an output named like an input
    (``robokin sim ... out/simulated.csv --out out``) would replace what the user
    wrote: both are refused before anything is computed or written.

    Args:
        outputs: ``(path, argument)`` per file to write (the option naming it).
        inputs: ``(path, argument)`` per file read (None: not a file, skipped).

    Raises:
        InputError: naming the output's argument, the file and the other
            argument.
    """
    read: dict[str, str] = {}
    for path, arg in inputs:
        if path is None:
            continue
        for key in _input_keys(Path(path)):
            read.setdefault(key, arg)
    written: dict[str, str] = {}
    for path, arg in outputs:
        keys = _output_key(Path(path))
        other = next((read[k] for k in keys if k in read), None)
        if other is not None:
            raise InputError(arg, f"{path} is the input {other}; robokin never writes "
                             "over a file it reads: choose another name")
        other = next((written[k] for k in keys if k in written), None)
        if other is not None:
            raise InputError(arg, f"{path} is also the output of {other}; choose "
                             "another name")
        for k in keys:
            written[k] = arg


def _cannot_write(path: Path, argument: str, exc: OSError, folder: Path | None = None
                  ) -> InputError:
    """The one-line error for an OSError writing ``path`` (in ``folder``)."""
    where = f" in {folder}" if folder is not None else ""
    return InputError(argument, f"{path}: cannot write{where}: {exc.strerror or exc}")


def _check_folder_target(path: Path, overwrite: bool, argument: str) -> Path:
    """The parent folder of a folder target, after the checks of :func:`publish_folder`."""
    parent = path.parent if str(path.parent) else Path(".")
    if not os.path.isdir(parent):
        raise InputError(argument, f"{path}: the folder {parent} does not exist")
    if os.path.exists(path) and not overwrite:
        raise InputError(argument, f"{path} exists; pass overwrite=True to replace it")
    if os.path.exists(path) and not os.path.isdir(path):
        raise InputError(argument, f"{path} is a file, expected a store folder")
    return parent


@contextlib.contextmanager
def publish_folder(
    path: str | Path, *, overwrite: bool = False, argument: str = "path"
) -> Iterator[Path]:
    """Build a folder beside ``path``, then rename it into place in one step.

    For folders of many files written by another library (a Zarr store): the
    folder is built inside a fresh private folder made with
    :func:`tempfile.mkdtemp` next to ``path`` (the same file system), and
    appears at ``path`` in one rename when the body returns. A reader sees the
    old folder or the new one, never half of one; if the body raises, ``path``
    is as it was. The temporary folder is removed in every case.

    Args:
        path: The folder to create (or replace).
        overwrite: Replace an existing folder (False: refuse).
        argument: The argument or option name used in error messages.

    Yields:
        The path to build the folder at (it does not exist yet; its parent
        does).

    Raises:
        InputError: the parent folder is missing, ``path`` exists (without
            ``overwrite``) or is a file, or a file operation fails (read-only
            folder, full disk, name too long...), naming ``path`` (never the
            temporary folder). Other errors of the body propagate unchanged.
    """
    target = Path(path)
    parent = _check_folder_target(target, overwrite, argument)
    try:
        tmp = Path(tempfile.mkdtemp(prefix=f".{target.name}.", suffix=".tmp", dir=parent))
    except OSError as exc:
        raise _cannot_write(target, argument, exc, parent) from None
    built = tmp / "store"
    try:
        yield built
        if os.path.exists(target):
            os.replace(target, tmp / "old")
        os.replace(built, target)
    except OSError as exc:
        raise _cannot_write(target, argument, exc) from None
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    _sync_folder(parent)
