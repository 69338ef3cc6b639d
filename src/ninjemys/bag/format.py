"""Bag v2.0 records: constants, header encoding and the plain data the reader and writer share.

A bag is ``#ROSBAG V2.0\\n`` followed by records ``u32 header_len, header, u32 data_len, data``; the
header is a list of ``u32 len, name=value`` fields. Everything here is pure (bytes in, bytes out) so the
reader, writer, reindexer and exporter agree on one encoding.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass, field

from ninjemys.errors import BagError

MAGIC = b"#ROSBAG V2.0\n"
VERSION_PREFIX = b"#ROSBAG V"
#: the file header record is padded so the whole record occupies this many bytes
FILE_HEADER_LENGTH = 4096

OP_MSG_DEF = 0x01
OP_MSG_DATA = 0x02
OP_FILE_HEADER = 0x03
OP_INDEX_DATA = 0x04
OP_CHUNK = 0x05
OP_CHUNK_INFO = 0x06
OP_CONNECTION = 0x07

COMPRESSIONS = ("none", "bz2", "lz4")
DEFAULT_CHUNK_THRESHOLD = 768 * 1024

U32 = struct.Struct("<I")
U64 = struct.Struct("<Q")
TIME = struct.Struct("<II")
INDEX_ENTRY = struct.Struct("<III")
COUNT_ENTRY = struct.Struct("<II")

NSEC = 1_000_000_000


def ns_to_stamp(ns: int) -> tuple[int, int]:
    """Split integer nanoseconds into ROS (sec, nsec)."""
    return divmod(ns, NSEC)


def encode_header(fields: dict[str, bytes]) -> bytes:
    """Encode ``name=value`` fields, each prefixed with its u32 length."""
    parts: list[bytes] = []
    for name, value in fields.items():
        entry = name.encode() + b"=" + value
        parts.append(U32.pack(len(entry)))
        parts.append(entry)
    return b"".join(parts)


def decode_header(buf: bytes | memoryview, where: str = "") -> dict[str, bytes]:
    """Decode a record header; raises BagError naming ``where`` on malformed input."""
    fields: dict[str, bytes] = {}
    pos = 0
    end = len(buf)
    while pos < end:
        if pos + 4 > end:
            raise BagError(f"{where}: record header truncated inside a field length")
        (size,) = U32.unpack_from(buf, pos)
        pos += 4
        if pos + size > end:
            raise BagError(f"{where}: record header field of {size} bytes overruns the header ({end} bytes)")
        entry = bytes(buf[pos : pos + size])
        pos += size
        sep = entry.find(b"=")
        if sep < 1:
            raise BagError(f"{where}: record header field without a name=value separator")
        fields[entry[:sep].decode("latin-1")] = entry[sep + 1 :]
    return fields


def encode_record(fields: dict[str, bytes], data: bytes | memoryview) -> bytes:
    """One whole record: header length, header, data length, data."""
    header = encode_header(fields)
    return b"".join((U32.pack(len(header)), header, U32.pack(len(data)), data))


def field_u32(fields: dict[str, bytes], name: str, where: str) -> int:
    return U32.unpack(_field(fields, name, 4, where))[0]


def field_u64(fields: dict[str, bytes], name: str, where: str) -> int:
    return U64.unpack(_field(fields, name, 8, where))[0]


def field_time(fields: dict[str, bytes], name: str, where: str) -> int:
    sec, nsec = TIME.unpack(_field(fields, name, 8, where))
    return sec * NSEC + nsec


def field_op(fields: dict[str, bytes], where: str) -> int:
    return _field(fields, "op", 1, where)[0]


def _field(fields: dict[str, bytes], name: str, size: int, where: str) -> bytes:
    value = fields.get(name)
    if value is None:
        raise BagError(f"{where}: record header has no {name!r} field")
    if len(value) != size:
        raise BagError(f"{where}: field {name!r} has {len(value)} bytes, expected {size}")
    return value


@dataclass
class Connection:
    """One CONNECTION record: a topic as published by one publisher (type, md5, definition...)."""

    id: int
    topic: str
    header: dict[str, bytes]

    @property
    def datatype(self) -> str:
        return self.header.get("type", b"").decode()

    @property
    def md5sum(self) -> str:
        return self.header.get("md5sum", b"").decode()

    @property
    def msg_def(self) -> str:
        return self.header.get("message_definition", b"").decode()

    @property
    def callerid(self) -> str | None:
        value = self.header.get("callerid")
        return None if value is None else value.decode()

    @property
    def latching(self) -> bool:
        return self.header.get("latching", b"0") == b"1"

    def string_header(self) -> dict[str, str]:
        """The connection header as text (what rosbag's ``connection_header`` holds)."""
        return {k: v.decode("utf-8", "replace") for k, v in self.header.items()}

    def record(self) -> bytes:
        fields = {"op": bytes((OP_CONNECTION,)), "conn": U32.pack(self.id), "topic": self.topic.encode()}
        return encode_record(fields, encode_header(self.header))


@dataclass
class ChunkInfo:
    """One CHUNK_INFO record: where a chunk is, its time span and message count per connection."""

    pos: int
    start_time: int
    end_time: int
    counts: dict[int, int] = field(default_factory=dict)

    @property
    def message_count(self) -> int:
        return sum(self.counts.values())

    def record(self) -> bytes:
        fields = {
            "op": bytes((OP_CHUNK_INFO,)),
            "ver": U32.pack(1),
            "chunk_pos": U64.pack(self.pos),
            "start_time": TIME.pack(*ns_to_stamp(self.start_time)),
            "end_time": TIME.pack(*ns_to_stamp(self.end_time)),
            "count": U32.pack(len(self.counts)),
        }
        data = b"".join(COUNT_ENTRY.pack(conn, n) for conn, n in self.counts.items())
        return encode_record(fields, data)


@dataclass
class ChunkHeader:
    """The CHUNK record header: compression and sizes (what ``rosbag info`` sums)."""

    compression: str
    compressed_size: int
    uncompressed_size: int
    data_pos: int


def file_header_record(index_pos: int, conn_count: int, chunk_count: int) -> bytes:
    """The FILE_HEADER record padded with spaces to exactly FILE_HEADER_LENGTH bytes."""
    header = encode_header(
        {
            "op": bytes((OP_FILE_HEADER,)),
            "index_pos": U64.pack(index_pos),
            "conn_count": U32.pack(conn_count),
            "chunk_count": U32.pack(chunk_count),
        }
    )
    pad = FILE_HEADER_LENGTH - 8 - len(header)
    return b"".join((U32.pack(len(header)), header, U32.pack(pad), b" " * pad))


def message_record_header(conn: int, ns: int) -> bytes:
    """The header of a MSG_DATA record (without the u32 data length)."""
    sec, nsec = divmod(ns, NSEC)
    header = b"".join(
        (
            b"\x04\x00\x00\x00op=\x02",
            b"\x09\x00\x00\x00conn=",
            U32.pack(conn),
            b"\x0d\x00\x00\x00time=",
            TIME.pack(sec, nsec),
        )
    )
    return U32.pack(len(header)) + header


def index_data_record(conn: int, entries: list[tuple[int, int]]) -> bytes:
    """An INDEX_DATA record for one connection in one chunk: (time ns, offset in chunk) pairs."""
    fields = {
        "op": bytes((OP_INDEX_DATA,)),
        "ver": U32.pack(1),
        "conn": U32.pack(conn),
        "count": U32.pack(len(entries)),
    }
    data = b"".join(INDEX_ENTRY.pack(ns // NSEC, ns % NSEC, off) for ns, off in entries)
    return encode_record(fields, data)
