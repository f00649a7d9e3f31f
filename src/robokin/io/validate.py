"""Pydantic validation of file documents, its first error as one bounded ModelError.

The schemas of robot, actuator and motion files are pydantic models (imported
lazily). :func:`validate_document` runs one and turns its first error into a
:class:`~robokin.exceptions.ModelError` naming the file and the field path; the
offending value is shown through :func:`robokin._text.short_repr`, whose cost
does not depend on the value's size (pydantic's own message is never built).
"""

from __future__ import annotations

import typing
from collections.abc import Sequence
from typing import Any

from robokin._text import short_repr
from robokin.exceptions import ModelError
from robokin.io.yaml_reader import field_path

__all__ = [
    "accepted_keys",
    "list_of",
    "tagged_union",
    "union_of",
    "unknown_key",
    "validate_document",
]

_ANNOTATED: Any = typing.Annotated


def union_of(*types: Any) -> Any:
    """``Union[types]`` built at run time (for models assembled from parts)."""
    return typing.Union.__getitem__(types)


def tagged_union(*models: Any, tag: str = "type") -> Any:
    """A union of pydantic models told apart by their ``tag`` field (a Literal)."""
    from pydantic import Field

    return _ANNOTATED[union_of(*models), Field(discriminator=tag)]


def list_of(item: Any) -> Any:
    """``list[item]`` built at run time."""
    return list.__class_getitem__(item)


def unknown_key(accepted: Sequence[str]) -> str:
    """The reason for an unknown key: ``"unknown key; accepted: a, b, c"``."""
    return "unknown key; accepted: " + ", ".join(accepted)


def _models_in(annotation: Any) -> list[Any]:
    """The pydantic models an annotation can hold, unwrapping unions and Annotated."""
    from pydantic import BaseModel

    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return [annotation]
    if typing.get_origin(annotation) is typing.Annotated:
        return _models_in(typing.get_args(annotation)[0])
    out: list[Any] = []
    for arg in typing.get_args(annotation):
        out += _models_in(arg)
    return out


def accepted_keys(model: Any, loc: Sequence[Any]) -> list[str] | None:
    """The keys the model at ``loc`` (a pydantic error location) accepts.

    Walks the fields of ``model`` along ``loc``: a name enters a field, an index
    or a dictionary key enters the items of a list or mapping, a discriminated
    union's tag picks its member. None when ``loc`` leads to no model.
    """
    current = [model]
    for part in loc:
        if not isinstance(part, str):  # a list index: the same models
            continue
        holders = [m for m in current if part in m.model_fields]
        if holders:
            current = [x for m in holders
                       for x in _models_in(m.model_fields[part].annotation)]
            continue
        tagged = [m for m in current if part in (_tag_of(m), m.__name__)]
        if tagged:  # a union's tag or member name
            current = tagged
        # else a key of a mapping of models: the same models
    if len(current) != 1:
        return None
    return list(current[0].model_fields)


def _tag_of(model: Any) -> Any:
    """The value of a discriminator field ``type`` / ``kind`` (a Literal), if any."""
    for key in ("type", "kind"):
        field = model.model_fields.get(key)
        if field is not None and typing.get_origin(field.annotation) is typing.Literal:
            args = typing.get_args(field.annotation)
            if len(args) == 1:
                return args[0]
    return None


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
            keys = accepted_keys(model, err["loc"][:-1])
            msg = "unknown key" if keys is None else unknown_key(keys)
        else:
            msg = err["msg"]
            if "input" in err:
                msg = f"{msg} (got {short_repr(err['input'])})"
        raise ModelError(msg, file=file, field=field_path(loc) or None) from None
