"""The robokin exception hierarchy: every error robokin raises derives from RobokinError."""

from __future__ import annotations

import os
import sys

__all__ = [
    "FrozenError",
    "InputError",
    "MissingExtraError",
    "ModelError",
    "RobokinError",
    "UnreachableError",
]


class RobokinError(Exception):
    """Root of every error robokin raises."""


class ModelError(RobokinError, ValueError):
    """A bad robot or scene file, or an inconsistent model definition.

    Attributes:
        file: The file the problem was found in, or None for in-memory models.
        field: The field path inside the file, e.g. ``joints[2].limits``, or None.
        reason: What is wrong.
        line: The line in the file (1-based), or None when unknown. The message
            then starts ``FILE:LINE:``, the form editors jump to.
    """

    def __init__(
        self,
        reason: str,
        *,
        file: object = None,
        field: str | None = None,
        line: int | None = None,
    ):
        """Record the reason and where it applies (file, field, line)."""
        self.file = None if file is None else str(file)
        self.field = field
        self.reason = reason
        self.line = None if line is None else int(line)
        where = []
        if self.file is not None:
            where.append(self.file if self.line is None else f"{self.file}:{self.line}")
        elif self.line is not None:
            where.append(f"line {self.line}")
        if field:
            where.append(field)
        prefix = ": ".join(where)
        super().__init__(f"{prefix}: {reason}" if prefix else reason)

    def at_line(self, line: int | None) -> ModelError:
        """The same error with ``line`` set (a no-op when it is None or known)."""
        if line is None or self.line is not None:
            return self
        return ModelError(self.reason, file=self.file, field=self.field, line=line)


class InputError(RobokinError, ValueError):
    """A bad argument to a public function (wrong shape, NaN, out of range).

    Attributes:
        argument: The name of the offending argument.
        reason: What is wrong, stating expected vs got.
    """

    def __init__(self, argument: str, reason: str):
        """Record the argument and why it was refused."""
        self.argument = argument
        self.reason = reason
        super().__init__(f"argument '{argument}': {reason}")


class FrozenError(RobokinError, AttributeError):
    """An attempt to change an immutable object (a Robot).

    The message says what to call instead.

    Attributes:
        name: The attribute that was to be set or deleted.
    """

    def __init__(self, owner: str, name: str, hint: str):
        """Name the object and attribute, and say what to do instead."""
        self.name = name
        super().__init__(f"{owner} is immutable: cannot change '{name}'; {hint}")


class UnreachableError(RobokinError):
    """Raised only where the caller asked for exactly one IK answer and none exists."""


class MissingExtraError(RobokinError, ImportError):
    """An optional dependency is missing; the message names the extra to install."""

    def __init__(self, package: str, extra: str):
        """Record the package that is missing and the extra that installs it."""
        self.package = package
        self.extra = extra
        super().__init__(
            f"this feature needs the '{package}' package: "
            f"pip install 'robokin[{extra}]'"
        )


def user_stacklevel() -> int:
    """The ``stacklevel`` that makes ``warnings.warn`` name the first caller outside robokin.

    Called where the warning is raised: however many robokin functions lie
    between the user's call and the warning (``Robot.from_urdf`` ->
    ``parts_from_urdf`` -> ...), the warning points at the user's line.
    """
    package = os.path.dirname(os.path.abspath(__file__)) + os.sep
    frame = sys._getframe(1)  # the function that will call warnings.warn
    level = 1
    while frame.f_back is not None and frame.f_code.co_filename.startswith(package):
        frame = frame.f_back
        level += 1
    return level
