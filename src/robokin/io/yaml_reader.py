"""The one YAML reader: safe loading, line numbers, no duplicate keys, bounded work.

Robot, scene, motion and controller-profile files all come through
:func:`read_yaml_document` (or :func:`read_yaml` for the data alone). It

* loads with PyYAML's safe loader only (libyaml's when installed): no Python
  objects, no tags beyond YAML's own;
* refuses a key given twice in one mapping, naming ``FILE:LINE`` of the second;
* reads ``1e3`` as a number, as YAML 1.2 does (YAML 1.1 reads it as a string);
* bounds the work before building anything: a first pass over the parser's
  events counts the nodes of the document *as expanded* (an alias counts the
  whole subtree it names) and refuses a document whose expanded size is far
  beyond its text (a "billion laughs" alias chain of a few hundred bytes), one
  nested deeper than ``max_depth``, or an alias inside its own anchor;
* keeps the line of every mapping key and sequence item, so later validation
  errors (a field path such as ``joints[2].a``) can name the line
  (:meth:`YamlDocument.line_of`).

Errors are :class:`~robokin.exceptions.ModelError` naming the file and the line.
"""

from __future__ import annotations

import re
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Protocol

import yaml

from robokin.exceptions import ModelError
from robokin.io.text_files import MAX_TEXT_BYTES, read_text_file

__all__ = [
    "MAX_DEPTH",
    "MAX_NODES",
    "NODES_BASE",
    "NODES_PER_BYTE",
    "YamlDocument",
    "field_path",
    "parse_yaml",
    "read_yaml",
    "read_yaml_document",
]

#: Deepest nesting of mappings and sequences accepted.
MAX_DEPTH = 64
#: Expanded node budget: ``min(NODES_BASE + NODES_PER_BYTE * len(text),
#: MAX_NODES)`` (a plain document has at most about one node per two bytes; PyYAML
#: builds about 150 000 nodes a second, so the absolute cap keeps any file to
#: well under a second).
NODES_BASE = 10_000
NODES_PER_BYTE = 4
MAX_NODES = 100_000

_Base: Any = getattr(yaml, "CSafeLoader", yaml.SafeLoader)
_FLOAT_12 = re.compile(r"^[-+]?(?:[0-9][0-9_]*)(?:\.[0-9_]*)?[eE][-+]?[0-9]+$")
_MAP = "tag:yaml.org,2002:map"
_SEQ = "tag:yaml.org,2002:seq"
_MERGE = "tag:yaml.org,2002:merge"


class _Loader(_Base):
    """The safe loader, keeping lines and refusing duplicate keys."""

    def __init__(self, stream: str) -> None:
        super().__init__(stream)
        # id(container) -> (container, {key or index: line}); the container is
        # held so its id stays unique while the table lives.
        self.lines: dict[int, tuple[Any, dict[Any, int]]] = {}

    def _checked_pairs(self, node: yaml.MappingNode) -> dict[Any, int]:
        """Construct the explicit keys; refuse a repeated one; their lines."""
        lines: dict[Any, int] = {}
        for key_node, _ in node.value:
            if key_node.tag == _MERGE:
                continue
            key = self.construct_object(key_node, deep=True)
            try:
                seen = key in lines
            except TypeError:
                raise yaml.constructor.ConstructorError(
                    "while constructing a mapping", node.start_mark,
                    "found an unhashable key", key_node.start_mark) from None
            if seen:
                raise yaml.constructor.ConstructorError(
                    None, None,
                    f"duplicate key {_short(key)} (first given at line {lines[key]})",
                    key_node.start_mark)
            lines[key] = key_node.start_mark.line + 1
        return lines

    def construct_checked_map(self, node: yaml.MappingNode) -> Iterator[dict]:
        data: dict[Any, Any] = {}
        yield data
        lines = self._checked_pairs(node)
        value = self.construct_mapping(node)  # flattens merges ('<<')
        for key_node, _ in node.value:  # merged keys: the line where they were given
            key = self.construct_object(key_node)
            lines.setdefault(key, key_node.start_mark.line + 1)
        data.update(value)
        self.lines[id(data)] = (data, lines)

    def construct_checked_seq(self, node: yaml.SequenceNode) -> Iterator[list]:
        data: list[Any] = []
        yield data
        data.extend(self.construct_sequence(node))
        self.lines[id(data)] = (
            data, {i: child.start_mark.line + 1 for i, child in enumerate(node.value)})


_Loader.add_constructor(_MAP, _Loader.construct_checked_map)
_Loader.add_constructor(_SEQ, _Loader.construct_checked_seq)
_Loader.add_implicit_resolver("tag:yaml.org,2002:float", _FLOAT_12,
                              list("-+0123456789"))


def _short(value: Any) -> str:
    from robokin._text import short_repr

    return short_repr(value)


@dataclass(frozen=True)
class YamlDocument:
    """A parsed YAML document and where each of its parts was written.

    Attributes:
        data: The document (dicts, lists, scalars).
        file: The file it came from, or None for a string.
    """

    data: Any
    file: Path | None = None
    _lines: dict[int, tuple[Any, dict[Any, int]]] = field(default_factory=dict,
                                                          repr=False)

    def line(self, loc: Sequence[Any]) -> int | None:
        """The line (1-based) of the part at ``loc`` (keys and indices).

        Or of the deepest part of it that exists; None for the whole document.
        """
        node, found = self.data, None
        for part in loc:
            entry = self._lines.get(id(node))
            if entry is None or entry[0] is not node:
                break
            line = entry[1].get(part)
            if line is None:
                break
            found = line
            try:
                node = node[part]
            except (KeyError, IndexError, TypeError):
                break
        return found

    def line_of(self, field_path: str | None) -> int | None:
        """The line of a field path such as ``joints[2].limits`` (see :func:`field_path`)."""
        if not field_path:
            return None
        return self.line(_parse_field_path(field_path))

    def locate(self, exc: ModelError) -> ModelError:
        """``exc`` with the line of its field filled in (when it is in this file)."""
        if exc.line is not None or (self.file is not None and exc.file is not None
                                    and exc.file != str(self.file)):
            return exc
        return exc.at_line(self.line_of(exc.field))


def field_path(loc: Sequence[Any]) -> str:
    """A location ``("joints", 2, "a")`` as the field path ``joints[2].a``."""
    out = ""
    for part in loc:
        if isinstance(part, int):
            out += f"[{part}]"
        else:
            out += ("." if out else "") + str(part)
    return out


_PART = re.compile(r"\[(\d+)\]|\.?([^.\[]+)")


def _parse_field_path(text: str) -> list[Any]:
    return [int(m.group(1)) if m.group(1) is not None else m.group(2)
            for m in _PART.finditer(text)]


class _Mark(Protocol):
    line: int  # 0-based, as PyYAML's pure and libyaml marks both give it


def _line(mark: _Mark | None) -> int | None:
    """The 1-based line of a parser position, when the parser gave one."""
    return None if mark is None else mark.line + 1


def _budget(text: str, file: Any, max_depth: int, max_nodes: int | None) -> None:
    """Refuse a document too deep, recursive, or whose expansion is too large.

    One pass over the parser's events (libyaml's parser does not recurse); an
    alias adds the expanded size of the subtree its anchor names, so the count
    is the size of the document as a tree, computed without building it.
    """
    limit = (min(NODES_BASE + NODES_PER_BYTE * len(text), MAX_NODES)
             if max_nodes is None else max_nodes)
    loader = _Base(text)
    aliases = False
    sizes: dict[str, int] = {}
    open_anchors: list[tuple[str | None, int]] = []  # per open collection
    total = 0
    try:
        while loader.check_event():
            ev = loader.get_event()
            if isinstance(ev, yaml.AliasEvent):
                aliases = True
                if ev.anchor in sizes:
                    total += sizes[ev.anchor]
                elif any(a == ev.anchor for a, _ in open_anchors):
                    raise ModelError("an alias refers to the collection it is in "
                                     f"(&{ev.anchor}): a recursive document",
                                     file=file, line=_line(ev.start_mark))
                else:
                    continue  # undefined: the loader reports it
            elif isinstance(ev, yaml.ScalarEvent):
                total += 1
                if ev.anchor is not None:
                    sizes[ev.anchor] = 1
            elif isinstance(ev, yaml.CollectionStartEvent):
                total += 1
                open_anchors.append((ev.anchor, total))
                if len(open_anchors) > max_depth:
                    raise ModelError(f"nested deeper than {max_depth} levels",
                                     file=file, line=_line(ev.start_mark))
            elif isinstance(ev, yaml.CollectionEndEvent):
                anchor, start = open_anchors.pop()
                if anchor is not None:
                    sizes[anchor] = total - start + 1
            else:
                continue
            if total > limit:
                what = (f"expands to more than {limit:,} values from {len(text):,} "
                        "characters (aliases repeating aliases)" if aliases
                        else f"holds more than {limit:,} values")
                raise ModelError(f"{what}; refused (pass max_nodes= to raise the cap)",
                                 file=file, line=_line(ev.start_mark))
    except yaml.YAMLError as exc:
        raise _yaml_error(exc, file) from None
    finally:
        loader.dispose()


def _yaml_error(exc: yaml.YAMLError, file: Any) -> ModelError:
    mark = getattr(exc, "problem_mark", None)
    problem = getattr(exc, "problem", None) or str(exc)
    line = None if mark is None else mark.line + 1
    if problem.startswith("duplicate key"):
        return ModelError(problem[:300], file=file, line=line)
    col = "" if mark is None else f", column {mark.column + 1}"
    return ModelError(f"not valid YAML{col}: {problem}"[:300], file=file, line=line)


def parse_yaml(
    text: str, *, file: str | Path | None = None, max_depth: int = MAX_DEPTH,
    max_nodes: int | None = None,
) -> YamlDocument:
    """Parse one YAML document (see the module docstring for the checks).

    Args:
        text: The YAML text.
        file: The file it came from, for messages.
        max_depth: Deepest nesting accepted.
        max_nodes: Expanded node budget (default ``min(NODES_BASE +
            NODES_PER_BYTE * len(text), MAX_NODES)``).

    Returns:
        The :class:`YamlDocument`.

    Raises:
        ModelError: not valid YAML, a duplicate key, a document too deep, too
            large once expanded, or recursive (naming the file and the line).
    """
    file = None if file is None else Path(file)
    _budget(text, file, max_depth, max_nodes)
    loader = _Loader(text)
    try:
        data = loader.get_single_data()
    except yaml.YAMLError as exc:
        raise _yaml_error(exc, file) from None
    except ValueError as exc:  # e.g. an integer beyond Python's digit limit
        raise ModelError(f"not valid YAML: {exc}"[:300], file=file) from None
    finally:
        loader.dispose()
    return YamlDocument(data, file, loader.lines)


def read_yaml_document(
    path: str | Path, *, max_bytes: int = MAX_TEXT_BYTES, max_depth: int = MAX_DEPTH,
    max_nodes: int | None = None,
) -> YamlDocument:
    """Read and parse a YAML file (see :func:`parse_yaml`).

    Args:
        path: The file.
        max_bytes: The largest file accepted [bytes].
        max_depth: Deepest nesting accepted.
        max_nodes: Expanded node budget (default: from the text's size).

    Raises:
        ModelError: missing, a folder, binary or too large (see
            :func:`robokin.io.text_files.read_text_file`), or as :func:`parse_yaml`.
    """
    path = Path(path)
    text = read_text_file(path, max_bytes=max_bytes)
    return parse_yaml(text, file=path, max_depth=max_depth, max_nodes=max_nodes)


def read_yaml(path: str | Path, **caps: Any) -> Any:
    """The data of a YAML file (see :func:`read_yaml_document`)."""
    return read_yaml_document(path, **caps).data
