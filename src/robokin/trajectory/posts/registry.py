"""The post processor registry: the built-in dialects, registered ones, entry points.

Lookup order for a name: :func:`register`-ed classes, the built-ins, then the
``robokin.post_processors`` entry point group of the installed distributions (a
package declares ``[project.entry-points."robokin.post_processors"] my_dialect =
"my_pkg.posts:MyPost"``; the class is imported only when its name is asked for).
Nothing registers itself by being imported.
"""

from __future__ import annotations

import re
from importlib.metadata import entry_points
from typing import Any

from robokin._text import short_repr
from robokin.exceptions import InputError
from robokin.trajectory.posts._abb_rapid import AbbRapid
from robokin.trajectory.posts._fanuc_tp import FanucTp
from robokin.trajectory.posts._kawasaki_as import KawasakiAs
from robokin.trajectory.posts._kuka_krl import KukaKrl
from robokin.trajectory.posts._staubli_val3 import StaubliVal3
from robokin.trajectory.posts._yaskawa_inform import YaskawaInform
from robokin.trajectory.posts.base import PostProcessor, options_error

__all__ = ["BUILTIN", "ENTRY_POINT_GROUP", "get_post", "post_names", "register",
           "unregister"]

#: The entry point group third-party dialects are declared in.
ENTRY_POINT_GROUP = "robokin.post_processors"
#: The built-in dialects by name.
BUILTIN: dict[str, type[PostProcessor]] = {
    cls.name: cls for cls in (KukaKrl, AbbRapid, FanucTp, YaskawaInform, StaubliVal3,
                              KawasakiAs)}
_REGISTERED: dict[str, type[PostProcessor]] = {}
_NAME = re.compile(r"^[a-z][a-z0-9_]*$")


def _check_class(cls: Any) -> type[PostProcessor]:
    if not (isinstance(cls, type) and issubclass(cls, PostProcessor)):
        raise InputError("cls", "expected a PostProcessor subclass (a frozen dataclass "
                         f"deriving robokin.trajectory.posts.PostProcessor), got "
                         f"{short_repr(cls)}")
    if not isinstance(cls.name, str) or not _NAME.match(cls.name):
        raise InputError("cls", f"{cls.__name__}.name must be a lower-case identifier "
                         f"such as 'my_dialect', got {short_repr(cls.name)}")
    if getattr(cls, "__abstractmethods__", None):
        raise InputError("cls", f"{cls.__name__} does not implement "
                         f"{sorted(cls.__abstractmethods__)}")
    return cls


def register(cls: type[PostProcessor], *, replace: bool = False) -> type[PostProcessor]:
    """Make a post processor available by its ``name`` (returns the class).

    Args:
        cls: A :class:`~robokin.trajectory.posts.PostProcessor` subclass.
        replace: Allow replacing a built-in or registered dialect of that name.

    Raises:
        InputError: not a complete PostProcessor subclass, a bad name, or a name
            taken (without ``replace``).
    """
    cls = _check_class(cls)
    if not replace and (cls.name in BUILTIN or cls.name in _REGISTERED):
        raise InputError("cls", f"a post processor named {cls.name!r} exists; pass "
                         "replace=True to replace it")
    _REGISTERED[cls.name] = cls
    return cls


def unregister(name: str) -> None:
    """Forget a :func:`register`-ed dialect (the built-ins stay)."""
    _REGISTERED.pop(name, None)


def _entry_points() -> dict[str, Any]:
    return {ep.name: ep for ep in entry_points(group=ENTRY_POINT_GROUP)}


def post_names() -> list[str]:
    """Every available dialect name, sorted (built-in, registered, entry points)."""
    return sorted(set(BUILTIN) | set(_REGISTERED) | set(_entry_points()))


def _lookup(name: str) -> type[PostProcessor]:
    if name in _REGISTERED:
        return _REGISTERED[name]
    if name in BUILTIN:
        return BUILTIN[name]
    ep = _entry_points().get(name)
    if ep is None:
        raise InputError("dialect", f"unknown post processor {short_repr(name)}; "
                         f"available: {post_names()}")
    try:
        loaded = ep.load()
    except Exception as exc:  # a broken plug-in: say which and why
        raise InputError("dialect", f"the post processor {name!r} ({ep.value}, entry "
                         f"point group {ENTRY_POINT_GROUP}) failed to load: "
                         f"{type(exc).__name__}: {exc}") from None
    cls = _check_class(loaded)
    if cls.name != name:
        raise InputError("dialect", f"the entry point {name!r} loads a post processor "
                         f"named {cls.name!r}")
    return cls


def get_post(dialect: str | PostProcessor, **options: Any) -> PostProcessor:
    """The post processor ``dialect`` with ``options`` (or ``dialect`` itself).

    Args:
        dialect: A name (:func:`post_names`) or an instance.
        **options: The dialect's options (its dataclass fields, e.g.
            ``length_decimals=4``, FANUC's ``cnt=100``).

    Raises:
        InputError: an unknown name (listing the available ones), unknown options
            (listing the dialect's), or bad option values.
    """
    if isinstance(dialect, PostProcessor):
        if options:
            raise InputError("options", "options apply to a dialect given by name; "
                             "this one is already an instance")
        return dialect
    if not isinstance(dialect, str):
        raise InputError("dialect", f"expected a dialect name, got {short_repr(dialect)}")
    cls = _lookup(dialect.strip().lower().replace("-", "_"))
    err = options_error(cls, options)
    if err is not None:
        raise err
    try:
        return cls(**options)
    except TypeError as exc:  # pragma: no cover - names are checked above
        raise InputError("options", f"{cls.name}: {exc}") from None
