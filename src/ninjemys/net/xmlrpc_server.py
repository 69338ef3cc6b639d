"""An event-loop XML-RPC server (HTTP/1.1 keep-alive) for the master and every node's slave API.

Why not ``xmlrpc.server``: it spends a thread per request (rosmaster) or serialises everything behind
one socket (rospy), and a peer that opens a connection and sends nothing can stall it. Here every
connection is a non-blocking socket watched by the caller's event loop, the HTTP parsing is the
bounded sans-IO parser of :mod:`ninjemys.wire.xmlrpc`, and each connection has two clocks: a request
must arrive completely within ``request_timeout`` of its first byte (slowloris), and an idle
keep-alive connection is closed after ``idle_timeout``. Garbage gets a 400 and a closed connection;
the server keeps serving everyone else.

RPC methods are the public methods of ``handler`` (names not starting with ``_``). They run on the
event loop, so they must not block; a method may return an awaitable, which is awaited before the
response is written (requests on one connection are answered in order). A handler may instead define
``_dispatch(method, params)`` to route calls itself. ``system.multicall`` (used by roslaunch to set
parameters) and ``system.listMethods`` are built in.

The server uses only the loop calls that asyncio's loop and :class:`ninjemys.net.loop.Loop` share
(``add_reader``/``add_writer``, ``call_later``, ``create_task``), so the same code serves the master
and the web tools (asyncio) and every node's slave API (the node runtime's small loop, which keeps
asyncio out of node processes).
"""

from __future__ import annotations

import logging
import socket
from collections import deque

from ninjemys.errors import ProtocolError
from ninjemys.net import auth
from ninjemys.net.addresses import advertised_host, lookup_host
from ninjemys.net.loop import get_running_loop, is_numeric_host
from ninjemys.wire import xmlrpc as wire

TYPE_CHECKING = False  # importing typing costs ~7 ms of every node's start-up; checkers set it
if TYPE_CHECKING:
    from typing import Any

log = logging.getLogger(__name__)

#: Fault codes: the stdlib server's convention (1) for application errors; -32601 for unknown methods.
FAULT_APPLICATION = 1
FAULT_NO_METHOD = -32601
FAULT_PARSE = -32700

_MAX_QUEUED = 8
#: Stop reading a connection whose unsent answers exceed this (the peer does not read them).
_WRITE_HIGH_WATER = 256 * 1024
_RECV_SIZE = 65536
#: Connections accepted per readiness event (fairness with the other sockets on the loop).
_ACCEPT_BATCH = 64


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
        self._sock: socket.socket | None = None
        self._loop: Any = None
        self._connections: set[_Connection] = set()
        self._dispatch = getattr(handler, "_dispatch", None)
        # the credentials are looked up once (NINJEMYS_SECRET / NINJEMYS_KEYS_FILE, net.auth): reading
        # the environment on every request cost ~2 us of a ~150 us master call
        self.auth = auth.credentials()

    async def start(self) -> None:
        """Bind and start accepting (raises ``OSError`` if the port is taken)."""
        loop = get_running_loop()
        host = self.host or "0.0.0.0"
        if is_numeric_host(host):  # no lookup: asyncio would send even this to its thread pool
            infos = socket.getaddrinfo(
                lookup_host(host), self._requested_port, type=socket.SOCK_STREAM, flags=socket.AI_PASSIVE
            )
        else:
            infos = await loop.getaddrinfo(
                host, self._requested_port, type=socket.SOCK_STREAM, flags=socket.AI_PASSIVE
            )
        if not infos:
            raise OSError(f"cannot resolve {host}")
        family, kind, proto, _, address = infos[0]
        sock = socket.socket(family, kind, proto)
        try:
            sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
            sock.bind(address)
            sock.listen(1024)
            sock.setblocking(False)
        except BaseException:
            sock.close()
            raise
        self._sock, self._loop = sock, loop
        loop.add_reader(sock.fileno(), self._accept)

    def _accept(self) -> None:
        sock = self._sock
        if sock is None:
            return
        for _ in range(_ACCEPT_BATCH):
            try:
                conn, _ = sock.accept()
            except (BlockingIOError, InterruptedError):
                return
            except OSError as exc:  # out of file descriptors, ...: keep serving the connections we have
                log.warning("XML-RPC server on port %s: accept failed: %s", self.port, exc)
                return
            _Connection(self, conn, self._loop)

    @property
    def port(self) -> int:
        if self._sock is None:
            return self._requested_port
        return self._sock.getsockname()[1]

    @property
    def uri(self) -> str:
        """``http://host:port/`` as peers should call it."""
        return f"http://{self._advertise or advertised_host()}:{self.port}/"

    def close(self) -> None:
        """Stop accepting and drop every open connection."""
        sock, self._sock = self._sock, None
        if sock is not None:
            self._requested_port = sock.getsockname()[1]
            self._loop.remove_reader(sock.fileno())
            sock.close()
        for conn in list(self._connections):
            conn.close_gracefully()

    async def wait_closed(self) -> None:
        """Nothing to wait for once :meth:`close` returned (kept for asyncio-style callers)."""

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
                if _is_awaitable(result):
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


def _is_awaitable(value: Any) -> bool:
    return hasattr(value, "__await__") and not isinstance(value, type)


async def _await(awaitable: Any) -> Any:
    return await awaitable


def _fault_dict(exc: Exception) -> dict[str, Any]:
    if isinstance(exc, wire.Fault):
        return {"faultCode": exc.faultCode, "faultString": exc.faultString}
    return {"faultCode": FAULT_APPLICATION, "faultString": f"{type(exc).__name__}: {exc}"}


class _Connection:
    """One client connection: read, parse, dispatch in order, answer, enforce the timeouts."""

    def __init__(self, server: XmlRpcServer, sock: socket.socket, loop: Any) -> None:
        self.server = server
        self.sock = sock
        self.fd = sock.fileno()
        self.loop = loop
        self.parser = wire.HttpRequestParser(max_body=server.max_body)
        self.trusted: str | None = None  # whom a signed request authenticated this connection for
        self.queue: deque[wire.HttpMessage] = deque()
        self.out: deque[memoryview] = deque()
        self.out_bytes = 0
        self.busy = False
        self.closing = False
        self.closed = False
        self.eof = False
        self.reading = False
        self.timer: Any = None
        self.timer_kind = ""
        sock.setblocking(False)
        try:
            sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        except OSError:
            pass
        server._connections.add(self)
        self._set_reading(True)
        self._arm(server.idle_timeout, "idle")

    # ----------------------------------------------------------------------------------- reading

    def _on_readable(self) -> None:
        try:
            data = self.sock.recv(_RECV_SIZE)
        except (BlockingIOError, InterruptedError):
            return
        except OSError:
            self.abort()
            return
        if not data:
            self._set_reading(False)
            self.eof = True
            self._run_queue()
            return
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
        if self.eof and not self.busy and not self.closing:
            self.close_gracefully()  # the peer sent all it will; answer what it asked, then close
            return
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
        refused, self.trusted = auth.check_on_connection(
            self.server.auth, self.trusted, request.headers, request.body, params
        )
        if refused is not None:
            log.warning(
                "XML-RPC %s from %s refused: authentication failed: %s", method, self._peer(), refused
            )
            self._write(wire.dump_response([-1, f"authentication failed: {refused}", 0]), keep_alive)
            return
        try:
            result = self.server.call(method, params)
        except Exception as exc:
            self._write(self._fault_body(method, exc), keep_alive)
            return
        if _is_awaitable(result):
            self.busy = True
            self._disarm()
            if not hasattr(result, "add_done_callback"):
                result = self.loop.create_task(result if hasattr(result, "send") else _await(result))
            result.add_done_callback(lambda t: self._finish(method, t, keep_alive))
            self._update_reading()
            return
        self._write(self._result_body(method, result), keep_alive)

    def _finish(self, method: str, task: Any, keep_alive: bool) -> None:
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
        if self.closing:
            return
        self._send(wire.http_response(body, 200, keep_alive))
        if not keep_alive:
            self.queue.clear()
            self.close_gracefully()

    def _reply_and_close(self, status: int, message: str) -> None:
        if self.closing:
            return
        self.queue.clear()
        body = message.encode("utf-8", "replace") + b"\n"
        self._send(wire.http_response(body, status, keep_alive=False))
        self.close_gracefully()

    # ----------------------------------------------------------------------------------- writing

    def _send(self, data: bytes) -> None:
        """Write at once what the kernel takes; queue the rest and drain it when writable."""
        if self.closed:
            return
        view = memoryview(data)
        if not self.out:
            try:
                view = view[self.sock.send(view) :]
            except (BlockingIOError, InterruptedError):
                pass
            except OSError:
                self.abort()
                return
            if not view:
                return
            self.loop.add_writer(self.fd, self._on_writable)
        self.out.append(view)
        self.out_bytes += len(view)

    def _on_writable(self) -> None:
        while self.out:
            head = self.out[0]
            try:
                sent = self.sock.send(head)
            except (BlockingIOError, InterruptedError):
                return
            except OSError:
                self.abort()
                return
            self.out_bytes -= sent
            if sent < len(head):
                self.out[0] = head[sent:]
                return
            self.out.popleft()
        self.loop.remove_writer(self.fd)
        if self.closing:
            self._close_now()
        else:
            self._update_reading()

    # ------------------------------------------------------------------------- flow and timeouts

    def _set_reading(self, on: bool) -> None:
        if on and not self.reading and not self.closed:
            self.loop.add_reader(self.fd, self._on_readable)
            self.reading = True
        elif not on and self.reading:
            self.loop.remove_reader(self.fd)
            self.reading = False

    def _update_reading(self) -> None:
        if self.closing or self.eof:
            return
        paused = self.out_bytes > _WRITE_HIGH_WATER or len(self.queue) >= _MAX_QUEUED or self.busy
        self._set_reading(not paused)

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
        self.timer = self.loop.call_later(delay, self._timed_out)

    def _disarm(self) -> None:
        self.timer_kind = ""
        if self.timer is not None:
            self.timer.cancel()
            self.timer = None

    def _timed_out(self) -> None:
        self.timer = None
        if self.busy and not self.closing:
            return
        log.debug("XML-RPC: closing %s (timeout)", self._peer())
        self.abort()

    def close_gracefully(self) -> None:
        """Flush what was already answered, then close; abort if the peer does not read within 1 s."""
        if self.closing:
            return
        self.closing = True
        self._disarm()
        self._set_reading(False)
        if not self.out:
            self._close_now()
            return
        self.timer = self.loop.call_later(1.0, self._timed_out)

    def abort(self) -> None:
        self.closing = True
        self._disarm()
        self._close_now()

    def _close_now(self) -> None:
        if self.closed:
            return
        self.closed = True
        self._disarm()
        self._set_reading(False)
        if self.out:
            self.loop.remove_writer(self.fd)
            self.out.clear()
            self.out_bytes = 0
        self.queue.clear()
        self.server._connections.discard(self)
        try:
            self.sock.close()
        except OSError:
            pass

    def _peer(self) -> str:
        try:
            return str(self.sock.getpeername())
        except OSError:
            return "?"
