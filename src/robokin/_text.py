"""Bounded text of user values, for error messages.

An error message never formats a whole user value: ``f"{value!r:.60}"`` builds the
full repr first and cuts it afterwards, which for a value with shared parts (a
YAML alias chain, a nested list) can take gigabytes. :func:`short_repr` cuts while
it builds (``reprlib``: a few elements per level, two levels, 60 characters of a
string), so its cost does not depend on the size of the value.
"""

from __future__ import annotations

import re
import reprlib

__all__ = ["control_character", "printable", "short_repr"]

# C0 and C1 control characters and DEL, but not tab or newline: an escape sequence
# from a file (``\x1b[2J``) must not reach the terminal as one.
_CONTROL = re.compile(r"[\x00-\x08\x0b-\x1f\x7f-\x9f]")

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


def printable(text: str) -> str:
    r"""``text`` with control characters shown as ``\xNN`` (tab and newline kept).

    For text from a file on its way to a terminal: an escape sequence in a robot
    name (``"\e[2J"`` in YAML) is printed as the characters ``\x1b[2J``, not
    obeyed.
    """
    return _CONTROL.sub(lambda m: f"\\x{ord(m.group()):02x}", text)


def control_character(text: str) -> str | None:
    r"""What is wrong with a name holding a control character, or None.

    Names (robot, joint, link, object) become XML attributes, file names and
    lines on a terminal: a control character (``\x1b``, a NUL, a newline) has
    no place in any of them.
    """
    m = _CONTROL.search(text) or re.search(r"[\t\n]", text)
    if m is None:
        return None
    return (f"a name must be printable text, got the control character "
            f"\\x{ord(m.group()):02x} at position {m.start()}")
