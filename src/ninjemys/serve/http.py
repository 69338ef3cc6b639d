"""A small asyncio HTTP/1.1 server for the web tools: routes, static files, JSON, and WebSocket upgrades.

Stdlib only here; the WebSocket connections (:mod:`ninjemys.serve.websocket`, on ``websockets``'
sans-I/O protocol) carry every live update the pages need, through the gateway mounted on the
server: there are no server-push HTTP responses (Server-Sent Events went with the in-process
pollers that used them). The server runs on whatever event loop calls :meth:`HttpServer.start`, so
it can share a loop, or run on its own thread via the web app or the standalone gateway.
"""

from __future__ import annotations

import asyncio
import contextlib
import json
import logging
import mimetypes
from collections.abc import Awaitable, Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING
from urllib.parse import parse_qs, unquote, urlsplit

from ninjemys.errors import NinjemysError

log = logging.getLogger(__name__)

MAX_HEADER_BYTES = 64 * 1024
MAX_BODY_BYTES = 1024 * 1024

_REASONS = {
    200: "OK",
    204: "No Content",
    400: "Bad Request",
    404: "Not Found",
    405: "Method Not Allowed",
    413: "Payload Too Large",
    500: "Internal Server Error",
}


@dataclass
class Request:
    """One parsed HTTP request."""

    method: str
    path: str
    query: dict[str, list[str]]
    headers: dict[str, str]
    body: bytes = b""
    #: the request target as sent (path and query, still %-encoded)
    target: str = ""
    #: every header line in order, names as sent (a WebSocket handshake needs repeated headers)
    raw_headers: list[tuple[str, str]] = field(default_factory=list)

    def arg(self, name: str, default: str | None = None) -> str | None:
        values = self.query.get(name)
        return values[0] if values else default

    def json(self) -> object:
        """The body decoded as JSON; malformed bodies raise ValueError (answered with 400)."""
        return json.loads(self.body.decode("utf-8")) if self.body else None


@dataclass
class Response:
    """A complete response; ``body`` may be bytes, str or any JSON-able value."""

    body: bytes | str | object = b""
    status: int = 200
    content_type: str | None = None
    headers: dict[str, str] = field(default_factory=dict)

    def encode(self) -> tuple[bytes, str]:
        if isinstance(self.body, bytes):
            return self.body, self.content_type or "application/octet-stream"
        if isinstance(self.body, str):
            return self.body.encode("utf-8"), self.content_type or "text/plain; charset=utf-8"
        return json.dumps(self.body).encode("utf-8"), self.content_type or "application/json"


Handler = Callable[[Request], Awaitable[Response] | Response]

if TYPE_CHECKING:
    import ssl

    from ninjemys.serve.websocket import WebSocketEndpoint


class HttpError(NinjemysError):
    """Raised by a handler to answer with an error status and a one-line reason."""

    def __init__(self, status: int, reason: str) -> None:
        super().__init__(reason)
        self.status = status
        self.reason = reason


class HttpServer:
    """Routes exact paths (and one static directory) to handlers."""

    def __init__(
        self, host: str = "127.0.0.1", port: int = 0, ssl_context: ssl.SSLContext | None = None
    ) -> None:
        self.host = host
        self.port = port
        self.ssl_context = ssl_context
        self._routes: dict[tuple[str, str], Handler] = {}
        self._websockets: dict[str, WebSocketEndpoint] = {}
        self._static: list[tuple[str, Path]] = []
        self._server: asyncio.base_events.Server | None = None
        self._writers: set[asyncio.StreamWriter] = set()
        self._tasks: set[asyncio.Task[None]] = set()  # the connections' handlers (closed in order)

    def route(self, method: str, path: str, handler: Handler) -> None:
        self._routes[(method.upper(), path)] = handler

    def websocket(self, path: str, endpoint: WebSocketEndpoint) -> None:
        """Accept WebSocket upgrades on ``path`` (see :mod:`ninjemys.serve.websocket`); a plain GET of
        the same path still goes to the HTTP route, if there is one."""
        self._websockets[path] = endpoint

    def static(self, prefix: str, directory: Path) -> None:
        """Serve files under ``directory`` at ``prefix`` (no directory listings, no escaping the root)."""
        self._static.append((prefix.rstrip("/") + "/", directory.resolve()))

    @property
    def url(self) -> str:
        host = "localhost" if self.host in ("127.0.0.1", "0.0.0.0", "") else self.host
        scheme = "https" if self.ssl_context is not None else "http"
        return f"{scheme}://{host}:{self.port}/"

    async def start(self) -> None:
        self._server = await asyncio.start_server(self._serve, self.host, self.port, ssl=self.ssl_context)
        self.port = self._server.sockets[0].getsockname()[1]

    async def close(self) -> None:
        if self._server is None:
            return
        self._server.close()
        # every connection's handler is cancelled and awaited: a WebSocket sends its close frame and
        # its endpoint stops its own tasks, so the loop can close with nothing left pending
        # (otherwise "Task was destroyed but it is pending" at exit while a page is still open)
        tasks = [t for t in self._tasks if not t.done() and t is not asyncio.current_task()]
        for task in tasks:
            task.cancel()
        if tasks:
            await asyncio.wait(tasks, timeout=2.0)
        for writer in list(self._writers):
            writer.close()
        with contextlib.suppress(Exception):
            await asyncio.wait_for(self._server.wait_closed(), 2.0)
        self._server = None

    # -- connection handling ----------------------------------------------------------------
    async def _serve(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        task = asyncio.current_task()
        if task is not None:
            self._tasks.add(task)
            task.add_done_callback(self._tasks.discard)
        self._writers.add(writer)
        try:
            while True:
                request = await self._read_request(reader, writer)
                if request is None:
                    return
                keep_alive = request.headers.get("connection", "").lower() != "close"
                endpoint = self._websockets.get(request.path)
                if endpoint is not None and request.headers.get("upgrade", "").lower() == "websocket":
                    from ninjemys.serve.websocket import serve_upgrade  # only WebSocket users load it

                    await serve_upgrade(endpoint, request, reader, writer)
                    return
                if not await self._dispatch(request, writer) or not keep_alive:
                    return
        except (ConnectionError, asyncio.IncompleteReadError, asyncio.CancelledError, OSError):
            return
        finally:
            self._writers.discard(writer)
            writer.close()

    async def _read_request(
        self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter
    ) -> Request | None:
        try:
            head = await reader.readuntil(b"\r\n\r\n")
        except asyncio.LimitOverrunError:
            await self._send(writer, Response("request header too large", 413))
            return None
        except asyncio.IncompleteReadError:
            return None
        if len(head) > MAX_HEADER_BYTES:
            await self._send(writer, Response("request header too large", 413))
            return None
        lines = head.decode("latin-1").split("\r\n")
        parts = lines[0].split(" ")
        if len(parts) != 3:
            await self._send(writer, Response("malformed request line", 400))
            return None
        method, target, _version = parts
        headers = {}
        raw_headers = []
        for line in lines[1:]:
            if ":" in line:
                key, value = line.split(":", 1)
                headers[key.strip().lower()] = value.strip()
                raw_headers.append((key.strip(), value.strip()))
        try:
            length = int(headers.get("content-length", "0"))
        except ValueError:
            length = -1
        if length < 0 or length > MAX_BODY_BYTES:
            await self._send(writer, Response("bad or too large Content-Length", 413))
            return None
        body = await reader.readexactly(length) if length else b""
        split = urlsplit(target)
        return Request(
            method.upper(), unquote(split.path), parse_qs(split.query), headers, body, target, raw_headers
        )

    async def _dispatch(self, request: Request, writer: asyncio.StreamWriter) -> bool:
        """Answer one request; False when the connection must close afterwards."""
        method = "GET" if request.method == "HEAD" else request.method
        handler = self._routes.get((method, request.path))
        try:
            if handler is None:
                result: Response = self._static_file(request)
            else:
                outcome = handler(request)
                result = await outcome if isinstance(outcome, Awaitable) else outcome
        except HttpError as exc:
            result = Response({"error": exc.reason}, exc.status)
        except ValueError as exc:
            result = Response({"error": str(exc)}, 400)
        except Exception as exc:  # a handler bug must not take the server down
            log.exception("web handler for %s %s failed", request.method, request.path)
            result = Response({"error": f"{type(exc).__name__}: {exc}"}, 500)
        await self._send(writer, result, head_only=request.method == "HEAD")
        return True

    def _static_file(self, request: Request) -> Response:
        if request.method not in ("GET", "HEAD"):
            raise HttpError(405, f"{request.method} not allowed on {request.path}")
        for prefix, root in self._static:
            if request.path.startswith(prefix):
                candidate = (root / request.path[len(prefix) :]).resolve()
                if candidate.is_file() and candidate.is_relative_to(root):
                    ctype = mimetypes.guess_type(candidate.name)[0] or "application/octet-stream"
                    if ctype.startswith("text/") or ctype.endswith("javascript"):
                        ctype += "; charset=utf-8"
                    return Response(candidate.read_bytes(), 200, ctype, {"Cache-Control": "no-cache"})
        raise HttpError(404, f"no such page: {request.path}")

    async def _send(self, writer: asyncio.StreamWriter, response: Response, head_only: bool = False) -> None:
        body, ctype = response.encode()
        lines = [
            f"HTTP/1.1 {response.status} {_REASONS.get(response.status, 'Status')}",
            f"Content-Type: {ctype}",
            f"Content-Length: {len(body)}",
        ]
        lines += [f"{k}: {v}" for k, v in response.headers.items()]
        writer.write(("\r\n".join(lines) + "\r\n\r\n").encode("latin-1"))
        if not head_only:
            writer.write(body)
        await writer.drain()
