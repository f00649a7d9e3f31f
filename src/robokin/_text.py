"""Bounded text of user values, for error messages.

An error message never formats a whole user value: ``f"{value!r:.60}"`` builds the
full repr first and cuts it afterwards, which for a value with shared parts (a
YAML alias chain, a nested list) can take gigabytes. :func:`short_repr` cuts while
it builds (``reprlib``: a few elements per level, two levels, 60 characters of a
string), so its cost does not depend on the size of the value.
"""

from __future__ import annotations

import reprlib

__all__ = ["short_repr"]

_REPR = reprlib.Repr()
_REPR.maxlevel = 2
_REPR.maxstring = 60
_REPR.maxother = 60
_REPR.maxlong = 40
for _attr in ("maxlist", "maxtuple", "maxdict", "maxset", "maxfrozenset", "maxdeque",
              "maxarray"):
    setattr(_REPR, _attr, 4)


def short_repr(value: object, limit: int = 60) -> str:
    """A repr of ``value`` of at most ``limit`` characters, built in bounded time.

    Args:
        value: Any object (user input).
        limit: The largest length of the result (characters).

    Returns:
        The repr, cut with ``...`` when longer than ``limit``.
    """
    try:
        text = _REPR.repr(value)
    except Exception:  # a broken __repr__, an int beyond str()'s digit limit
        text = f"<{type(value).__name__}>"
    if len(text) > limit:
        text = text[: max(limit - 3, 0)] + "..."
    return text
