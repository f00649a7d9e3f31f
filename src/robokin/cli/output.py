r"""Tables of the ``robokin`` command, printed so that no number is ever hidden.

A command builds :class:`OutputTable` objects (a title, columns, rows of plain
values) and hands them to :func:`emit`, which prints them in the format asked for
with ``--format``:

- ``table``: a rich table; a column too narrow for its values folds them onto
  more lines (never ``…``). The default when stdout is a terminal.
- ``text``: plain text, columns aligned with spaces, no box drawing, no width
  limit (a pipe or a file has no columns). The default otherwise.
- ``csv``: the rows as CSV (a header line of column names with units), numbers
  at full precision; several tables are separated by an empty line.
- ``json``: the command's own JSON (``--json`` is the same as ``--format json``).

Notes (one line each) follow the tables in ``table`` and ``text``; ``csv`` is
data only.

Text from files (robot, joint and link names, sources) is printed literally: rich
markup (``[red]``) is escaped, emoji codes (``:warning:``) are not replaced (every
console is made by :func:`console`, ``emoji=False``), and control characters
(an escape sequence ``\x1b[2J`` in a name) are shown as ``\xNN``
(:func:`robokin._text.printable`), in every format but ``csv`` and ``json``
(which carry the data as it is).
"""

from __future__ import annotations

import csv
import io
import sys
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from enum import Enum
from typing import Annotated, Any

import typer

from robokin._text import printable

__all__ = [
    "FORMAT_HELP",
    "Column",
    "console",
    "FormatOption",
    "OutputFormat",
    "OutputTable",
    "emit",
    "fixed",
    "general",
    "is_terminal",
    "resolve_format",
    "say",
    "tables_json",
]

FORMAT_HELP = ("table | text | csv | json (default: a table on a terminal, plain "
               "text otherwise).")


class OutputFormat(str, Enum):
    """The output formats of ``--format``."""

    table = "table"
    text = "text"
    csv = "csv"
    json = "json"


#: The ``--format`` option of a command that prints tables.
FormatOption = Annotated[
    OutputFormat | None, typer.Option("--format", help=FORMAT_HELP, show_default=False)
]


@dataclass(frozen=True)
class Column:
    """A table column.

    Attributes:
        name: The header (units in brackets, e.g. ``"q1 [deg]"``).
        fmt: Formats a value for ``table`` and ``text`` output (``csv`` writes
            numbers at full precision); ``str`` by default.
        right: Right-justify (numbers).
    """

    name: str
    fmt: Callable[[Any], str] = str
    right: bool = False


@dataclass
class OutputTable:
    """A titled table of plain values (numbers, text) and its notes.

    Attributes:
        title: One line above the table (``table`` and ``text``).
        columns: The columns.
        rows: One sequence of values per row, in column order.
        notes: Lines printed after the table (``table`` and ``text``).
        styles: A rich style per row (``table`` only), or None.
    """

    title: str
    columns: Sequence[Column]
    rows: list[Sequence[Any]] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    styles: list[str | None] | None = None

    def add_row(self, *values: Any, style: str | None = None) -> None:
        """Append a row (values in column order) with an optional rich style."""
        self.rows.append(values)
        if style is not None or self.styles is not None:
            if self.styles is None:
                self.styles = [None] * (len(self.rows) - 1)
            self.styles.append(style)

    def display(self) -> list[list[str]]:
        """The rows as the text ``table`` and ``text`` show."""
        return [[c.fmt(v) if v is not None else "" for c, v in zip(self.columns, row)]
                for row in self.rows]


def console(*, stderr: bool = False) -> Any:
    """The rich console every ``robokin`` command prints through.

    ``emoji=False``: ``:warning:`` in a robot name stays those characters (rich
    would replace emoji codes even in text printed with ``markup=False``).
    """
    from rich.console import Console

    return Console(emoji=False, stderr=stderr)


def is_terminal() -> bool:
    """Whether stdout is a terminal (rich's answer: honours FORCE_COLOR and TTY_*)."""
    return bool(console().is_terminal)


def resolve_format(fmt: OutputFormat | str | None, as_json: bool = False) -> str:
    """The format to print in: ``--format`` if given, ``json`` for ``--json``, else auto.

    Raises:
        InputError: ``--json`` together with a ``--format`` other than json.
    """
    from robokin.exceptions import InputError

    name = None if fmt is None else OutputFormat(fmt).value
    if as_json:
        if name not in (None, "json"):
            raise InputError("--format", f"--json contradicts --format {name}")
        return "json"
    if name is not None:
        return name
    return "table" if is_terminal() else "text"


def _full(value: Any) -> str:
    """A value for CSV: floats at full precision (shortest round-trip repr)."""
    if value is None:
        return ""
    if isinstance(value, float):
        return repr(value)
    if hasattr(value, "item"):  # a numpy scalar
        return _full(value.item())
    return str(value)


def _text(tables: Sequence[OutputTable], out: Any) -> None:
    for k, tab in enumerate(tables):
        if k:
            out.write("\n")
        if tab.title:
            out.write(printable(tab.title) + "\n")
        cells = [[printable(v) for v in row]
                 for row in ([c.name for c in tab.columns], *tab.display())]
        widths = [max(len(r[j]) for r in cells) for j in range(len(tab.columns))]
        for r in cells:
            parts = [s.rjust(w) if c.right else s.ljust(w)
                     for s, w, c in zip(r, widths, tab.columns)]
            out.write("  ".join(parts).rstrip() + "\n")
        for note in tab.notes:
            out.write(printable(note) + "\n")


def _csv(tables: Sequence[OutputTable], out: Any) -> None:
    for k, tab in enumerate(tables):
        if k:
            out.write("\n")
        buf = io.StringIO()
        writer = csv.writer(buf, lineterminator="\n")
        writer.writerow([c.name for c in tab.columns])
        for row in tab.rows:
            writer.writerow([_full(v) for v in row])
        out.write(buf.getvalue())


def _rich(tables: Sequence[OutputTable]) -> None:
    from rich import box
    from rich.markup import escape as rich_escape
    from rich.table import Table

    def escape(text: str) -> str:
        return rich_escape(printable(text))

    con = console()
    for tab in tables:
        table = Table(title=escape(tab.title) if tab.title else None,
                      box=box.SIMPLE_HEAD, title_justify="left", pad_edge=False)
        for c in tab.columns:
            table.add_column(escape(c.name), justify="right" if c.right else "left",
                             overflow="fold")
        styles = tab.styles or [None] * len(tab.rows)
        for row, style in zip(tab.display(), styles):
            table.add_row(*(escape(s) for s in row), style=style)
        con.print(table)
        for note in tab.notes:
            con.print(printable(note), markup=False, highlight=False)


def emit(tables: OutputTable | Sequence[OutputTable], fmt: str) -> None:
    """Print tables as ``fmt`` (``table``, ``text`` or ``csv``; see the module docstring).

    Args:
        tables: One table or several.
        fmt: The resolved format (:func:`resolve_format`); ``json`` is the
            command's own and is not printed here.

    Raises:
        ValueError: ``fmt`` is ``json`` or unknown (a bug in the caller).
    """
    if isinstance(tables, OutputTable):
        tables = [tables]
    if fmt == "table":
        _rich(tables)
    elif fmt == "text":
        _text(tables, sys.stdout)
    elif fmt == "csv":
        _csv(tables, sys.stdout)
    else:
        raise ValueError(f"emit() prints table, text or csv, not {fmt!r}")


def say(text: str, fmt: str) -> None:
    """Print one line of prose: never wrapped in a pipe, never markup; none in csv."""
    if fmt == "csv":
        return
    if fmt == "table":
        console().print(printable(text), markup=False, highlight=False)
    else:
        print(printable(text))


def tables_json(tables: Sequence[OutputTable]) -> list[dict[str, Any]]:
    """Tables as JSON-ready data: ``[{title, columns, rows, notes}, ...]``."""
    return [{"title": t.title, "columns": [c.name for c in t.columns],
             "rows": [[v.item() if hasattr(v, "item") else v for v in row]
                      for row in t.rows],
             "notes": list(t.notes)} for t in tables]


def fixed(digits: int) -> Callable[[Any], str]:
    """A column format with ``digits`` decimals (``f"{v:.{digits}f}"``)."""
    return lambda v: f"{v:.{digits}f}"


def general(digits: int = 6) -> Callable[[Any], str]:
    """A column format with ``digits`` significant digits (``f"{v:.{digits}g}"``)."""
    return lambda v: f"{v:.{digits}g}"
