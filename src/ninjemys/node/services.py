"""Services over TCPROS: servers (one thread per client connection) and persistent-capable proxies.

A service call is a strict request/response exchange, so after the header handshake (done on the
I/O loop for servers) each server connection gets its own thread doing blocking socket I/O and
calling the handler there; a proxy does its I/O directly in the caller's thread. Neither path
crosses threads per call, which is what makes a persistent service round trip cheap: per call, each
side makes one ``sendall`` and (usually) one ``recv_into`` into its connection's preallocated buffer
(:class:`_Link`), and the Python between them is bound once per connection (see docs/node_services.md).

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

from ninjemys.errors import (
    MasterError,
    NinjemysError,
    ProtocolError,
    ServiceError,
    ShutdownError,
    TimeoutError_,
)
from ninjemys.net import auth
from ninjemys.net.addresses import is_local_address, split_uri
from ninjemys.node import transport
from ninjemys.wire import headers
from ninjemys.wire.headers import MAX_HEADER_LEN
from ninjemys.wire.tcpros import (
    MAX_FRAME_LEN,
    SERVICE_RESPONSE_HEAD,
    encode_service_response,
)

TYPE_CHECKING = False  # importing typing costs ~7 ms of every node's start-up; checkers set it

if TYPE_CHECKING:
    from typing import Any

    from ninjemys.node.context import NodeContext

_log = logging.getLogger(__name__)
_U32 = struct.Struct("<I")
_unpack_len = _U32.unpack_from
_unpack_response_head = SERVICE_RESPONSE_HEAD.unpack_from


def probe(service: str, uri: str, timeout: float = 5.0, caller_id: str = "/rosservice") -> dict[str, str]:
    """The provider's connection header for ``service`` (its ``type``, ``md5sum``, ...), learned the
    way ROS 1 learns a service's type: a TCPROS probe (``probe=1``, md5 ``*``) that the provider
    answers with its header before closing. One home for the tools, the gateway and rosapi.

    Raises :class:`ServiceError` naming the service and its URI when it cannot be reached.
    """
    try:
        host, port = split_uri(uri)
    except ValueError:
        raise ServiceError(f"service [{service}] has an invalid RPC URI [{uri}]") from None
    try:
        with socket.create_connection((host, port), timeout=timeout) as sock:
            fields = {"probe": "1", "md5sum": "*", "callerid": caller_id, "service": service}
            sock.sendall(headers.encode_header(auth.sign_fields(fields)))
            prefix = _recv_exact(sock, 4)
            reply = headers.decode_header(_recv_exact(sock, headers.header_length(prefix)))
            refused = auth.check_fields(reply)
            if refused is not None:
                raise ServiceError(f"service [{service}] at {uri}: authentication failed: {refused}")
            return reply
    except (OSError, NinjemysError) as exc:
        raise ServiceError(
            f"Unable to communicate with service [{service}], address [{uri}]: {exc}"
        ) from None


def _recv_exact(sock: socket.socket, n: int) -> bytes:
    chunks, have = [], 0
    while have < n:
        chunk = sock.recv(n - have)
        if not chunk:
            raise ConnectionError("service closed the connection during the handshake")
        chunks.append(chunk)
        have += len(chunk)
    return b"".join(chunks)


class RequestArgumentError(ServiceError, TypeError):
    """Call arguments that do not make a request of the service's type. Also a TypeError, which is
    what rospy raises for them (code written for rospy may catch it)."""


class _Link:
    """The receive side of one service connection: records (a fixed head whose last field is the
    body length, then the body) read through one preallocated buffer.

    A service exchange is one small record each way, so the usual read is ONE ``recv_into`` that
    brings the whole record; parsing is one ``unpack_from`` and the body is one copy out, as
    ``bytes`` (what generated classes decode fastest, and immutable, so deserialization may keep
    views into it). A record split across packets is completed with further reads; one larger than
    half the buffer is received straight into a ``bytearray`` of its exact size (no further copy).
    Bytes past the record (a client sending ahead) stay for the next one.
    Not thread-safe: its owner (a proxy under its lock, or a server connection's thread) serializes use.
    """

    __slots__ = ("sock", "sendall", "_recv_into", "_buf", "_view", "_start", "_end")

    def __init__(self, sock: socket.socket, size: int = 1 << 16) -> None:
        self.sock = sock
        self.sendall = sock.sendall
        self._recv_into = sock.recv_into
        self._buf = bytearray(size)
        self._view = memoryview(self._buf)
        self._start = self._end = 0

    def request(self) -> bytes | bytearray:
        """The next request body. Fast path: nothing buffered and one read brings exactly one record
        (the length test also rules out short reads: a stale prefix never matches ``end``)."""
        if self._start == self._end:  # both 0: every path that empties the buffer resets them
            buf = self._buf
            end = self._recv_into(buf)
            if end == _unpack_len(buf)[0] + 4:
                return self._view[4:end].tobytes()
            if not end:
                raise ConnectionError("peer closed the connection")
            self._end = end
        return self.take(_U32)[1]

    def exchange(self, frame: bytes) -> tuple[int, bytes | bytearray]:
        """Send a framed request and read its response: (ok byte, body); a client's whole call on
        the wire, in one method. Fast path as :meth:`request`."""
        self.sendall(frame)
        if self._start == self._end:
            buf = self._buf
            end = self._recv_into(buf)
            ok, length = _unpack_response_head(buf)
            if end == length + 5:
                return ok, self._view[5:end].tobytes()
            if not end:
                raise ConnectionError("peer closed the connection")
            self._end = end
        return self.take(SERVICE_RESPONSE_HEAD)

    def take(self, head: struct.Struct, limit: int = MAX_FRAME_LEN) -> tuple[int, bytes | bytearray]:
        """The next record: (the head's first field, the body). ``ConnectionError`` if the peer
        closes first, ``ProtocolError`` if the announced length exceeds ``limit``."""
        buf = self._buf
        start, end = self._start, self._end
        if start == end:  # the usual case: nothing buffered, read into the start of the buffer
            start = 0
            end = self._recv_into(buf)
            if not end:
                raise ConnectionError("peer closed the connection")
        size = head.size
        if end - start < size:
            start, end = self._more(start, end, size)
        fields = head.unpack_from(buf, start)
        length = fields[-1]
        if length > limit:
            raise ProtocolError(f"length prefix {length} exceeds the {limit}-byte limit")
        first = start + size
        stop = first + length
        if stop > end:
            return fields[0], self._rest(first, end, length)
        if stop == end:
            self._start = self._end = 0
        else:
            self._start, self._end = stop, end
        return fields[0], self._view[first:stop].tobytes()

    def _more(self, start: int, end: int, need: int) -> tuple[int, int]:
        """Read until ``need`` bytes follow ``start`` (moving them to the front if they would not fit)."""
        if start + need > len(self._buf):
            self._view[: end - start] = self._view[start:end]
            start, end = 0, end - start
        while end - start < need:
            k = self._recv_into(self._view[end:])
            if not k:
                raise ConnectionError(f"peer closed the connection after {end - start} of {need} bytes")
            end += k
        return start, end

    def _rest(self, first: int, end: int, length: int) -> bytes | bytearray:
        """A body that did not arrive with its head: completed in the buffer, or in its own."""
        if length <= len(self._buf) // 2:
            start, end = self._more(first, end, length)
            stop = start + length
            self._start, self._end = (0, 0) if stop == end else (stop, end)
            return self._view[start:stop].tobytes()
        have = end - first
        out = bytearray(length)
        out[:have] = self._view[first:end]
        self._start = self._end = 0
        view, got = memoryview(out), have
        while got < length:
            k = self._recv_into(view[got:])
            if not k:
                raise ConnectionError(f"peer closed the connection after {got} of {length} bytes")
            got += k
        return out

    def header(self) -> dict[str, str]:
        """A connection header (length-prefixed ``key=value`` fields)."""
        _, body = self.take(_U32, MAX_HEADER_LEN)
        return headers.decode_header(body)


def make_response(response_class: Any, value: Any) -> Any:
    """Turn what a handler returned into a response, the ways rospy accepts (instance, dict, tuple,
    value); what cannot be one is a ServiceError worded as rospy's, which the caller receives."""
    if isinstance(value, response_class):
        return value
    if value is None:
        raise ServiceError("service handler returned None")
    if isinstance(value, dict):
        try:
            return response_class(**value)
        except (AttributeError, TypeError) as exc:
            raise ServiceError(f"handler returned invalid value: {exc}") from None
    if isinstance(value, list | tuple):
        try:
            return response_class(*value)
        except TypeError as exc:
            raise ServiceError(f"handler returned wrong number of values: {exc}") from None
    try:
        return response_class(value)
    except TypeError as exc:
        raise ServiceError(f"handler returned invalid value: {exc}") from None


class ServiceServer:
    """A service this node provides; see :meth:`ninjemys.node.Node.service`."""

    def __init__(
        self, node: NodeContext, name: str, service_class: Any, handler: Callable[[Any], Any]
    ) -> None:
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
        #: connections inside a call (request read, reply not yet sent): shutdown(grace) waits for them
        self._busy: set[socket.socket] = set()
        self._lock = threading.Lock()
        self._closed = False

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
        await transport.write_all(sock, headers.encode_header(auth.sign_fields(self._reply_header())))
        if header.get("probe") == "1":
            transport.close_quietly(sock)
            return
        sock.setblocking(True)
        with self._lock:
            self._socks.add(sock)
        self.node.runtime.start_thread(lambda: self._serve(sock, who), f"srv:{self.name}")

    def _serve(self, sock: socket.socket, who: str) -> None:
        """This connection's thread: read a request, answer it, repeat until the client leaves.

        Everything a call needs is bound to locals once, so a request costs one ``recv_into``, the
        deserialize, the handler, the serialize and one ``sendall``, with no lock and no other
        thread woken. Handler errors become ok=0 responses; the connection stays usable.
        """
        link = _Link(sock)
        receive, send = link.request, link.sendall
        request_class = self.request_class
        deserialize = request_class.deserialize_from
        # a request type without fields (std_srvs/Trigger, Empty) arrives as an empty body: building
        # the default instance is what decoding it would do, at a fraction of the cost
        fieldless = not getattr(request_class, "_slot_types", True)
        response_class = self.response_class
        handler = self.handler
        ok_head = SERVICE_RESPONSE_HEAD.pack
        busy = self._busy
        try:
            while not self._closed:
                try:
                    body = receive()
                except OSError:
                    return  # the client is done (non-persistent clients close after one call)
                try:
                    request = request_class() if fieldless and not body else deserialize(body)
                except Exception as exc:
                    send(self._bad_request(exc, who))
                    continue
                busy.add(sock)
                try:
                    value = handler(request)
                    if type(value) is not response_class:
                        value = make_response(response_class, value)
                    payload = value.serialize_to_bytes()
                    reply = ok_head(1, len(payload)) + payload
                except Exception as exc:
                    reply = self._failed(exc)
                try:
                    send(reply)
                finally:
                    busy.discard(sock)
        except ProtocolError as exc:
            _log.warning("service %s: dropped client %s: %s", self.name, who, exc)
        except OSError as exc:
            _log.info("service %s: client %s went away: %s", self.name, who, exc)
        finally:
            with self._lock:
                self._socks.discard(sock)
            transport.close_quietly(sock)

    def _bad_request(self, exc: Exception, who: str) -> bytes:
        _log.warning("service %s: bad request from %s: %s", self.name, who, exc)
        return encode_service_response(False, f"cannot deserialize request: {exc}")

    def _failed(self, exc: Exception) -> bytes:
        """The caller's error text, worded as rospy's: a handler that refuses the request on purpose
        (ServiceError; rospy.ServiceException through the facade) "cannot process" it, any other
        exception is an "error processing" it and is logged here."""
        if isinstance(exc, ServiceError):
            _log.debug("service %s: handler refused the request: %s", self.name, exc)
            return encode_service_response(False, f"service cannot process request: {exc}")
        if getattr(exc, "ninjemys_reported", False):  # the handler's owner (rospy) logged it already
            _log.debug("service %s: error processing request: %s", self.name, exc)
        else:
            _log.error("service %s: error processing request: %s", self.name, exc)
        return encode_service_response(False, f"error processing request: {exc}")

    @property
    def closed(self) -> bool:
        return self._closed

    @closed.setter
    def closed(self, value: bool) -> None:
        """``Node.shutdown`` marks its servers closed: that also ends their client connections, so a
        shut-down node answers no further call on a persistent connection (as rospy)."""
        self._closed = value
        if value:
            self._end_connections()

    def shutdown(self, grace: float = 0.0) -> None:
        """Stop serving: unregister, and close every client connection. With ``grace``, calls already
        inside their handler get up to that many seconds to send their answer first (a provider that
        fails its pending calls on the way out wants its callers to read why, not a closed socket)."""
        if self._closed:
            return
        self._closed = True
        self.node.release_service(self)
        deadline = time.monotonic() + grace
        while self._busy and time.monotonic() < deadline:
            time.sleep(0.005)
        self._end_connections()

    def _end_connections(self) -> None:
        """Wake each connection thread out of its blocking read; it then closes its socket."""
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
        node: NodeContext,
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
        self._sock: socket.socket | None = None  # the open connection, if any (persistent, or mid-call)
        self._link: _Link | None = None
        self._empty_frame: bytes | None = None
        self._lock = threading.Lock()
        self._closed = False

    def call(self, *args: Any, **kwargs: Any) -> Any:
        """Call the service with a request instance, or with the request's fields (positional/keyword).

        The lock makes one proxy usable from several threads (one exchange at a time on its
        connection); an exchange is one ``sendall`` of the framed request and, usually, one
        ``recv_into`` of the whole response.
        """
        frame = self._frame(args, kwargs) if args or kwargs else self._empty_frame or self._frame((), {})
        with self._lock:
            link = self._link
            if link is None:
                if self._closed:
                    raise ShutdownError(f"service proxy for [{self.name}] is closed")
                link = self._link = self._connect()
                self._sock = link.sock
            try:
                ok, body = link.exchange(frame)
            except (OSError, ProtocolError) as exc:
                self._drop()
                raise ServiceError(
                    f"service [{self.name}]: transport error completing the call: {exc}"
                ) from None
            if not self.persistent:
                self._drop()
        if ok:
            try:
                return self.response_class.deserialize_from(body)
            except Exception as exc:
                raise ServiceError(f"service [{self.name}]: cannot decode the response: {exc}") from None
        raise ServiceError(
            f"service [{self.name}] responded with an error: {body.decode('utf-8', 'replace')}"
        )

    __call__ = call  # an alias, not a forwarding method: one Python frame less per call

    def _frame(self, args: tuple[Any, ...], kwargs: dict[str, Any]) -> bytes:
        """The framed request for call arguments. A call without arguments sends the default request,
        whose bytes never change, so they are built once (Trigger, Empty and the like cost nothing)."""
        if len(args) == 1 and not kwargs and isinstance(args[0], self.request_class):
            request = args[0]
        else:
            try:
                request = self.request_class(*args, **kwargs)
            except TypeError as exc:
                raise RequestArgumentError(f"service [{self.name}]: bad request arguments: {exc}") from None
        payload = request.serialize_to_bytes()
        frame = _U32.pack(len(payload)) + payload
        if not args and not kwargs:
            self._empty_frame = frame
        return frame

    def _lookup(self) -> tuple[str, int]:
        try:
            uri = self.node.master.lookup_service(self.name)
        except MasterError as exc:
            raise ServiceError(f"service [{self.name}] unavailable: {exc}") from None
        try:
            return split_uri(uri)
        except ValueError:
            raise ServiceError(f"service [{self.name}]: master gave a bad URI {uri!r}") from None

    def _connect(self, probe: bool = False, timeout: float | None = 10.0) -> _Link:
        """Look the service up, connect and exchange headers; the link then carries the calls."""
        host, port = self._lookup()
        sock = _local_connection(host, port, timeout)
        try:
            if sock is None:
                sock = socket.create_connection((host, port), timeout=timeout)
        except OSError as exc:
            raise ServiceError(
                f"unable to connect to service [{self.name}] at {host}:{port}: {exc}"
            ) from None
        try:
            if sock.family != socket.AF_UNIX:
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
            sock.sendall(headers.encode_header(auth.sign_fields(fields)))
            link = _Link(sock, 4096 if probe else 1 << 16)
            reply = link.header()
            refused = auth.check_fields(reply)
            if refused is not None:
                reply = {"error": f"authentication failed: {refused}"}
        except (OSError, NinjemysError) as exc:
            transport.close_quietly(sock)
            raise ServiceError(f"service [{self.name}]: handshake failed: {exc}") from None
        if "error" in reply:
            transport.close_quietly(sock)
            raise ServiceError(f"service [{self.name}]: {reply['error']}")
        sock.settimeout(None)
        return link

    def _drop(self) -> None:
        if self._sock is not None:
            transport.close_quietly(self._sock)
        self._sock = self._link = None

    def wait_for_service(self, timeout: float | None = None) -> None:
        """Block until the service is registered and answers a probe; TimeoutError_ after ``timeout``."""
        deadline = None if timeout is None else time.monotonic() + timeout
        delay = 0.01
        while True:
            if self.node.is_shutdown:
                raise ShutdownError("node shut down while waiting for service")
            try:
                transport.close_quietly(self._connect(probe=True, timeout=1.0).sock)
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


def _local_connection(host: str, port: int, timeout: float | None) -> socket.socket | None:
    """A Unix-socket connection to the ninjemys node behind a local ``rosrpc://host:port``
    (``transport.unix_address``), or None: another host, not Linux, or a server that has none
    (rospy, roscpp), which then gets TCP as before."""
    if not transport.local_transport_enabled() or not _is_local(host):
        return None
    sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    sock.settimeout(timeout)
    try:
        sock.connect(transport.unix_sockaddr(transport.unix_address(port)))
    except OSError:
        sock.close()
        return None
    return sock


_LOCAL_HOSTS: dict[str, bool] = {}


def _is_local(host: str) -> bool:
    """``is_local_address``, remembered: a service call may connect anew each time, and naming a
    host may cost a resolver round trip."""
    known = _LOCAL_HOSTS.get(host)
    if known is None:
        known = _LOCAL_HOSTS[host] = is_local_address(host)
    return known
