"""Sans-IO XML-RPC over HTTP/1.1: bytes in, bytes out, no sockets.

This is the one place that knows how ROS 1's XML-RPC looks on the wire, shared by the master, the
node's slave API and every client:

* :class:`HttpRequestParser` / :class:`HttpResponseParser` turn a byte stream into complete HTTP
  messages with hard bounds (header size, body size), so a hostile peer can never make us buffer
  without limit; they raise :class:`~ninjemys.errors.ProtocolError` on anything malformed.
* :func:`parse_call` / :func:`dump_response` / :func:`dump_fault` / :func:`dump_call` /
  :func:`parse_response` marshal XML-RPC bodies (expat via the stdlib's ``xmlrpc.client``, which is
  as fast as pure Python gets here).
* :func:`ok`, :func:`error`, :func:`failure` build ROS 1's ``[code, statusMessage, value]`` triples.

Integers beyond 32 bits: XML-RPC's ``<int>`` is 32-bit, and the stdlib refuses to send anything
larger (``OverflowError``). We *receive* ``<i8>`` (as rospy does) and *send* integers that do not fit
in 32 bits as ``<i8>`` (the Apache extension every Python ROS 1 peer - rospy, rosmaster, the ROS 1
tools - parses). Integers outside the signed 64-bit range are refused with a
:class:`~ninjemys.errors.ProtocolError` naming the value, never a crash. roscpp's XmlRpc++ does not
parse ``<i8>``: a C++ node reading such a parameter sees an XML-RPC error for that call only.
``None`` is never sent (``<nil>`` is not understood by ROS 1 peers): it raises ``ProtocolError``.
"""

from __future__ import annotations

import xmlrpc.client
from dataclasses import dataclass, field
from typing import Any

from ninjemys.errors import ProtocolError

#: ROS 1 status codes.
ERROR = -1
FAILURE = 0
SUCCESS = 1

MAX_HEADER_BYTES = 64 * 1024
#: Large enough for any URDF / robot_description people put on the parameter server.
MAX_BODY_BYTES = 64 * 1024 * 1024

_INT32_MIN = -(2**31)
_INT32_MAX = 2**31 - 1
_INT64_MIN = -(2**63)
_INT64_MAX = 2**63 - 1


def ok(message: str, value: Any) -> list[Any]:
    """``[1, message, value]``: the call succeeded."""
    return [SUCCESS, message, value]


def error(message: str, value: Any = 0) -> list[Any]:
    """``[-1, message, value]``: the caller got something wrong; nothing was attempted."""
    return [ERROR, message, value]


def failure(message: str, value: Any = 0) -> list[Any]:
    """``[0, message, value]``: the call was attempted and failed."""
    return [FAILURE, message, value]


class _Marshaller(xmlrpc.client.Marshaller):
    """The stdlib marshaller, but ints beyond 32 bits go out as ``<i8>`` and ``None`` is refused."""

    dispatch = dict(xmlrpc.client.Marshaller.dispatch)

    def dump_long(self, value: int, write: Any) -> None:  # noqa: D102 - stdlib hook
        if _INT32_MIN <= value <= _INT32_MAX:
            write("<value><int>")
            write(str(int(value)))
            write("</int></value>\n")
        elif _INT64_MIN <= value <= _INT64_MAX:
            write("<value><i8>")
            write(str(int(value)))
            write("</i8></value>\n")
        else:
            raise ProtocolError(f"XML-RPC: integer {value} does not fit in 64 bits")

    dispatch[int] = dump_long

    def dump_nil(self, value: None, write: Any) -> None:  # noqa: D102 - stdlib hook
        raise ProtocolError("XML-RPC: None cannot be sent to ROS 1 peers (no <nil>)")

    dispatch[type(None)] = dump_nil


def _dump_params(params: tuple[Any, ...] | list[Any]) -> str:
    try:
        return _Marshaller("utf-8", allow_none=False).dumps(params)
    except ProtocolError:
        raise
    except (TypeError, OverflowError, ValueError, RecursionError) as exc:
        raise ProtocolError(f"XML-RPC: cannot marshal value: {exc}") from None


def dump_call(method: str, params: tuple[Any, ...] | list[Any]) -> bytes:
    """The XML body of a ``methodCall``."""
    body = _dump_params(tuple(params))
    return (
        "<?xml version='1.0'?>\n<methodCall>\n<methodName>"
        + _escape(method)
        + "</methodName>\n"
        + body
        + "</methodCall>\n"
    ).encode("utf-8")


def dump_response(value: Any) -> bytes:
    """The XML body of a successful ``methodResponse`` carrying ``value``."""
    body = _dump_params((value,))
    return ("<?xml version='1.0'?>\n<methodResponse>\n" + body + "</methodResponse>\n").encode("utf-8")


def dump_fault(code: int, message: str) -> bytes:
    """The XML body of a fault response (unknown method, unparsable call, internal error)."""
    return xmlrpc.client.dumps(xmlrpc.client.Fault(code, message), methodresponse=True).encode("utf-8")


def parse_call(body: bytes) -> tuple[str, tuple[Any, ...]]:
    """``(method, params)`` of a ``methodCall`` body; ``ProtocolError`` if it is not one."""
    try:
        params, method = xmlrpc.client.loads(body, use_builtin_types=True)
    except xmlrpc.client.Fault as exc:
        raise ProtocolError(f"XML-RPC: a fault is not a call ({exc.faultString})") from None
    except Exception as exc:  # expat errors, bad ints/doubles, bad base64, deep nesting ...
        raise ProtocolError(f"XML-RPC: malformed call: {type(exc).__name__}: {exc}") from None
    if not method:
        raise ProtocolError("XML-RPC: call has no methodName")
    return method, params


def parse_response(body: bytes) -> Any:
    """The value of a ``methodResponse``; raises ``xmlrpc.client.Fault`` or ``ProtocolError``."""
    try:
        params, _ = xmlrpc.client.loads(body, use_builtin_types=True)
    except xmlrpc.client.Fault:
        raise
    except Exception as exc:
        raise ProtocolError(f"XML-RPC: malformed response: {type(exc).__name__}: {exc}") from None
    if len(params) != 1:
        raise ProtocolError(f"XML-RPC: response carries {len(params)} values, expected 1")
    return params[0]


def _escape(text: str) -> str:
    return text.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")


# --------------------------------------------------------------------------------------------- HTTP


@dataclass
class HttpMessage:
    """One complete HTTP request or response (start line split, lower-cased header names)."""

    start: tuple[str, str, str]
    headers: dict[str, str] = field(default_factory=dict)
    body: bytes = b""

    @property
    def keep_alive(self) -> bool:
        conn = self.headers.get("connection", "").lower()
        version = self.start[0] if self.start[0].startswith("HTTP/") else self.start[2]
        if version == "HTTP/1.0":
            return "keep-alive" in conn
        return "close" not in conn


class _HttpParser:
    """Incremental HTTP/1.x message parser with bounded buffers (Content-Length bodies only)."""

    def __init__(self, max_header: int = MAX_HEADER_BYTES, max_body: int = MAX_BODY_BYTES) -> None:
        self._buf = bytearray()
        self._max_header = max_header
        self._max_body = max_body
        self._head: tuple[tuple[str, str, str], dict[str, str]] | None = None
        self._need = 0

    @property
    def pending(self) -> bool:
        """True while part of a message has been received."""
        return bool(self._buf) or self._head is not None

    def feed(self, data: bytes) -> list[HttpMessage]:
        """Add received bytes; return every message they complete (usually zero or one)."""
        self._buf += data
        out: list[HttpMessage] = []
        while True:
            if self._head is None:
                end = self._buf.find(b"\r\n\r\n")
                if end < 0:
                    if len(self._buf) > self._max_header:
                        raise ProtocolError(f"HTTP: header larger than {self._max_header} bytes")
                    return out
                if end > self._max_header:
                    raise ProtocolError(f"HTTP: header larger than {self._max_header} bytes")
                head = bytes(self._buf[:end])
                del self._buf[: end + 4]
                self._head = self._parse_head(head)
                self._need = self._content_length(self._head[1])
            if len(self._buf) < self._need:
                return out
            body = bytes(self._buf[: self._need])
            del self._buf[: self._need]
            start, headers = self._head
            self._head = None
            out.append(HttpMessage(start, headers, body))

    def _parse_head(self, head: bytes) -> tuple[tuple[str, str, str], dict[str, str]]:
        try:
            text = head.decode("latin-1")
        except UnicodeDecodeError:  # latin-1 decodes everything; kept for clarity
            raise ProtocolError("HTTP: undecodable header") from None
        lines = text.split("\r\n")
        parts = lines[0].split(" ", 2)
        if len(parts) != 3:
            raise ProtocolError(f"HTTP: malformed start line {lines[0][:80]!r}")
        start = (parts[0], parts[1], parts[2])
        self._check_start(start)
        headers: dict[str, str] = {}
        for line in lines[1:]:
            name, sep, value = line.partition(":")
            if not sep or not name or name != name.strip():
                raise ProtocolError(f"HTTP: malformed header line {line[:80]!r}")
            headers[name.lower()] = value.strip()
        if "chunked" in headers.get("transfer-encoding", "").lower():
            raise ProtocolError("HTTP: chunked bodies are not supported by XML-RPC peers")
        return start, headers

    def _check_start(self, start: tuple[str, str, str]) -> None:
        """Subclasses reject start lines that are not a request / a status line."""

    def _content_length(self, headers: dict[str, str]) -> int:
        raw = headers.get("content-length")
        if raw is None:
            return 0
        if not raw.isdigit():
            raise ProtocolError(f"HTTP: bad Content-Length {raw[:40]!r}")
        length = int(raw)
        if length > self._max_body:
            raise ProtocolError(f"HTTP: body of {length} bytes exceeds the {self._max_body} byte limit")
        return length


class HttpRequestParser(_HttpParser):
    """Parses requests (``POST /RPC2 HTTP/1.1``) as a server receives them."""

    def _check_start(self, start: tuple[str, str, str]) -> None:
        method, _, version = start
        if version not in ("HTTP/1.1", "HTTP/1.0"):
            raise ProtocolError(f"HTTP: unsupported version {version[:20]!r}")
        if not method.isalpha() or not method.isupper():
            raise ProtocolError(f"HTTP: bad method {method[:20]!r}")


class HttpResponseParser(_HttpParser):
    """Parses responses (``HTTP/1.1 200 OK``) as a client receives them."""

    def _check_start(self, start: tuple[str, str, str]) -> None:
        if not start[0].startswith("HTTP/1.") or not start[1].isdigit():
            raise ProtocolError(f"HTTP: malformed status line {' '.join(start)[:80]!r}")

    def _content_length(self, headers: dict[str, str]) -> int:
        if "content-length" not in headers:
            raise ProtocolError("HTTP: response without Content-Length")
        return super()._content_length(headers)


_REASONS = {
    200: "OK",
    400: "Bad Request",
    404: "Not Found",
    405: "Method Not Allowed",
    413: "Payload Too Large",
}


def http_response(body: bytes, status: int = 200, keep_alive: bool = True) -> bytes:
    """A complete HTTP/1.1 response carrying an XML-RPC body."""
    head = (
        f"HTTP/1.1 {status} {_REASONS.get(status, 'Error')}\r\n"
        "Server: ninjemys\r\n"
        "Content-Type: text/xml\r\n"
        f"Content-Length: {len(body)}\r\n"
        f"Connection: {'keep-alive' if keep_alive else 'close'}\r\n\r\n"
    )
    return head.encode("latin-1") + body


def http_request(host: str, port: int, body: bytes, path: str = "/RPC2", keep_alive: bool = True) -> bytes:
    """A complete HTTP/1.1 POST carrying an XML-RPC call."""
    head = (
        f"POST {path} HTTP/1.1\r\n"
        f"Host: {host}:{port}\r\n"
        "User-Agent: ninjemys\r\n"
        "Content-Type: text/xml\r\n"
        f"Content-Length: {len(body)}\r\n"
        f"Connection: {'keep-alive' if keep_alive else 'close'}\r\n\r\n"
    )
    return head.encode("latin-1") + body
