"""Sans-IO XML-RPC over HTTP/1.1: bytes in, bytes out, no sockets.

This is the one place that knows how ROS 1's XML-RPC looks on the wire, shared by the master, the
node's slave API and every client:

* :class:`HttpRequestParser` / :class:`HttpResponseParser` turn a byte stream into complete HTTP
  messages with hard bounds (header size, body size), so a hostile peer can never make us buffer
  without limit; they raise :class:`~ninjemys.errors.ProtocolError` on anything malformed.
* :func:`parse_call` / :func:`dump_response` / :func:`dump_fault` / :func:`dump_call` /
  :func:`parse_response` marshal XML-RPC bodies. Our own marshaller (expat callbacks onto a value
  stack; string building by type dispatch) instead of ``xmlrpc.client``: it is faster, parses any
  nesting depth without recursion, and keeps ``http.client``/``email`` out of every process's
  start-up. A fault response raises :class:`Fault`. ``xmlrpc.client.Binary``/``DateTime`` values are
  accepted when sending; base64 arrives as ``bytes``, ``dateTime.iso8601`` as ``datetime``.
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

import binascii
from xml.parsers import expat

from ninjemys.errors import ProtocolError
from ninjemys.records import SlotRecord

TYPE_CHECKING = False  # importing typing costs ~7 ms of every tool's and node's start-up
if TYPE_CHECKING:
    from typing import Any

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


class Fault(ProtocolError):
    """An XML-RPC fault response (``faultCode``, ``faultString``), as ``xmlrpc.client.Fault`` carries."""

    def __init__(self, faultCode: int, faultString: str) -> None:  # noqa: N803 - XML-RPC's names
        self.faultCode = faultCode
        self.faultString = faultString
        super().__init__(f"XML-RPC fault {faultCode}: {faultString}")


def _escape(text: str) -> str:
    if "&" in text:
        text = text.replace("&", "&amp;")
    if "<" in text:
        text = text.replace("<", "&lt;")
    if ">" in text:
        text = text.replace(">", "&gt;")
    return text


def _dump(value: Any, out: list[str]) -> None:
    """Append the ``<value>`` XML of ``value`` to ``out`` (exact types first: the hot path)."""
    kind = type(value)
    if kind is str:
        out.append("<value><string>" + _escape(value) + "</string></value>\n")
    elif kind is int:
        _dump_int(value, out)
    elif kind is list or kind is tuple:
        out.append("<value><array><data>\n")
        for item in value:
            _dump(item, out)
        out.append("</data></array></value>\n")
    elif kind is bool:
        out.append(
            "<value><boolean>1</boolean></value>\n" if value else "<value><boolean>0</boolean></value>\n"
        )
    elif kind is float:
        out.append("<value><double>" + repr(value) + "</double></value>\n")
    elif kind is dict:
        out.append("<value><struct>\n")
        for key, item in value.items():
            if type(key) is not str:
                raise ProtocolError(f"XML-RPC: struct keys must be strings, got {type(key).__name__} {key!r}")
            out.append("<member>\n<name>" + _escape(key) + "</name>\n")
            _dump(item, out)
            out.append("</member>\n")
        out.append("</struct></value>\n")
    elif kind is bytes or kind is bytearray or kind is memoryview:
        out.append(
            "<value><base64>\n" + binascii.b2a_base64(bytes(value)).decode("ascii") + "</base64></value>\n"
        )
    elif value is None:
        raise ProtocolError("XML-RPC: None cannot be sent to ROS 1 peers (no <nil>)")
    else:
        _dump_other(value, out)


def _dump_int(value: int, out: list[str]) -> None:
    if _INT32_MIN <= value <= _INT32_MAX:
        out.append(f"<value><int>{value}</int></value>\n")
    elif _INT64_MIN <= value <= _INT64_MAX:
        out.append(f"<value><i8>{value}</i8></value>\n")
    else:
        raise ProtocolError(f"XML-RPC: integer {value} does not fit in 64 bits")


class Marshalled:
    """A value rendered to XML-RPC once, sent many times (the master caches getSystemState this way)."""

    __slots__ = ("value", "xml")

    def __init__(self, value: Any) -> None:
        out: list[str] = []
        _dump(value, out)
        self.value = value
        self.xml = "".join(out)


def _dump_other(value: Any, out: list[str]) -> None:
    """Subclasses and foreign types: xmlrpc.client.Binary / DateTime, datetime, numpy scalars."""
    if type(value) is Marshalled:
        out.append(value.xml)
    elif isinstance(value, bool):
        _dump(bool(value), out)
    elif isinstance(value, int):
        _dump_int(int(value), out)
    elif isinstance(value, float):
        _dump(float(value), out)
    elif isinstance(value, str):
        _dump(str(value), out)
    elif isinstance(value, dict):
        _dump(dict(value), out)
    elif isinstance(value, list | tuple):
        _dump(list(value), out)
    elif type(value).__name__ == "Binary" and isinstance(getattr(value, "data", None), bytes):
        _dump(value.data, out)
    elif hasattr(value, "timetuple") and hasattr(value, "strftime"):
        out.append(
            "<value><dateTime.iso8601>" + value.strftime("%Y%m%dT%H:%M:%S") + "</dateTime.iso8601></value>\n"
        )
    elif type(value).__name__ == "DateTime" and isinstance(getattr(value, "value", None), str):
        out.append("<value><dateTime.iso8601>" + value.value + "</dateTime.iso8601></value>\n")
    elif hasattr(value, "__index__"):
        _dump_int(value.__index__(), out)
    elif hasattr(value, "__float__") and hasattr(value, "dtype"):
        _dump(float(value), out)
    else:
        raise ProtocolError(f"XML-RPC: cannot marshal a {type(value).__name__} ({value!r:.60})")


def _dump_params(params: tuple[Any, ...] | list[Any]) -> str:
    out = ["<params>\n"]
    try:
        for param in params:
            out.append("<param>\n")
            _dump(param, out)
            out.append("</param>\n")
    except RecursionError:
        raise ProtocolError("XML-RPC: value nested too deeply to marshal") from None
    out.append("</params>\n")
    return "".join(out)


def dump_call(method: str, params: tuple[Any, ...] | list[Any]) -> bytes:
    """The XML body of a ``methodCall``."""
    body = _dump_params(params)
    return (
        "<?xml version='1.0'?>\n<methodCall>\n<methodName>"
        + _escape(method)
        + "</methodName>\n"
        + body
        + "</methodCall>\n"
    ).encode("utf-8")


def dump_response(value: Any) -> bytes:
    """The XML body of a successful ``methodResponse`` carrying ``value``."""
    return (
        "<?xml version='1.0'?>\n<methodResponse>\n" + _dump_params((value,)) + "</methodResponse>\n"
    ).encode("utf-8")


def dump_fault(code: int, message: str) -> bytes:
    """The XML body of a fault response (unknown method, unparsable call, internal error)."""
    out = ["<?xml version='1.0'?>\n<methodResponse>\n<fault>\n"]
    _dump({"faultCode": int(code), "faultString": str(message)}, out)
    out.append("</fault>\n</methodResponse>\n")
    return "".join(out).encode("utf-8")


class _Unmarshaller:
    """expat callbacks building Python values on a stack (iterative: nesting depth costs no recursion)."""

    def __init__(self) -> None:
        self.stack: list[Any] = []
        self.marks: list[int] = []
        self.data: list[str] = []
        self.method: str | None = None
        self.fault = False
        self.untyped = False  # inside <value> with no type element yet: a bare string

    def start(self, tag: str, attrs: Any) -> None:
        tag = tag.rpartition(":")[2]
        if tag == "array" or tag == "struct":
            self.marks.append(len(self.stack))
        elif tag == "value":
            self.untyped = True
        elif tag == "fault":
            self.fault = True
        elif tag not in _KNOWN_TAGS:
            raise ProtocolError(f"XML-RPC: unknown element <{tag}>")
        if tag != "value":
            self.untyped = False
        self.data = []

    def chars(self, text: str) -> None:
        self.data.append(text)

    def end(self, tag: str) -> None:
        tag = tag.rpartition(":")[2]
        text = "".join(self.data)
        self.data = []
        convert = _SCALARS.get(tag)
        if convert is not None:
            try:
                self.stack.append(convert(text))
            except (ValueError, binascii.Error) as exc:
                raise ProtocolError(f"XML-RPC: bad <{tag}> value {text[:40]!r}: {exc}") from None
            self.untyped = False
        elif tag == "value":
            if self.untyped:
                self.stack.append(text)
            self.untyped = False
        elif tag == "array":
            mark = self.marks.pop()
            self.stack[mark:] = [self.stack[mark:]]
        elif tag == "struct":
            mark = self.marks.pop()
            items = self.stack[mark:]
            if len(items) % 2:
                raise ProtocolError("XML-RPC: struct member without a value")
            self.stack[mark:] = [dict(zip(items[::2], items[1::2], strict=True))]
        elif tag == "name":
            self.stack.append(text)
        elif tag == "methodName":
            self.method = text


def _boolean(text: str) -> bool:
    if text.strip() not in ("0", "1"):
        raise ValueError("expected 0 or 1")
    return text.strip() == "1"


def _datetime(text: str) -> Any:
    from datetime import datetime

    return datetime.strptime(text.strip(), "%Y%m%dT%H:%M:%S")


_SCALARS: dict[str, Any] = {
    "int": int,
    "i4": int,
    "i8": int,
    "i1": int,
    "i2": int,
    "biginteger": int,
    "string": str,
    "double": float,
    "float": float,
    "boolean": _boolean,
    "base64": lambda text: binascii.a2b_base64(text.encode("ascii")),
    "dateTime.iso8601": _datetime,
    "nil": lambda text: None,
}
_KNOWN_TAGS = frozenset(
    {"methodCall", "methodName", "methodResponse", "params", "param", "data", "member", "name", "fault"}
    | set(_SCALARS)
)


def _unmarshal(body: bytes) -> _Unmarshaller:
    handler = _Unmarshaller()
    parser = expat.ParserCreate("utf-8")
    parser.StartElementHandler = handler.start
    parser.EndElementHandler = handler.end
    parser.CharacterDataHandler = handler.chars
    parser.buffer_text = True
    try:
        parser.Parse(body, True)
    except expat.ExpatError as exc:
        raise ProtocolError(f"XML-RPC: malformed XML: {exc}") from None
    except ProtocolError:
        raise
    except (IndexError, TypeError, ValueError) as exc:  # structure that is not XML-RPC
        raise ProtocolError(f"XML-RPC: malformed message: {exc}") from None
    if handler.marks:
        raise ProtocolError("XML-RPC: unterminated array or struct")
    return handler


def parse_call(body: bytes) -> tuple[str, tuple[Any, ...]]:
    """``(method, params)`` of a ``methodCall`` body; ``ProtocolError`` if it is not one."""
    handler = _unmarshal(body)
    if handler.fault:
        raise ProtocolError("XML-RPC: a fault is not a call")
    if not handler.method:
        raise ProtocolError("XML-RPC: call has no methodName")
    return handler.method, tuple(handler.stack)


def parse_response(body: bytes) -> Any:
    """The value of a ``methodResponse``; raises :class:`Fault` or ``ProtocolError``."""
    handler = _unmarshal(body)
    if handler.method is not None:
        raise ProtocolError("XML-RPC: expected a response, got a call")
    if handler.fault:
        fault = handler.stack[0] if len(handler.stack) == 1 else None
        if not isinstance(fault, dict):
            raise ProtocolError("XML-RPC: malformed fault")
        raise Fault(fault.get("faultCode", 0), str(fault.get("faultString", "")))
    if len(handler.stack) != 1:
        raise ProtocolError(f"XML-RPC: response carries {len(handler.stack)} values, expected 1")
    return handler.stack[0]


# --------------------------------------------------------------------------------------------- HTTP


class HttpMessage(SlotRecord):
    """One complete HTTP request or response (start line split, lower-cased header names)."""

    __slots__ = ("start", "headers", "body")

    def __init__(
        self, start: tuple[str, str, str], headers: dict[str, str] | None = None, body: bytes = b""
    ) -> None:
        self.start = start
        self.headers = {} if headers is None else headers
        self.body = body

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
        # ASCII digits only: str.isdigit() also accepts '²' and other digits int() refuses
        if not (raw.isascii() and raw.isdigit()):
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


def http_request(
    host: str, port: int, body: bytes, path: str = "/RPC2", keep_alive: bool = True, extra_headers: str = ""
) -> bytes:
    """A complete HTTP/1.1 POST carrying an XML-RPC call (``extra_headers``: whole ``Name: value\\r\\n`` lines)."""
    head = (
        f"POST {path} HTTP/1.1\r\n"
        f"Host: {host}:{port}\r\n"
        "User-Agent: ninjemys\r\n"
        "Content-Type: text/xml\r\n"
        f"Content-Length: {len(body)}\r\n"
        f"{extra_headers}"
        f"Connection: {'keep-alive' if keep_alive else 'close'}\r\n\r\n"
    )
    return head.encode("latin-1") + body
