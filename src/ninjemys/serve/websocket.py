"""WebSocket connections on the web tools' asyncio HTTP server, over the ``websockets`` sans-I/O core.

The HTTP server (:mod:`ninjemys.serve.http`) parses the upgrade request like any other request and
hands it to a :class:`WebSocketEndpoint`; the endpoint decides (subprotocol, Origin, token) and the
connection then runs over the same asyncio streams. ``websockets``' sans-I/O ``ServerProtocol`` does
the RFC 6455 work (handshake validation, framing, masking, ping/pong, close handshake, UTF-8
checks, size limits) without owning any I/O, which is why one server can serve the static pages,
the JSON API and every WebSocket protocol on one port, with one TLS set-up.

Sending never waits: :meth:`WebSocket.send` writes the frame into the transport's buffer, and the
caller bounds its own backlog with :attr:`WebSocket.buffered` and :meth:`WebSocket.drain`.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
from collections.abc import AsyncIterator, Callable
from typing import Protocol

from websockets.exceptions import PayloadTooBig
from websockets.frames import Frame, Opcode
from websockets.http11 import Request as WsRequest
from websockets.http11 import Response as WsResponse
from websockets.server import ServerProtocol

from ninjemys.serve.http import Request

log = logging.getLogger(__name__)

#: the transport buffer a sender may fill before it must wait (:meth:`WebSocket.drain`)
WRITE_HIGH_WATER = 256 * 1024


class WebSocketEndpoint(Protocol):
    """What the HTTP server needs from a WebSocket path."""

    def handshake(self, request: Request) -> ServerProtocol | tuple[int, str]:
        """A protocol object configured for this request (subprotocols, Origin rules, size limit),
        or ``(status, reason)`` to refuse the upgrade with a plain HTTP answer."""
        ...

    async def serve(self, ws: WebSocket) -> None:
        """Run one accepted connection until it closes."""
        ...


class WebSocket:
    """One accepted WebSocket connection (asyncio streams driven through a sans-I/O protocol)."""

    def __init__(
        self,
        protocol: ServerProtocol,
        request: Request,
        reader: asyncio.StreamReader,
        writer: asyncio.StreamWriter,
    ) -> None:
        self.protocol = protocol
        self.request = request
        self.reader = reader
        self.writer = writer
        self.subprotocol: str | None = protocol.subprotocol
        peer = writer.get_extra_info("peername")
        self.peer = f"{peer[0]}:{peer[1]}" if isinstance(peer, tuple) else str(peer)
        #: called with the size limit text when a client sends an oversized message; the frame it
        #: returns (text) goes out just before the 1009 close
        self.on_oversized: Callable[[str], str | None] | None = None
        writer.transport.set_write_buffer_limits(high=WRITE_HIGH_WATER)
        #: bytes handed to the transport so far, and how far the client's reader has confirmed
        #: reading them (see :meth:`pace`)
        self.sent = 0
        self.confirmed = 0
        self._probed = 0  # the position the last ping was sent at
        self._pong = asyncio.Event()

    @property
    def closed(self) -> bool:
        return self.writer.is_closing() or self.protocol.state.name in ("CLOSING", "CLOSED")

    @property
    def buffered(self) -> int:
        """Bytes written but not yet taken by the kernel."""
        return self.writer.transport.get_write_buffer_size()

    async def drain(self) -> None:
        await self.writer.drain()

    def send(self, data: str | bytes | bytearray | memoryview, flush: bool = True) -> None:
        """Queue one message (str -> text frame, bytes -> binary frame); never blocks. With
        ``flush=False`` the frame waits for :meth:`flush`, so a burst leaves in one write."""
        if self.closed:
            return
        if isinstance(data, str):
            self.protocol.send_text(data.encode("utf-8"))
        else:
            self.protocol.send_binary(data)
        if flush:
            self.flush()

    async def pace(self, window: int) -> None:
        """Keep at most about ``window`` bytes between what was sent and what the client has read.

        Why: the kernel's socket buffers take whatever is written (tens of MB between two local
        sockets: a browser page starved of CPU was measured ~12 MB behind, seconds of camera frames),
        so a sender that only waits for the transport sends a slow client everything, late, and its
        own queue never gets to drop the stale data. A ping every ``window / 2`` bytes marks a
        position in the stream; the client answers it (RFC 6455 asks every client to) only once its
        reader got there, and beyond ``window`` unconfirmed bytes this waits for that pong."""
        if self.sent - self._probed >= window // 2 and not self.closed:
            self._probed = self.sent
            self.protocol.send_ping(str(self.sent).encode("ascii"))
            self.flush()
        while self.sent - self.confirmed > window and not self.closed:
            self._pong.clear()
            await self._pong.wait()

    def _confirm(self, payload: bytes | bytearray | memoryview) -> None:
        """A pong: the client read the stream up to the position its ping carried (other pongs,
        unsolicited or of another form, are ignored)."""
        try:
            position = int(bytes(payload).decode("ascii"))
        except (UnicodeDecodeError, ValueError):
            return
        if self.confirmed < position <= self.sent:
            self.confirmed = position
        self._pong.set()

    def close(self, code: int = 1000, reason: str = "") -> None:
        if self.protocol.state.name == "OPEN":
            self.protocol.send_close(code, reason)
            self.flush()

    def flush(self) -> None:
        """Hand every frame queued so far to the transport (one write for all of them)."""
        chunks = self.protocol.data_to_send()
        if not chunks:
            return
        eof = not chunks[-1]
        data = [c for c in chunks if c]
        if data:
            self.writer.writelines(data)
            self.sent += sum(len(c) for c in data)
        if eof and self.writer.can_write_eof():
            with contextlib.suppress(OSError, RuntimeError):
                self.writer.write_eof()

    async def messages(self) -> AsyncIterator[str | bytes]:
        """Each complete message the client sends (text as str, binary as bytes), until it closes."""
        parts: list[bytes | bytearray | memoryview] = []
        text = False
        protocol = self.protocol
        while True:
            try:
                data = await self.reader.read(1 << 16)
            except (ConnectionError, OSError):
                data = b""
            if data:
                protocol.receive_data(data)
            else:
                protocol.receive_eof()
            if isinstance(protocol.parser_exc, PayloadTooBig) and self.on_oversized is not None:
                notice = self.on_oversized(str(protocol.parser_exc))
                self.on_oversized = None
                if notice is not None:
                    frame = Frame(Opcode.TEXT, notice.encode("utf-8"))
                    self.writer.write(frame.serialize(mask=False, extensions=[]))
            for event in protocol.events_received():
                if not isinstance(event, Frame):
                    continue
                if event.opcode in (Opcode.TEXT, Opcode.BINARY):
                    text = event.opcode is Opcode.TEXT
                    parts = [event.data]
                elif event.opcode is Opcode.CONT:
                    parts.append(event.data)
                else:
                    if event.opcode is Opcode.PONG:
                        self._confirm(event.data)
                    continue  # ping/close: the protocol answers them
                if event.fin:
                    payload = b"".join(parts)
                    parts = []
                    yield payload.decode("utf-8") if text else payload
            self.flush()
            if not data or protocol.close_expected() or protocol.state.name == "CLOSED":
                self._pong.set()  # a sender waiting in pace() sees the end
                return


async def serve_upgrade(
    endpoint: WebSocketEndpoint,
    request: Request,
    reader: asyncio.StreamReader,
    writer: asyncio.StreamWriter,
) -> None:
    """Complete (or refuse) the upgrade of ``request`` and run the connection to its end."""
    decision = endpoint.handshake(request)
    if isinstance(decision, tuple):
        status, reason = decision
        protocol = ServerProtocol()
        response: WsResponse = protocol.reject(status, reason + "\n")
    else:
        protocol = decision
        # the HTTP server already read the request: replay its head so the protocol's own parser
        # validates it and moves on to frames
        head = f"GET {request.target or request.path} HTTP/1.1\r\n" + "".join(
            f"{k}: {v}\r\n" for k, v in request.raw_headers
        )
        protocol.receive_data((head + "\r\n").encode("latin-1"))
        events = [e for e in protocol.events_received() if isinstance(e, WsRequest)]
        if events:
            response = protocol.accept(events[0])
        else:
            response = protocol.reject(400, f"malformed WebSocket handshake: {protocol.handshake_exc}\n")
    protocol.send_response(response)
    for chunk in protocol.data_to_send():
        if chunk:
            writer.write(chunk)
    await writer.drain()
    if response.status_code != 101:
        log.info("websocket %s refused: %d %s", request.path, response.status_code, response.body)
        return
    ws = WebSocket(protocol, request, reader, writer)
    try:
        await endpoint.serve(ws)
    except asyncio.CancelledError:  # the server is closing: tell the client it goes away
        ws.close(1001, "server shutting down")
        raise
    finally:
        ws.close()
        with contextlib.suppress(Exception):
            await asyncio.wait_for(writer.drain(), 1.0)
        writer.close()
