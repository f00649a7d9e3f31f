"""xacro in: expand a ``.xacro`` / ``.urdf.xacro`` file to URDF without ROS.

:func:`expand_xacro` runs ros/xacro (the ROS reference expander, from PyPI: the
``robokin[ros]`` extra) on a file, with ``<xacro:arg>`` values given as
``args``; ``$(find NAME)`` and ``${find('NAME')}`` resolve through a
:class:`~robokin.io.ros_packages.PackageFinder` (the package map,
``ROS_PACKAGE_PATH``, ``AMENT_PREFIX_PATH``, the folders above the file). The
expanded URDF is read by :func:`robokin.io.urdf.parts_from_urdf`, which resolves
``package://`` meshes through the same finder.

Why ros/xacro directly and not xacrodoc (the library first chosen): xacrodoc 2.0
reads the file into a string before expanding it, so a relative
``<xacro:include filename="part.xacro"/>`` resolves against the current
directory rather than the including file ("No such file or directory:
././part.xacro"), and it resolves ``package://`` meshes itself, stopping at the
first package it cannot find, where robokin reports every dropped mesh and goes
on. xacro's own ``process_file`` does neither; the package lookup xacrodoc
adds is :mod:`robokin.io.ros_packages` here.

Errors are :class:`~robokin.exceptions.ModelError` naming the file being
expanded (an included file when the error is there), the line for malformed
XML, and for a missing package the places searched.

A xacro file is a program: its ``${...}`` expressions are Python evaluated by
xacro (without builtins) and it may include any file it names. A 300-byte file
can compute ``${9**9**9}`` until killed or build a gigabyte string, so every
expansion runs in a child process (forked: it starts in milliseconds with
xacro already imported) under :data:`LIMITS` (:class:`XacroLimits`): CPU time
(``RLIMIT_CPU``), memory (``RLIMIT_AS``, counted from what the child starts
with) and a wall-clock timeout (a xacro that includes a FIFO waits forever).
A file that goes over ends in one :class:`~robokin.exceptions.ModelError`
naming the file and the limit; raise the limits with ``limits=`` or by setting
:data:`LIMITS`. The child sees nothing of the caller but the file, the
arguments and the package finder, and sends back only the URDF text, the files
it included, xacro's warnings and the packages it found, as JSON. Where there is no
``fork`` or no ``resource`` module (Windows) the expansion runs in this process,
unbounded. xacro keeps its state in module globals: each child has its own copy;
in-process expansions are serialised by a lock.
"""

from __future__ import annotations

import contextlib
import io
import json
import math
import os
import re
import signal
import threading
import time
import warnings
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from robokin._text import short_repr
from robokin.exceptions import InputError, MissingExtraError, ModelError
from robokin.io.ros_packages import PackageFinder
from robokin.io.text_files import read_file_bytes

__all__ = ["LIMITS", "XacroExpansion", "XacroLimits", "expand_xacro", "is_xacro"]

_LOCK = threading.Lock()


@dataclass(frozen=True)
class XacroLimits:
    """What one xacro expansion may cost (it runs in a child process).

    The defaults leave a large margin over real robot descriptions (the
    rtb-data vendor xacros expand in 10 to 60 ms and a few MB) and stop a
    hostile file within a few seconds and about 200 MB.

    Attributes:
        cpu_seconds: CPU time of the child [s] (whole seconds, >= 1).
        wall_seconds: Wall-clock time before the child is killed [s] (> 0).
        memory_mb: Memory the child may add to what it starts with [MiB]
            (address space; Linux).
    """

    cpu_seconds: int = 2
    wall_seconds: float = 3.0
    memory_mb: int = 192

    def __post_init__(self) -> None:
        """Check the limits."""
        for name, low in (("cpu_seconds", 1), ("memory_mb", 16)):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, int) or v < low:
                raise InputError("limits", f"{name}: expected a whole number >= {low}, "
                                 f"got {short_repr(v)}")
        w = self.wall_seconds
        if isinstance(w, bool) or not isinstance(w, int | float) or not (
                math.isfinite(w) and w > 0):
            raise InputError("limits", f"wall_seconds: expected seconds > 0, got "
                             f"{short_repr(w)}")


#: The limits of every expansion (``expand_xacro(..., limits=)`` overrides them for
#: one call; assign a new :class:`XacroLimits` here to change them for all,
#: ``Robot.from_urdf`` and ``robokin import`` included).
LIMITS = XacroLimits()


def is_xacro(source: object) -> bool:
    """True for a path (not XML text) whose name ends in ``.xacro``."""
    if isinstance(source, bytes):
        return False
    if isinstance(source, str) and source.lstrip().startswith("<"):
        return False
    return isinstance(source, (str, Path)) and str(source).lower().endswith(".xacro")


@dataclass(frozen=True)
class XacroExpansion:
    """The result of :func:`expand_xacro`.

    Attributes:
        urdf: The expanded URDF (XML text).
        file: The xacro file expanded.
        packages: The finder that resolved ``$(find ...)``; it resolves the
            URDF's ``package://`` meshes too.
        includes: Every file the expansion included, in order.
        args: The ``<xacro:arg>`` values given.
    """

    urdf: str
    file: Path
    packages: PackageFinder
    includes: tuple[Path, ...]
    args: Mapping[str, str]


def _xacro() -> Any:
    try:
        import xacro
        from xacro import substitution_args  # noqa: F401 - imported by _finder_installed
    except ImportError:
        raise MissingExtraError("xacro", "ros") from None
    return xacro


_WARM = threading.Event()
# robokin's own document, expanded once in this process: xacro compiles its
# regular expressions and imports what it needs on first use (about 40 ms), and
# each child forked afterwards starts with that done
_WARM_UP = ('<robot xmlns:xacro="http://www.ros.org/wiki/xacro" name="w">'
            '<xacro:property name="a" value="1"/><xacro:macro name="m" params="x">'
            '<link name="${x}"/></xacro:macro><xacro:m x="${a * 2}"/>'
            '<link name="$(arg q)"/></robot>')


def _warm_up(xacro: Any) -> None:
    """Expand :data:`_WARM_UP` once per process (before children are forked)."""
    if _WARM.is_set():
        return
    with _LOCK, contextlib.redirect_stderr(io.StringIO()):
        if not _WARM.is_set():
            xacro.all_includes = []
            doc = xacro.parse(_WARM_UP)
            xacro.process_doc(doc, mappings={"q": "1"})
            doc.toprettyxml(indent="  ")
            _WARM.set()


class _PackageMissing(Exception):
    """Raised inside xacro by the finder; turned into a ModelError outside."""


@contextlib.contextmanager
def _finder_installed(xacro: Any, finder: PackageFinder) -> Iterator[None]:
    """Route xacro's ``$(find)`` and ``${find()}`` through ``finder``."""
    from xacro import substitution_args as sa

    def find(name: str) -> str:
        path = finder.find(str(name))
        if path is None:
            raise _PackageMissing(f"$(find {name}): {finder.not_found(str(name))}")
        return str(path)

    saved = sa._eval_find, sa._eval_dict.get("find")
    sa._eval_find = find
    sa._eval_dict["find"] = find
    try:
        yield
    finally:
        sa._eval_find = saved[0]
        sa._eval_dict["find"] = saved[1]


def _check_args(args: Mapping[str, str] | None) -> dict[str, str]:
    out: dict[str, str] = {}
    for name, value in (args or {}).items():
        if not isinstance(name, str) or not name.strip() or ":=" in name:
            raise InputError("xacro_args", f"an argument name must be non-empty "
                             f"text, got {short_repr(name)}")
        if not isinstance(value, (str, int, float, bool)):
            raise InputError("xacro_args", f"argument '{name}': expected text, got "
                             f"{short_repr(value)}")
        out[name] = str(value).lower() if isinstance(value, bool) else str(value)
    return out


def _where(xacro: Any, default: Path) -> Path:
    """The file xacro was working on when it stopped (an include, or the top file)."""
    stack = [f for f in (getattr(xacro, "filestack", None) or []) if f]
    return Path(stack[-1]) if stack else default


def expand_xacro(
    path: str | Path,
    *,
    args: Mapping[str, str] | None = None,
    package_map: Mapping[str, str | Path] | None = None,
    packages: PackageFinder | None = None,
    limits: XacroLimits | None = None,
) -> XacroExpansion:
    """Expand a xacro file to URDF text (needs ``robokin[ros]``; no ROS install).

    Args:
        path: The ``.xacro`` / ``.urdf.xacro`` file.
        args: Values of its ``<xacro:arg>`` declarations (``name=value`` on
            ``xacro``'s command line); an argument the file does not declare
            is refused, listing those it does.
        package_map: ``{package: directory}`` for ``$(find ...)`` and
            ``package://`` (searched before ``ROS_PACKAGE_PATH``).
        packages: A finder to use instead of one built from ``package_map``.
        limits: CPU time, wall-clock time and memory of the expansion (default
            :data:`LIMITS`).

    Returns:
        An :class:`XacroExpansion`.

    Raises:
        ModelError: an unreadable file, malformed XML (file and line), a xacro
            error (the file it occurred in; the macro when xacro names one), a
            package that is not found (listing the places searched), or an
            expansion that went over a limit (naming the file and the limit).
        InputError: a bad ``args``, ``package_map`` or ``limits``, or an
            argument the file does not declare.
        MissingExtraError: xacro is not installed.
    """
    file = Path(path)
    read_file_bytes(file)  # a missing, binary or oversized file: a ModelError now
    vals = _check_args(args)
    lim = LIMITS if limits is None else limits
    if not isinstance(lim, XacroLimits):
        raise InputError("limits", f"expected an XacroLimits, got {short_repr(lim)}")
    finder = packages or PackageFinder(package_map, near=file)
    xacro = _xacro()  # imported before a child is forked: a missing extra is said here
    if _can_isolate():
        _warm_up(xacro)
        urdf, includes, noise = _expand_in_child(file, vals, finder, lim)
    else:  # pragma: no cover - no fork (Windows): unbounded, in this process
        with _LOCK:
            urdf, includes, noise = _expand(file, vals, finder)
    for message in _messages(noise):
        warnings.warn(f"xacro: {message}", UserWarning, stacklevel=2)
    _check_declared(vals, file, includes)
    return XacroExpansion(urdf, file, finder, includes, vals)


class _OutOfMemory(Exception):
    """The expansion hit its memory limit (a MemoryError anywhere in xacro)."""


def _expand(file: Path, vals: Mapping[str, str], finder: PackageFinder
            ) -> tuple[str, tuple[Path, ...], str]:
    """The expansion itself: ``(URDF text, included files, xacro's stderr)``.

    Raises:
        ModelError: as :func:`expand_xacro`.
        _OutOfMemory: a MemoryError inside xacro.
    """
    xacro = _xacro()
    from xml.parsers.expat import ExpatError

    noise = io.StringIO()
    with _finder_installed(xacro, finder), contextlib.redirect_stderr(noise):
        xacro.all_includes = []
        try:
            doc = xacro.process_file(str(file), mappings=dict(vals), verbosity=1)
            urdf = doc.toprettyxml(indent="  ")
        except ExpatError as exc:
            raise ModelError(f"not valid XML: {xacro_message(exc)}",
                             file=_where(xacro, file), line=exc.lineno) from None
        except Exception as exc:  # xacro raises XacroException, NameError, ...
            if _in_chain(exc, MemoryError) is not None:
                raise _OutOfMemory from None
            missing = _in_chain(exc, _PackageMissing)
            if missing is not None:
                raise ModelError(str(missing), file=_where(xacro, file)) from None
            raise _xacro_error(xacro, exc, file) from None
        includes = tuple(dict.fromkeys(Path(p) for p in xacro.all_includes))
    return urdf, includes, noise.getvalue()


# ------------------------------------------------------------- the child process
def _can_isolate() -> bool:
    """Whether expansions can run in a limited child (fork and resource exist)."""
    try:
        import resource  # noqa: F401
    except ImportError:  # pragma: no cover - Windows
        return False
    return hasattr(os, "fork")


def _vm_size() -> int | None:
    """This process's address space [bytes] (Linux), or None."""
    try:
        with open("/proc/self/status", encoding="ascii") as fh:
            for line in fh:
                if line.startswith("VmSize:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError):  # pragma: no cover - not Linux
        return None
    return None  # pragma: no cover


def _apply_limits(limits: XacroLimits) -> None:
    """In the child: CPU time, address space (from what it has now), no core file."""
    import resource

    def cap(kind: int, soft: int, hard: int) -> None:
        _, old_hard = resource.getrlimit(kind)
        if old_hard != resource.RLIM_INFINITY:
            soft, hard = min(soft, old_hard), min(hard, old_hard)
        with contextlib.suppress(ValueError, OSError):
            resource.setrlimit(kind, (soft, hard))

    cap(resource.RLIMIT_CORE, 0, 0)
    # the soft limit sends SIGXCPU (ending the child), the hard one SIGKILL a
    # second later (a handler of SIGXCPU cannot run inside one long C call)
    cap(resource.RLIMIT_CPU, limits.cpu_seconds, limits.cpu_seconds + 1)
    vm = _vm_size()
    if vm is not None:
        cap(resource.RLIMIT_AS, vm + limits.memory_mb * 2**20,
            vm + limits.memory_mb * 2**20)


def _child_message(file: Path, vals: dict[str, str], finder: PackageFinder,
                   limits: XacroLimits) -> bytes:
    """In the child: expand under the limits; the answer as JSON.

    Never a pickle: the child ran the file's expressions.
    """
    _apply_limits(limits)
    message: dict[str, Any]
    try:
        urdf, includes, noise = _expand(file, vals, finder)
        message = {"kind": "ok", "urdf": urdf, "includes": [str(f) for f in includes],
                   "noise": noise, "packages": finder.lookups()}
    except (_OutOfMemory, MemoryError):
        message = {"kind": "memory"}
    except ModelError as exc:
        message = {"kind": "model", "reason": exc.reason, "file": exc.file,
                   "field": exc.field, "line": exc.line}
    except BaseException as exc:  # noqa: BLE001 - reported to the parent, one line
        message = {"kind": "error", "text": f"{type(exc).__name__}: {xacro_message(exc)}"}
    try:
        return json.dumps(message).encode()
    except MemoryError:  # pragma: no cover - the URDF itself is too large to send
        return b'{"kind": "memory"}'


def _run_child(write_fd: int, file: Path, vals: dict[str, str], finder: PackageFinder,
               limits: XacroLimits) -> None:
    """The forked child: write the answer to ``write_fd`` and exit, whatever happens."""
    code = 1
    try:
        data = _child_message(file, vals, finder, limits)
        view = memoryview(data)
        while view:
            view = view[os.write(write_fd, view):]
        code = 0
    except BaseException:  # noqa: BLE001 - the parent reports a child without an answer
        pass
    finally:
        os._exit(code)  # no atexit handlers, no flushing of the parent's buffers


def _read_answer(fd: int, deadline: float) -> bytes | None:
    """Everything the child writes, or None when the deadline passes first."""
    import select

    chunks: list[bytes] = []
    while True:
        left = deadline - time.monotonic()
        if left <= 0:
            return None
        ready, _, _ = select.select([fd], [], [], left)
        if not ready:
            return None
        chunk = os.read(fd, 1 << 20)
        if not chunk:
            return b"".join(chunks)
        chunks.append(chunk)


def _expand_in_child(file: Path, vals: dict[str, str], finder: PackageFinder,
                     limits: XacroLimits) -> tuple[str, tuple[Path, ...], str]:
    """Run :func:`_expand` in a forked child under ``limits`` (see the module doc)."""
    read_fd, write_fd = os.pipe()
    with warnings.catch_warnings():
        # Python 3.12+ warns about fork() in a process with threads: the child
        # runs xacro only, under a deadline, and takes no lock of those threads
        warnings.filterwarnings("ignore", category=DeprecationWarning,
                                message=".*fork.*")
        pid = os.fork()
    if pid == 0:  # pragma: no cover - the child (measured by the parent's tests)
        os.close(read_fd)
        _run_child(write_fd, file, vals, finder, limits)
    os.close(write_fd)
    killed = False
    try:
        data = _read_answer(read_fd, time.monotonic() + limits.wall_seconds)
    finally:
        os.close(read_fd)
        if data is None:
            killed = True
            with contextlib.suppress(ProcessLookupError):
                os.kill(pid, signal.SIGKILL)
        _, status = os.waitpid(pid, 0)
    exitcode = os.waitstatus_to_exitcode(status)
    if not data:
        raise _limit_error(file, limits, exitcode, killed)
    message = json.loads(data)
    kind = message["kind"]
    if kind == "ok":
        finder.absorb(message["packages"])
        return (message["urdf"], tuple(Path(f) for f in message["includes"]),
                message["noise"])
    if kind == "model":
        raise ModelError(message["reason"], file=message["file"], field=message["field"],
                         line=message["line"])
    if kind == "memory":
        raise _limit_error(file, limits, None, False, memory=True)
    raise ModelError(f"xacro: {message['text']}", file=file)


def _limit_error(file: Path, limits: XacroLimits, exitcode: int | None, killed: bool,
                 *, memory: bool = False) -> ModelError:
    """The error for an expansion that went over a limit (or died)."""
    how = ("raise it with expand_xacro(..., limits=XacroLimits(...)) or "
           "robokin.io.xacro.LIMITS; a xacro is a program: expand only files you trust")
    if memory:
        what = f"needed more than {limits.memory_mb} MiB of memory, its limit"
    elif killed:
        what = (f"took more than {limits.wall_seconds:g} s (wall clock), its limit (it "
                "may compute without end, or wait on a FIFO or a device it includes)")
    elif exitcode in (-signal.SIGXCPU, -signal.SIGKILL):
        what = f"used more than {limits.cpu_seconds} s of CPU time, its limit"
    else:
        name: object = exitcode
        if exitcode is not None and exitcode < 0:
            with contextlib.suppress(ValueError):
                name = signal.Signals(-exitcode).name
        what = (f"ended without an answer (exit {name}; out of its "
                f"{limits.memory_mb} MiB of memory?)")
    return ModelError(f"xacro: expanding this file {what}; {how}", file=file)


_LOCATION = ("when instantiating", "instantiated from", "in file", "included from",
             "when processing file")


def _messages(text: str) -> list[str]:
    """The stderr of xacro as messages: a warning with its location lines, one each."""
    out: list[str] = []
    for line in text.splitlines():
        line = line.strip()
        if not line:
            continue
        if out and line.startswith(_LOCATION):
            out[-1] += f" ({line})"
        else:
            out.append(line.removeprefix("warning: "))
    return out


def _in_chain(exc: BaseException, kind: type[BaseException]) -> Any:
    """The first exception of type ``kind`` in ``exc``'s chain, wherever xacro put it."""
    seen: set[int] = set()
    todo: list[Any] = [exc]
    while todo:
        e = todo.pop()
        if e is None or id(e) in seen:
            continue
        seen.add(id(e))
        if isinstance(e, kind):
            return e
        todo += [getattr(e, "exc", None), e.__cause__, e.__context__]
    return None


def xacro_message(exc: BaseException) -> str:
    """One line (at most 300 characters) for an exception raised inside xacro."""
    text = " ".join(str(exc).split()) or type(exc).__name__
    return text if len(text) <= 300 else text[:297] + "..."


_EXPRESSION = re.compile(r"when evaluating expression '(.+)'$")
_ARGUMENT = re.compile(r"Undefined substitution argument (\S+)")


def _find_line(files: list[Path], message: str) -> tuple[Path, int] | None:
    """The file and line holding the expression or argument a message names."""
    m = _EXPRESSION.search(message)
    a = _ARGUMENT.search(message)
    if m:
        needles = [m.group(1).strip()]
        pattern = re.compile(r"\$\{\s*" + re.escape(needles[0]) + r"\s*\}")
    elif a:
        pattern = re.compile(r"\$\(\s*arg\s+" + re.escape(a.group(1)) + r"\s*\)")
    else:
        return None
    for f in files:
        try:
            text = read_file_bytes(f).decode("utf-8", "replace")
        except (OSError, ModelError):
            continue
        hit = pattern.search(text)
        if hit:
            return f, text.count("\n", 0, hit.start()) + 1
    return None


def _xacro_error(xacro: Any, exc: BaseException, file: Path) -> ModelError:
    """A ModelError naming the file (and line, when it can be found) and macro."""
    where = _where(xacro, file)
    stack = [m for m in (getattr(xacro, "macrostack", None) or []) if hasattr(m, "body")]
    names = [m.body.getAttribute("name") for m in stack]
    inside = f" (in macro {' <- '.join(reversed(names))})" if names else ""
    kind = "" if type(exc).__name__ == "XacroException" else f"{type(exc).__name__}: "
    message = xacro_message(exc)
    cause = getattr(exc, "exc", None)
    if isinstance(cause, OSError):  # an include that cannot be read
        message = f"cannot include {cause.filename}: {cause.strerror}"
    defined = [Path(m.history[-1][-1]) for m in reversed(stack)
               if getattr(m, "history", None) and m.history[-1] and m.history[-1][-1]]
    located = _find_line([*defined, where], message)
    if located is not None:
        return ModelError(f"xacro: {kind}{message}{inside}", file=located[0],
                          line=located[1])
    return ModelError(f"xacro: {kind}{message}{inside}", file=where)


def _check_declared(vals: Mapping[str, str], file: Path,
                    includes: tuple[Path, ...]) -> None:
    """Refuse an argument that no expanded file declares with ``<xacro:arg>``."""
    if not vals:
        return
    pattern = re.compile(r"<\s*xacro:arg\b[^>]*\bname\s*=\s*[\"']([^\"']+)[\"']")
    declared: set[str] = set()
    for f in (file, *includes):
        with contextlib.suppress(OSError, ModelError):
            declared.update(pattern.findall(read_file_bytes(f).decode("utf-8",
                                                                       "replace")))
    unknown = sorted(set(vals) - declared)
    if unknown:
        raise InputError("xacro_args", f"{file} declares no argument "
                         f"{', '.join(repr(u) for u in unknown)}; it declares "
                         f"{sorted(declared) or 'none'}")
