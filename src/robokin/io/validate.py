"""Pydantic validation of file documents, its first error as one bounded ModelError.

The schemas of robot, actuator and motion files are pydantic models (imported
lazily). :func:`validate_document` runs one and turns its first error into a
:class:`~robokin.exceptions.ModelError` naming the file and the field path; the
offending value is shown through :func:`robokin._text.short_repr`, whose cost
does not depend on the value's size (pydantic's own message is never built).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from robokin._text import short_repr
from robokin.exceptions import ModelError
from robokin.io.yaml_reader import field_path

__all__ = ["validate_document"]


def validate_document(
    model: Any, data: Any, *, file: Any = None, prefix: Sequence[Any] = (),
    drop: Sequence[str] = (),
) -> Any:
    """``model.model_validate(data)``, its first error as a ModelError.

    Args:
        model: A pydantic model class.
        data: The document (or part of one).
        file: The file, for the message.
        prefix: The location of ``data`` in the file (``("joints", 2)``).
        drop: Location parts pydantic adds that are not fields (the tags of a
            discriminated union).

    Returns:
        The validated model instance.

    Raises:
        ModelError: naming ``file``, the field path and the reason.
    """
    from pydantic import ValidationError

    try:
        return model.model_validate(data)
    except ValidationError as exc:
        err = exc.errors(include_url=False, include_context=False)[0]
        loc = tuple(prefix) + tuple(p for p in err["loc"] if p not in drop)
        kind = err["type"]
        if kind == "missing":
            msg = "missing required field"
        elif kind == "extra_forbidden":
            msg = "unknown field"
        else:
            msg = err["msg"]
            if "input" in err:
                msg = f"{msg} (got {short_repr(err['input'])})"
        raise ModelError(msg, file=file, field=field_path(loc) or None) from None
