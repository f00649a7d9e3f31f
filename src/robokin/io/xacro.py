"""xacro in: expand a ``.xacro`` / ``.urdf.xacro`` file to URDF without ROS.

:func:`expand_xacro` runs ros/xacro (the ROS reference expander, from PyPI: the
``robokin[ros]`` extra) on a file, with ``<xacro:arg>`` values given as
``args``; ``$(find NAME)`` and ``${find('NAME')}`` resolve through a
:class:`~robokin.io.ros_packages.PackageFinder` (the package map,
``ROS_PACKAGE_PATH``, ``AMENT_PREFIX_PATH``, the folders above the file). The
expanded URDF is read by :func:`robokin.io.urdf.robot_from_urdf`, which resolves
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
XML, and for a missing package the places searched. xacro keeps its state in
module globals, so expansions are serialised by a lock. A xacro file is a
program: its ``${...}`` expressions are Python evaluated by xacro (without
builtins) and it may include any file it names; expand only files you trust.
"""

from __future__ import annotations

import contextlib
import io
import re
import threading
import warnings
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from robokin._text import short_repr
from robokin.exceptions import InputError, MissingExtraError, ModelError
from robokin.io.ros_packages import PackageFinder
from robokin.io.text_files import read_file_bytes

__all__ = ["XacroExpansion", "expand_xacro", "is_xacro"]

_LOCK = threading.Lock()


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
    except ImportError:
        raise MissingExtraError("xacro", "ros") from None
    return xacro


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

    Returns:
        An :class:`XacroExpansion`.

    Raises:
        ModelError: an unreadable file, malformed XML (file and line), a xacro
            error (the file it occurred in; the macro when xacro names one), a
            package that is not found (listing the places searched).
        InputError: a bad ``args`` or ``package_map`` entry, or an argument the
            file does not declare.
        MissingExtraError: xacro is not installed.
    """
    file = Path(path)
    read_file_bytes(file)  # a missing, binary or oversized file: a ModelError now
    vals = _check_args(args)
    finder = packages or PackageFinder(package_map, near=file)
    xacro = _xacro()
    from xml.parsers.expat import ExpatError

    noise = io.StringIO()
    with _LOCK, _finder_installed(xacro, finder), contextlib.redirect_stderr(noise):
        xacro.all_includes = []
        try:
            doc = xacro.process_file(str(file), mappings=dict(vals), verbosity=1)
        except ExpatError as exc:
            raise ModelError(f"not valid XML: {xacro_message(exc)}",
                             file=_where(xacro, file), line=exc.lineno) from None
        except Exception as exc:  # xacro raises XacroException, NameError, ...
            missing = _package_missing(exc)
            if missing is not None:
                raise ModelError(str(missing), file=_where(xacro, file)) from None
            raise _xacro_error(xacro, exc, file) from None
        includes = tuple(dict.fromkeys(Path(p) for p in xacro.all_includes))
    for message in _messages(noise.getvalue()):
        warnings.warn(f"xacro: {message}", UserWarning, stacklevel=2)
    _check_declared(vals, file, includes)
    return XacroExpansion(doc.toprettyxml(indent="  "), file, finder, includes, vals)


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


def _package_missing(exc: BaseException) -> _PackageMissing | None:
    """The finder's error, wherever xacro wrapped it."""
    seen: set[int] = set()
    todo: list[Any] = [exc]
    while todo:
        e = todo.pop()
        if e is None or id(e) in seen:
            continue
        seen.add(id(e))
        if isinstance(e, _PackageMissing):
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
