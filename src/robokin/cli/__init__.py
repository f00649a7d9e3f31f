"""The ``robokin`` command and ``robokin demo``.

:func:`main` is the entry point (``[project.scripts] robokin``, ``python -m
robokin``); :data:`app` the typer application. The commands live in one module per
topic (:mod:`robokin.cli.robots`, :mod:`robokin.cli.ik`, ...), each on its own
``commands = typer.Typer()``; :data:`robokin.cli.entry.COMMAND_MODULES` lists them.
Shared helpers: :mod:`robokin.cli.common` (errors, safe text, robots) and
:mod:`robokin.cli.output` (tables as text, CSV or JSON). Nothing below this
package imports it.
"""

from robokin.cli.entry import app, main

__all__ = ["app", "main"]
