"""TCPROS connection headers: encode, decode and check them (sans-IO, bytes in, bytes out).

A header is ``uint32 total_len`` followed by repeated ``uint32 field_len`` + ``b"name=value"``, all
little-endian (https://wiki.ros.org/ROS/Connection%20Header). Values may be arbitrary bytes in
principle; every field real ROS 1 nodes send is text, so decoded values are ``str`` (UTF-8, with
``surrogateescape`` so odd bytes survive a round trip instead of crashing the reader).

The checks here mirror what rospy and roscpp answer when a peer asks for the wrong thing, so a real
ROS 1 peer gets the same ``error=`` text it would get from its own kind.
"""

from __future__ import annotations

import struct
from collections.abc import Mapping

from ninjemys.errors import ProtocolError

#: Largest connection header we accept. Real headers are a few KB (message_definition dominates);
#: the cap keeps a bogus length prefix from making us allocate gigabytes.
MAX_HEADER_LEN = 4 * 1024 * 1024

_U32 = struct.Struct("<I")


def encode_header(fields: Mapping[str, str | bytes]) -> bytes:
    """Serialize ``fields`` as a connection header, including the leading total length."""
    parts: list[bytes] = []
    for name, value in fields.items():
        if "=" in name:
            raise ProtocolError(f"connection header field name {name!r} must not contain '='")
        raw = value if isinstance(value, bytes) else str(value).encode("utf-8", "surrogateescape")
        item = name.encode("utf-8") + b"=" + raw
        parts.append(_U32.pack(len(item)))
        parts.append(item)
    body = b"".join(parts)
    return _U32.pack(len(body)) + body


def header_length(prefix: bytes | bytearray | memoryview) -> int:
    """The body length announced by the 4-byte prefix, checked against :data:`MAX_HEADER_LEN`."""
    if len(prefix) != 4:
        raise ProtocolError(f"connection header prefix must be 4 bytes, got {len(prefix)}")
    (length,) = _U32.unpack(prefix)
    if length > MAX_HEADER_LEN:
        raise ProtocolError(f"connection header length {length} exceeds the {MAX_HEADER_LEN}-byte limit")
    return length


def decode_header(body: bytes | bytearray | memoryview) -> dict[str, str]:
    """Parse a header body (without the total length prefix) into ``{name: value}``.

    Raises ProtocolError naming the byte offset when a field length runs past the end or a field has
    no ``=``: a garbage header must be reported, never guessed at.
    """
    data = bytes(body)
    fields: dict[str, str] = {}
    pos, end = 0, len(data)
    while pos < end:
        if end - pos < 4:
            raise ProtocolError(f"connection header truncated at byte {pos}: {end - pos} stray bytes")
        (n,) = _U32.unpack_from(data, pos)
        pos += 4
        if n > end - pos:
            raise ProtocolError(
                f"connection header field at byte {pos - 4} claims {n} bytes, {end - pos} left"
            )
        item = data[pos : pos + n]
        pos += n
        eq = item.find(b"=")
        if eq <= 0:
            shown = item[:40].decode("ascii", "backslashreplace")
            raise ProtocolError(f"connection header field at byte {pos - n - 4} has no name=value: {shown!r}")
        fields[item[:eq].decode("utf-8", "surrogateescape")] = item[eq + 1 :].decode(
            "utf-8", "surrogateescape"
        )
    return fields


def md5_matches(ours: str, theirs: str) -> bool:
    """True when two md5sums are compatible: equal, or either side is the wildcard ``*``."""
    return ours == theirs or ours == "*" or theirs == "*"


def check_subscriber_header(header: Mapping[str, str], topic: str, type_name: str, md5sum: str) -> str | None:
    """What a publisher answers a subscriber's header with: None if acceptable, else the error text."""
    for required in ("topic", "md5sum", "callerid"):
        if required not in header:
            return f"Missing required element {required} in connection header"
    if header["topic"] != topic:
        return f"request for topic [{header['topic']}] sent to a connection for [{topic}]"
    if not md5_matches(md5sum, header["md5sum"]):
        their_type = header.get("type", "")
        if their_type and their_type != "*" and their_type != type_name:
            return f"topic types do not match: [{their_type}] vs. [{type_name}]"
        return (
            f"Client [{header['callerid']}] wants topic [{topic}] to have datatype/md5sum "
            f"[{their_type}/{header['md5sum']}], but our version has [{type_name}/{md5sum}]. Dropping connection."
        )
    return None


def check_publisher_header(header: Mapping[str, str], type_name: str, md5sum: str) -> str | None:
    """What a subscriber makes of a publisher's reply: None if usable, else why not."""
    if "error" in header:
        return f"publisher refused the connection: {header['error']}"
    if "md5sum" not in header:
        return "publisher header has no md5sum"
    if not md5_matches(md5sum, header["md5sum"]):
        return (
            f"publisher sends [{header.get('type', '?')}/{header['md5sum']}], "
            f"we expect [{type_name}/{md5sum}]"
        )
    return None


def check_service_client_header(header: Mapping[str, str], service: str, md5sum: str) -> str | None:
    """What a service server answers a client's header with: None if acceptable, else the error text."""
    for required in ("service", "md5sum", "callerid"):
        if required not in header:
            return f"Missing required element {required} in connection header"
    if header["service"] != service:
        return f"request for service [{header['service']}] sent to a connection for [{service}]"
    if not md5_matches(md5sum, header["md5sum"]):
        return (
            f"request from [{header['callerid']}]: md5sums do not match: [{header['md5sum']}] vs. [{md5sum}]"
        )
    return None
