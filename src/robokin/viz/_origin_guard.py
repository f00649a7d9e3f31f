"""Refuse websocket connections to the viewer from other web pages.

Browsers do not apply the same-origin policy to websockets: any page the user has
open (any site) may connect to ``ws://127.0.0.1:8080`` and read the scene. The
browser always sends the page's ``Origin`` with the handshake, so the viewer
answers ``403 Forbidden`` unless that origin is the viewer's own page:
``http://HOST:PORT`` with the port the connection arrived on and HOST a loopback
name (``localhost``, ``127.0.0.1``, ``[::1]``), the address the connection
arrived on, or a host the caller allows. A handshake without ``Origin`` comes from
a program, not a page, and is let through (a local program can read the user's
files anyway). A DNS-rebinding page (``http://evil.example:8080`` resolving to
127.0.0.1) sends its own origin and is refused: the ``Host`` header is not
trusted.

How: viser has no hook for the handshake. It serves its HTTP files and its
websocket from one ``websockets.asyncio.server.serve(..., process_request=...)``
call in ``viser.infra._infra``. :func:`guarded_start` replaces that module's
reference to the ``websockets`` package (and no one else's) by a view in which
``serve`` puts the origin check in front of viser's own ``process_request``; the
check is armed only while a robokin viewer starts its server, so other viser
servers in the process are left as they are.
"""

from __future__ import annotations

import contextlib
import http
import ipaddress
import threading
from collections.abc import Callable, Iterable, Iterator
from typing import Any
from urllib.parse import urlsplit

from robokin.exceptions import RobokinError

__all__ = ["guarded_start", "origin_allowed"]

_LOCK = threading.Lock()
_STATE: dict[str, Any] = {"armed": None, "installed": False}
_LOOPBACK = ("localhost", "127.0.0.1", "::1")


def origin_allowed(origin: str | None, local_host: str, port: int,
                   extra_hosts: Iterable[str] = ()) -> bool:
    """Whether a websocket handshake with this ``Origin`` header may proceed.

    Args:
        origin: The header's value, or None when the client sent none.
        local_host: The address the connection arrived on.
        port: The port the connection arrived on.
        extra_hosts: More host names allowed (e.g. the machine's name for a
            viewer bound to a LAN interface).

    Returns:
        True for no origin, or ``http(s)://host:port`` with ``host`` a loopback
        name, ``local_host`` or one of ``extra_hosts`` and ``port`` the viewer's.
    """
    if origin is None:
        return True
    try:
        parts = urlsplit(origin.strip())
        host, oport = parts.hostname, parts.port
    except ValueError:
        return False
    if parts.scheme not in ("http", "https") or host is None:
        return False
    if oport is None:
        oport = 443 if parts.scheme == "https" else 80
    allowed = {*_LOOPBACK, _normal(local_host), *(_normal(h) for h in extra_hosts)}
    return oport == port and _normal(host) in allowed


def _normal(host: str) -> str:
    host = host.strip("[]").lower()
    try:
        return str(ipaddress.ip_address(host))
    except ValueError:
        return host


def _checking(inner: Callable | None, extra_hosts: tuple[str, ...]) -> Callable:
    """A ``process_request`` that refuses foreign origins, then asks ``inner``."""

    def process_request(connection: Any, request: Any) -> Any:
        if request.headers.get("Upgrade", "").lower() == "websocket":
            local = connection.local_address
            if not origin_allowed(request.headers.get("Origin"), local[0], local[1],
                                  extra_hosts):
                return connection.respond(http.HTTPStatus.FORBIDDEN,
                                          "robokin viewer: this origin may not "
                                          "connect\n")
        return None if inner is None else inner(connection, request)

    return process_request


class _View:
    """A module seen with some attributes replaced."""

    def __init__(self, real: Any, **replaced: Any) -> None:
        self._real = real
        self._replaced = replaced

    def __getattr__(self, name: str) -> Any:
        if name in self._replaced:
            return self._replaced[name]
        return getattr(self._real, name)


def _install() -> None:
    """Point viser's websocket server code at a guarded ``serve`` (once)."""
    if _STATE["installed"]:
        return
    try:
        from viser.infra import _infra
    except ImportError as exc:
        raise RobokinError(f"cannot guard the viewer: viser's server module is not "
                           f"where robokin expects it ({exc})") from None
    ws = getattr(_infra, "websockets", None)
    real_serve = getattr(getattr(getattr(ws, "asyncio", None), "server", None),
                         "serve", None)
    if ws is None or real_serve is None:
        import viser

        raise RobokinError(
            f"cannot guard the viewer: viser {getattr(viser, '__version__', '?')} "
            "does not start its server through websockets.asyncio.server.serve; "
            "robokin refuses to serve without the origin check")

    def serve(handler: Any, *args: Any, **kwargs: Any) -> Any:
        armed = _STATE["armed"]
        if armed is not None:
            kwargs["process_request"] = _checking(kwargs.get("process_request"),
                                                  armed)
        return real_serve(handler, *args, **kwargs)

    server = _View(ws.asyncio.server, serve=serve)
    # a view stands in for the module: viser reads only .asyncio.server.serve
    _infra.websockets = _View(  # type: ignore[assignment]
        ws, asyncio=_View(ws.asyncio, server=server))
    _STATE["installed"] = True


@contextlib.contextmanager
def guarded_start(extra_hosts: Iterable[str] = ()) -> Iterator[None]:
    """Arm the origin check for viser servers started inside this block.

    Args:
        extra_hosts: Host names allowed besides the loopback names and the
            address a connection arrives on.

    Raises:
        RobokinError: the installed viser cannot be guarded.
    """
    with _LOCK:
        _install()
        _STATE["armed"] = tuple(extra_hosts)
        try:
            yield
        finally:
            _STATE["armed"] = None
