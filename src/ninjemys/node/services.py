"""Services over TCPROS: servers (one thread per client connection) and persistent-capable proxies.

A service call is a strict request/response exchange, so after the header handshake (done on the
I/O loop for servers) each server connection gets its own thread doing blocking socket I/O and
calling the handler there; a proxy does its I/O directly in the caller's thread. Neither path
crosses threads per call, which is what makes a persistent service round trip cheap.

Wire: request ``uint32 len`` + body; response ``uint8 ok`` then ``uint32 len`` + body, or the error
text when ok is 0. A client header with ``probe=1`` gets our header and a closed connection (that is
how rosservice learns a service's type).
"""

from __future__ import annotations

import logging
import socket
import struct
import threading
import time
from collections.abc import Callable, Mapping
from typing import TYPE_CHECKING, Any

from ninjemys.errors import (
    MasterError,
    NinjemysError,
    ProtocolError,
    ServiceError,
    ShutdownError,
    TimeoutError_,
)
from ninjemys.net.addresses import split_uri
from ninjemys.node import transport
from ninjemys.wire import headers
from ninjemys.wire.tcpros import MAX_FRAME_LEN, encode_service_response

if TYPE_CHECKING:
    from ninjemys.node.node import Node

_log = logging.getLogger(__name__)
_U32 = struct.Struct("<I")


class _Reader:
    """Buffered exact reads on a blocking socket: one ``recv_into`` usually brings a whole
    response (ok byte, length and body), instead of one system call per field."""

    __slots__ = ("sock", "_buf", "_view", "_start", "_end")

    def __init__(self, sock: socket.socket, size: int = 1 << 16) -> None:
        self.sock = sock
        self._buf = bytearray(size)
        self._view = memoryview(self._buf)
        self._start = self._end = 0

    def exact(self, n: int) -> bytes | bytearray:
        have = self._end - self._start
        if have >= n:
            start = self._start
            self._start += n
            return self._buf[start : start + n]
        if n > len(self._buf) // 2:
            return self._big(n, have)
        if self._start:
            self._view[:have] = self._view[self._start : self._end]
            self._start, self._end = 0, have
        while self._end - self._start < n:
            k = self.sock.recv_into(self._view[self._end :])
            if k == 0:
                raise ConnectionError(
                    f"peer closed the connection after {self._end - self._start} of {n} bytes"
                )
            self._end += k
        self._start = n
        return self._buf[:n]

    def _big(self, n: int, have: int) -> bytearray:
        out = bytearray(n)
        out[:have] = self._view[self._start : self._end]
        self._start = self._end = 0
        view, got = memoryview(out), have
        while got < n:
            k = self.sock.recv_into(view[got:])
            if k == 0:
                raise ConnectionError(f"peer closed the connection after {got} of {n} bytes")
            got += k
        return out

    def frame(self) -> bytes | bytearray:
        (length,) = _U32.unpack(self.exact(4))
        if length > MAX_FRAME_LEN:
            raise ProtocolError(f"length prefix {length} exceeds the {MAX_FRAME_LEN}-byte limit")
        return self.exact(length)

    def header(self) -> dict[str, str]:
        length = headers.header_length(self.exact(4))
        return headers.decode_header(self.exact(length))


def make_response(response_class: Any, value: Any) -> Any:
    """Turn what a handler returned into a response, the ways rospy accepts (instance, dict, tuple, value)."""
    if isinstance(value, response_class):
        return value
    if value is None:
        raise ServiceError("service handler returned None")
    if isinstance(value, dict):
        return response_class(**value)
    if isinstance(value, list | tuple):
        return response_class(*value)
    return response_class(value)


class ServiceServer:
    """A service this node provides; see :meth:`ninjemys.node.Node.service`."""

    def __init__(self, node: Node, name: str, service_class: Any, handler: Callable[[Any], Any]) -> None:
        self.node = node
        self.resolved_name = name
        self.name = name
        self.service_class = service_class
        self.type: str = service_class._type
        self.md5sum: str = service_class._md5sum
        self.request_class = service_class._request_class
        self.response_class = service_class._response_class
        self.handler = handler
        self._socks: set[socket.socket] = set()
        self._lock = threading.Lock()
        self.closed = False

    def _reply_header(self) -> dict[str, str]:
        return {
            "callerid": self.node.name,
            "service": self.name,
            "type": self.type,
            "md5sum": self.md5sum,
            "request_type": self.request_class._type,
            "response_type": self.response_class._type,
        }

    async def accept(self, sock: socket.socket, header: Mapping[str, str]) -> None:
        """A client connected (on the loop): check, answer, then serve it from its own thread."""
        error = headers.check_service_client_header(header, self.name, self.md5sum)
        who = header.get("callerid", transport.peer_name(sock))
        if error is None and self.closed:
            error = f"service [{self.name}] is shutting down"
        if error is not None:
            _log.warning("service %s: refused client %s: %s", self.name, who, error)
            await transport.send_error_header(sock, error)
            transport.close_quietly(sock)
            return
        await transport.write_all(sock, headers.encode_header(self._reply_header()))
        if header.get("probe") == "1":
            transport.close_quietly(sock)
            return
        sock.setblocking(True)
        with self._lock:
            self._socks.add(sock)
        self.node.runtime.start_thread(lambda: self._serve(sock, who), f"srv:{self.name}")

    def _serve(self, sock: socket.socket, who: str) -> None:
        reader = _Reader(sock)
        try:
            while not self.closed:
                try:
                    body = reader.frame()
                except (ConnectionError, OSError):
                    return  # the client is done (non-persistent clients close after one call)
                sock.sendall(self._handle(body, who))
        except ProtocolError as exc:
            _log.warning("service %s: dropped client %s: %s", self.name, who, exc)
        except OSError as exc:
            _log.info("service %s: client %s went away: %s", self.name, who, exc)
        finally:
            with self._lock:
                self._socks.discard(sock)
            transport.close_quietly(sock)

    def _handle(self, body: bytes | bytearray, who: str) -> bytes:
        try:
            request = self.request_class.deserialize_from(body)
        except Exception as exc:
            _log.warning("service %s: bad request from %s: %s", self.name, who, exc)
            return encode_service_response(False, f"cannot deserialize request: {exc}")
        try:
            response = make_response(self.response_class, self.handler(request))
            return encode_service_response(True, response.serialize_to_bytes())
        except Exception as exc:
            _log.error("service %s: error processing request: %s", self.name, exc)
            return encode_service_response(False, f"error processing request: {exc}")

    def shutdown(self) -> None:
        """Stop serving: unregister, and close every client connection."""
        if self.closed:
            return
        self.closed = True
        self.node._drop_service(self)
        with self._lock:
            socks = list(self._socks)
        for sock in socks:
            try:
                sock.shutdown(socket.SHUT_RDWR)
            except OSError:
                pass

    unregister = shutdown


class ServiceProxy:
    """Calls a service; see :meth:`ninjemys.node.Node.service_proxy`. Thread-safe."""

    def __init__(
        self,
        node: Node,
        name: str,
        service_class: Any,
        persistent: bool = False,
        headers: Mapping[str, str] | None = None,
    ) -> None:
        self.node = node
        self.resolved_name = name
        self.name = name
        self.service_class = service_class
        self.request_class = service_class._request_class
        self.response_class = service_class._response_class
        self.persistent = persistent
        self.headers = dict(headers or {})
        self._sock: socket.socket | None = None
        self._reader: _Reader | None = None
        self._lock = threading.Lock()
        self._closed = False

    def __call__(self, *args: Any, **kwargs: Any) -> Any:
        return self.call(*args, **kwargs)

    def call(self, *args: Any, **kwargs: Any) -> Any:
        """Call the service with a request instance, or with the request's fields (positional/keyword)."""
        if len(args) == 1 and not kwargs and isinstance(args[0], self.request_class):
            request = args[0]
        else:
            try:
                request = self.request_class(*args, **kwargs)
            except TypeError as exc:
                raise ServiceError(f"service [{self.name}]: bad request arguments: {exc}") from None
        payload = request.serialize_to_bytes()
        frame = _U32.pack(len(payload)) + payload
        with self._lock:
            if self._closed:
                raise ShutdownError(f"service proxy for [{self.name}] is closed")
            if self._sock is None:
                self._sock = self._connect()
                self._reader = _Reader(self._sock)
            sock, reader = self._sock, self._reader
            try:
                sock.sendall(frame)
                ok = reader.exact(1)[0]
                body = reader.frame()
            except (OSError, ProtocolError) as exc:
                self._drop()
                raise ServiceError(
                    f"service [{self.name}]: transport error completing the call: {exc}"
                ) from None
            if not self.persistent:
                self._drop()
        if not ok:
            raise ServiceError(
                f"service [{self.name}] responded with an error: {body.decode('utf-8', 'replace')}"
            )
        try:
            return self.response_class.deserialize_from(body)
        except Exception as exc:
            raise ServiceError(f"service [{self.name}]: cannot decode the response: {exc}") from None

    def _lookup(self) -> tuple[str, int]:
        try:
            uri = self.node.master.lookup_service(self.name)
        except MasterError as exc:
            raise ServiceError(f"service [{self.name}] unavailable: {exc}") from None
        try:
            return split_uri(uri)
        except ValueError:
            raise ServiceError(f"service [{self.name}]: master gave a bad URI {uri!r}") from None

    def _connect(self, probe: bool = False, timeout: float | None = 10.0) -> socket.socket:
        host, port = self._lookup()
        try:
            sock = socket.create_connection((host, port), timeout=timeout)
        except OSError as exc:
            raise ServiceError(
                f"unable to connect to service [{self.name}] at {host}:{port}: {exc}"
            ) from None
        try:
            sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            fields = {
                "callerid": self.node.name,
                "service": self.name,
                "md5sum": "*" if probe else self.service_class._md5sum,
                "type": self.service_class._type,
            }
            if probe:
                fields["probe"] = "1"
            elif self.persistent:
                fields["persistent"] = "1"
            fields.update(self.headers)
            sock.sendall(headers.encode_header(fields))
            reply = _Reader(sock, 4096).header()
        except (OSError, NinjemysError) as exc:
            transport.close_quietly(sock)
            raise ServiceError(f"service [{self.name}]: handshake failed: {exc}") from None
        if "error" in reply:
            transport.close_quietly(sock)
            raise ServiceError(f"service [{self.name}]: {reply['error']}")
        sock.settimeout(None)
        return sock

    def _drop(self) -> None:
        if self._sock is not None:
            transport.close_quietly(self._sock)
        self._sock = None

    def wait_for_service(self, timeout: float | None = None) -> None:
        """Block until the service is registered and answers a probe; TimeoutError_ after ``timeout``."""
        deadline = None if timeout is None else time.monotonic() + timeout
        delay = 0.01
        while True:
            if self.node.is_shutdown:
                raise ShutdownError("node shut down while waiting for service")
            try:
                transport.close_quietly(self._connect(probe=True, timeout=1.0))
                return
            except ServiceError:
                pass
            if deadline is not None and time.monotonic() >= deadline:
                raise TimeoutError_(f"timeout exceeded while waiting for service {self.name}")
            wait = delay if deadline is None else min(delay, max(0.0, deadline - time.monotonic()))
            self.node.wait_for_shutdown(wait)
            delay = min(delay * 2, 0.2)

    def close(self) -> None:
        with self._lock:
            self._closed = True
            self._drop()
