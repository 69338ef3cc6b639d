"""Rebuild the index of a bag whose recording did not finish (``rosbag reindex``), in place.

Every chunk that reached the file whole is kept where it is; a chunk cut short by the crash is
replaced by a new chunk holding the messages of it that were intact; missing INDEX_DATA records of the
last chunk are rewritten; then the connection and chunk-info records go at the end and the file header
is updated. The result is a normal, spec-conforming bag (ROS 1 readers and rosbags open it).
"""

from __future__ import annotations

import os
from collections.abc import Iterator
from pathlib import Path

from ninjemys.bag.compression import compress
from ninjemys.bag.format import (
    FILE_HEADER_LENGTH,
    MAGIC,
    OP_CHUNK,
    U32,
    ChunkInfo,
    encode_record,
    file_header_record,
    index_data_record,
    message_record_header,
)
from ninjemys.bag.reader import BagReader
from ninjemys.errors import BagError


def reindex_in_place(path: str | os.PathLike[str]) -> Iterator[int]:
    """Reindex ``path``; yields byte offsets as it goes (for progress bars). Raises BagError if hopeless."""
    path = Path(path)
    with BagReader(path, scan=True) as reader:
        infos = list(reader.chunk_infos)
        connections = dict(reader.connections)
        kept: list[ChunkInfo] = []
        write_pos = len(MAGIC) + FILE_HEADER_LENGTH
        tail: bytes = b""
        partial_kind = "none"
        for i, info in enumerate(infos):
            yield info.pos
            last = i == len(infos) - 1
            if reader.is_partial(info):
                partial_kind = reader.chunk_headers[info.pos].compression
                tail = _rebuild_chunk(reader, info, partial_kind)
                write_pos = info.pos
                kept.append(info)
                break
            chunk_end, index_end = reader.chunk_extent(info)
            if index_end is None:
                if not last:
                    reader.warnings.append(f"{path}: chunk at {info.pos} lost its index records; left out")
                    continue
                tail = _index_records(reader.chunk_entries(info))
                write_pos = chunk_end
            else:
                write_pos = index_end
            kept.append(info)
    if not kept and not connections:
        raise BagError(f"{path}: nothing recoverable (no intact chunk found)")
    with open(path, "r+b") as f:
        f.seek(write_pos)
        f.write(tail)
        index_pos = f.tell()
        f.write(b"".join(c.record() for c in connections.values()))
        f.write(b"".join(c.record() for c in kept))
        f.truncate()
        f.seek(len(MAGIC))
        f.write(file_header_record(index_pos, len(connections), len(kept)))
    yield index_pos


def _index_records(entries: list[tuple[int, int, int]]) -> bytes:
    per_conn: dict[int, list[tuple[int, int]]] = {}
    for ns, conn, off in entries:
        per_conn.setdefault(conn, []).append((ns, off))
    return b"".join(index_data_record(conn, sorted(items)) for conn, items in per_conn.items())


def _rebuild_chunk(reader: BagReader, info: ChunkInfo, kind: str) -> bytes:
    """A whole new chunk (same compression) with the intact messages of a truncated one."""
    body = bytearray()
    for conn in info.counts:
        body += reader.connections[conn].record()
    entries: list[tuple[int, int, int]] = []
    for msg in reader.chunk_records(info):
        entries.append((msg.time, msg.connection.id, len(body)))
        body += message_record_header(msg.connection.id, msg.time)
        body += U32.pack(len(msg.data))
        body += msg.data
    raw = bytes(body)
    fields = {"op": bytes((OP_CHUNK,)), "compression": kind.encode(), "size": U32.pack(len(raw))}
    return encode_record(fields, compress(kind, raw)) + _index_records(entries)
