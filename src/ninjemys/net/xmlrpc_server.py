"""An asyncio XML-RPC server (HTTP/1.1 keep-alive) for the master and every node's slave API.

Why not ``xmlrpc.server``: it spends a thread per request (rosmaster) or serialises everything behind
one socket (rospy), and a peer that opens a connection and sends nothing can stall it. Here every
connection is an :class:`asyncio.Protocol` on the caller's event loop, the HTTP parsing is the
bounded sans-IO parser of :mod:`ninjemys.wire.xmlrpc`, and each connection has two clocks: a request
must arrive completely within ``request_timeout`` of its first byte (slowloris), and an idle
keep-alive connection is closed after ``idle_timeout``. Garbage gets a 400 and a closed connection;
the server keeps serving everyone else.

RPC methods are the public methods of ``handler`` (names not starting with ``_``). They run on the
event loop, so they must not block; a method may return an awaitable, which is awaited before the
response is written (requests on one connection are answered in order). A handler may instead define
``_dispatch(method, params)`` to route calls itself. ``system.multicall`` (used by roslaunch to set
parameters) and ``system.listMethods`` are built in.
"""

from __future__ import annotations

import asyncio
import inspect
import logging
from collections import deque
from typing import Any

from ninjemys.errors import ProtocolError
from ninjemys.net.addresses import advertised_host
from ninjemys.wire import xmlrpc as wire

log = logging.getLogger(__name__)

#: Fault codes: the stdlib server's convention (1) for application errors; -32601 for unknown methods.
FAULT_APPLICATION = 1
FAULT_NO_METHOD = -32601
FAULT_PARSE = -32700

_MAX_QUEUED = 8


class XmlRpcServer:
    """Serve ``handler``'s public methods over XML-RPC on ``host:port`` (port 0 picks a free one).

    ``advertise`` is the host name put in :attr:`uri` (default: ROS_HOSTNAME / ROS_IP / host name,
    as ROS 1 nodes advertise themselves).
    """

    def __init__(
        self,
        handler: object,
        host: str = "0.0.0.0",
        port: int = 0,
        *,
        advertise: str | None = None,
        request_timeout: float = 30.0,
        idle_timeout: float = 300.0,
        max_body: int = wire.MAX_BODY_BYTES,
    ) -> None:
        self.handler = handler
        self.host = host
        self.request_timeout = request_timeout
        self.idle_timeout = idle_timeout
        self.max_body = max_body
        self._requested_port = port
        self._advertise = advertise
        self._server: asyncio.base_events.Server | None = None
        self._connections: set[_Connection] = set()
        self._dispatch = getattr(handler, "_dispatch", None)

    async def start(self) -> None:
        """Bind and start accepting (raises ``OSError`` if the port is taken)."""
        loop = asyncio.get_running_loop()
        self._server = await loop.create_server(
            lambda: _Connection(self), self.host, self._requested_port, reuse_address=True, backlog=1024
        )

    @property
    def port(self) -> int:
        if self._server is None or not self._server.sockets:
            return self._requested_port
        return self._server.sockets[0].getsockname()[1]

    @property
    def uri(self) -> str:
        """``http://host:port/`` as peers should call it."""
        return f"http://{self._advertise or advertised_host()}:{self.port}/"

    def close(self) -> None:
        """Stop accepting and drop every open connection."""
        if self._server is not None:
            self._server.close()
        for conn in list(self._connections):
            conn.close_gracefully()

    async def wait_closed(self) -> None:
        if self._server is not None:
            await self._server.wait_closed()

    # ----------------------------------------------------------------------------------- dispatch

    def call(self, method: str, params: tuple[Any, ...]) -> Any:
        """Run one RPC method (may return an awaitable). Raises ``wire.Fault``."""
        if method == "system.multicall":
            return self._multicall(params)
        if method == "system.listMethods":
            return self._list_methods()
        if self._dispatch is not None:
            return self._dispatch(method, params)
        fn = None if method.startswith("_") else getattr(self.handler, method, None)
        if fn is None or not callable(fn):
            raise wire.Fault(FAULT_NO_METHOD, f'method "{method}" is not supported')
        return fn(*params)

    def _list_methods(self) -> list[str]:
        names = [n for n in dir(self.handler) if not n.startswith("_") and callable(getattr(self.handler, n))]
        return sorted(names + ["system.listMethods", "system.multicall"])

    def _multicall(self, params: tuple[Any, ...]) -> Any:
        if len(params) != 1 or not isinstance(params[0], list):
            raise wire.Fault(FAULT_APPLICATION, "system.multicall expects one array of calls")
        results: list[Any] = []
        awaitables: list[tuple[int, Any]] = []
        for call in params[0]:
            try:
                if not isinstance(call, dict) or not isinstance(call.get("methodName"), str):
                    raise wire.Fault(FAULT_APPLICATION, "multicall entry needs methodName")
                if call["methodName"] == "system.multicall":
                    raise wire.Fault(FAULT_APPLICATION, "recursive system.multicall forbidden")
                result = self.call(call["methodName"], tuple(call.get("params", ())))
                if inspect.isawaitable(result):
                    awaitables.append((len(results), result))
                results.append([result])
            except wire.Fault as fault:
                results.append({"faultCode": fault.faultCode, "faultString": fault.faultString})
            except Exception as exc:  # an application error becomes that entry's fault
                results.append(_fault_dict(exc))
        if not awaitables:
            return results

        async def gather() -> list[Any]:
            for index, awaitable in awaitables:
                try:
                    results[index] = [await awaitable]
                except Exception as exc:
                    results[index] = _fault_dict(exc)
            return results

        return gather()


def _fault_dict(exc: Exception) -> dict[str, Any]:
    if isinstance(exc, wire.Fault):
        return {"faultCode": exc.faultCode, "faultString": exc.faultString}
    return {"faultCode": FAULT_APPLICATION, "faultString": f"{type(exc).__name__}: {exc}"}


class _Connection(asyncio.Protocol):
    """One client connection: parse, dispatch in order, answer, enforce the timeouts."""

    def __init__(self, server: XmlRpcServer) -> None:
        self.server = server
        self.parser = wire.HttpRequestParser(max_body=server.max_body)
        self.transport: asyncio.Transport | None = None
        self.queue: deque[wire.HttpMessage] = deque()
        self.busy = False
        self.closing = False
        self.read_paused = False
        self.write_paused = False
        self.timer: asyncio.TimerHandle | None = None
        self.timer_kind = ""

    # ----------------------------------------------------------------------------- asyncio hooks

    def connection_made(self, transport: asyncio.BaseTransport) -> None:
        assert isinstance(transport, asyncio.Transport)
        self.transport = transport
        self.server._connections.add(self)
        self._arm(self.server.idle_timeout, "idle")

    def connection_lost(self, exc: Exception | None) -> None:
        self.closing = True
        self._disarm()
        self.server._connections.discard(self)

    def pause_writing(self) -> None:
        self.write_paused = True
        self._update_reading()

    def resume_writing(self) -> None:
        self.write_paused = False
        self._update_reading()

    def data_received(self, data: bytes) -> None:
        if self.closing:
            return
        try:
            messages = self.parser.feed(data)
        except ProtocolError as exc:
            log.debug("XML-RPC: dropping %s: %s", self._peer(), exc)
            self._reply_and_close(400, str(exc))
            return
        self.queue.extend(messages)
        self._run_queue()

    # ------------------------------------------------------------------------------------ work

    def _run_queue(self) -> None:
        while self.queue and not self.busy and not self.closing:
            self._handle(self.queue.popleft())
        self._rearm()
        self._update_reading()

    def _handle(self, request: wire.HttpMessage) -> None:
        keep_alive = request.keep_alive
        if request.start[0] != "POST":
            self._reply_and_close(405, f"XML-RPC needs POST, got {request.start[0]}")
            return
        try:
            method, params = wire.parse_call(request.body)
        except ProtocolError as exc:
            self._write(wire.dump_fault(FAULT_PARSE, str(exc)), keep_alive)
            return
        try:
            result = self.server.call(method, params)
        except Exception as exc:
            self._write(self._fault_body(method, exc), keep_alive)
            return
        if inspect.isawaitable(result):
            self.busy = True
            self._disarm()
            task = asyncio.ensure_future(result)
            task.add_done_callback(lambda t: self._finish(method, t, keep_alive))
            self._update_reading()
            return
        self._write(self._result_body(method, result), keep_alive)

    def _finish(self, method: str, task: asyncio.Future[Any], keep_alive: bool) -> None:
        self.busy = False
        if self.closing:
            return
        if task.cancelled():
            self._write(wire.dump_fault(FAULT_APPLICATION, f"{method}: cancelled"), keep_alive)
        elif task.exception() is not None:
            exc = task.exception()
            assert exc is not None
            self._write(self._fault_body(method, exc), keep_alive)
        else:
            self._write(self._result_body(method, task.result()), keep_alive)
        self._run_queue()

    def _result_body(self, method: str, result: Any) -> bytes:
        try:
            return wire.dump_response(result)
        except ProtocolError as exc:
            return wire.dump_fault(FAULT_APPLICATION, f"{method}: {exc}")

    def _fault_body(self, method: str, exc: BaseException) -> bytes:
        if isinstance(exc, wire.Fault):
            return wire.dump_fault(exc.faultCode, exc.faultString)
        if not isinstance(exc, TypeError | ValueError | ProtocolError):
            log.exception("XML-RPC method %s failed", method, exc_info=exc)
        return wire.dump_fault(FAULT_APPLICATION, f"{type(exc).__name__}: {exc}")

    def _write(self, body: bytes, keep_alive: bool) -> None:
        if self.transport is None or self.closing:
            return
        self.transport.write(wire.http_response(body, 200, keep_alive))
        if not keep_alive:
            self.closing = True
            self.queue.clear()
            self.transport.close()

    def _reply_and_close(self, status: int, message: str) -> None:
        if self.transport is None or self.closing:
            return
        self.closing = True
        self.queue.clear()
        body = message.encode("utf-8", "replace") + b"\n"
        self.transport.write(wire.http_response(body, status, keep_alive=False))
        self.transport.close()

    # ------------------------------------------------------------------------- flow and timeouts

    def _update_reading(self) -> None:
        if self.transport is None or self.closing:
            return
        should_pause = self.write_paused or len(self.queue) >= _MAX_QUEUED or self.busy
        if should_pause and not self.read_paused:
            self.transport.pause_reading()
            self.read_paused = True
        elif not should_pause and self.read_paused:
            self.transport.resume_reading()
            self.read_paused = False

    def _rearm(self) -> None:
        """Idle clock between requests, request clock from a request's first byte, none while busy."""
        if self.busy or self.closing:
            self._disarm()
        elif self.parser.pending or self.queue:
            if self.timer_kind != "request":
                self._arm(self.server.request_timeout, "request")
        else:
            self._arm(self.server.idle_timeout, "idle")

    def _arm(self, delay: float, kind: str) -> None:
        self._disarm()
        self.timer_kind = kind
        self.timer = asyncio.get_running_loop().call_later(delay, self._timed_out)

    def _disarm(self) -> None:
        self.timer_kind = ""
        if self.timer is not None:
            self.timer.cancel()
            self.timer = None

    def _timed_out(self) -> None:
        self.timer = None
        if self.busy:
            return
        log.debug("XML-RPC: closing %s (timeout)", self._peer())
        self.abort()

    def close_gracefully(self) -> None:
        """Flush what was already answered, then close; abort if the peer does not read within 1 s."""
        self.closing = True
        self._disarm()
        if self.transport is not None:
            self.transport.close()
            asyncio.get_running_loop().call_later(1.0, self.transport.abort)

    def abort(self) -> None:
        self.closing = True
        self._disarm()
        if self.transport is not None:
            self.transport.abort()

    def _peer(self) -> str:
        if self.transport is None:
            return "?"
        return str(self.transport.get_extra_info("peername"))
