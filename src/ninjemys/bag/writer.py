"""Bag v2.0 writer: chunks (none/bz2/lz4), per-chunk index records, and a final index.

Crash safety: a chunk is closed and written (with its INDEX_DATA records) whenever it reaches the size
threshold *or* has been open for ``flush_interval`` seconds, and the file is flushed to the OS then. A
process killed mid-recording therefore leaves every chunk up to the last flush intact, and
:func:`ninjemys.bag.reindex.reindex` (or the reader's scan mode) recovers them. With ``active=True`` the
bag is written as ``NAME.bag.active`` and renamed to ``NAME.bag`` only once its index is complete.
"""

from __future__ import annotations

import os
import time
from pathlib import Path
from typing import BinaryIO

from ninjemys.bag.compression import compress
from ninjemys.bag.format import (
    COMPRESSIONS,
    DEFAULT_CHUNK_THRESHOLD,
    MAGIC,
    OP_CHUNK,
    U32,
    ChunkInfo,
    Connection,
    encode_header,
    file_header_record,
    index_data_record,
    message_record_header,
)
from ninjemys.errors import BagError

_CHUNK_OP = bytes((OP_CHUNK,))


class BagWriter:
    """Writes one bag file. Not thread-safe: one writer thread owns it (``rosbag record`` does so)."""

    def __init__(
        self,
        path: str | os.PathLike[str],
        compression: str = "none",
        chunk_threshold: int = DEFAULT_CHUNK_THRESHOLD,
        flush_interval: float = 1.0,
        active: bool = False,
        append: bool = False,
    ) -> None:
        if compression not in COMPRESSIONS:
            raise BagError(f"{path}: unknown compression {compression!r} (expected none, bz2 or lz4)")
        self.path = Path(path)
        self.compression = compression
        self.chunk_threshold = chunk_threshold
        self.flush_interval = flush_interval
        self.connections: dict[int, Connection] = {}
        self.chunk_infos: list[ChunkInfo] = []
        self._by_key: dict[tuple[str, tuple[tuple[str, bytes], ...]], int] = {}
        self._by_topic: dict[str, int] = {}
        self._chunk = bytearray()
        self._chunk_index: dict[int, list[tuple[int, int]]] = {}
        self._chunk_sorted = True
        self._chunk_start = 0
        self._chunk_end = 0
        self._chunk_opened = 0.0
        self._chunk_messages = 0
        self.message_count = 0
        self._closed = False
        self.write_path = self.path.with_name(self.path.name + ".active") if active else self.path
        try:
            if append and self.path.exists():
                self._file = self._open_append()
            else:
                self._file = open(self.write_path, "wb")  # noqa: SIM115 - owned until close()
                self._file.write(MAGIC)
                self._file.write(file_header_record(0, 0, 0))
                self._file.flush()
        except OSError as exc:
            raise BagError(f"{self.write_path}: cannot open for writing ({exc.strerror})") from None

    def _open_append(self) -> BinaryIO:
        from ninjemys.bag.reader import BagReader

        with BagReader(self.path) as reader:
            if not reader.indexed:
                raise BagError(f"{self.path}: bag is not indexed; run `rosbag reindex {self.path}` first")
            index_pos = reader.index_pos
            self.connections = dict(reader.connections)
            self.chunk_infos = list(reader.chunk_infos)
        for conn in self.connections.values():
            self._remember(conn)
        self.message_count = sum(c.message_count for c in self.chunk_infos)
        f = open(self.path, "r+b")  # noqa: SIM115
        f.seek(0)
        f.write(MAGIC)
        f.write(file_header_record(0, 0, 0))
        f.truncate(index_pos)
        f.seek(index_pos)
        self.write_path = self.path
        return f

    def _remember(self, conn: Connection) -> None:
        self._by_key[(conn.topic, tuple(sorted(conn.header.items())))] = conn.id
        self._by_topic.setdefault(conn.topic, conn.id)

    # -- connections -----------------------------------------------------------------------------

    def connection(self, topic: str, header: dict[str, bytes]) -> int:
        """The id of the connection for ``topic`` with this exact header, created on first use.

        ``header`` is a TCPROS-style connection header (type, md5sum, message_definition, and for
        recordings callerid and latching). Its connection record goes into the current chunk, as in
        ROS 1, so a bag recovered by reindex still knows every connection it holds.
        """
        full = {"topic": topic.encode(), "type": b"", "md5sum": b"", "message_definition": b""}
        full.update(header)
        full["topic"] = topic.encode()
        key = (topic, tuple(sorted(full.items())))
        conn_id = self._by_key.get(key)
        if conn_id is not None:
            return conn_id
        conn = Connection(len(self.connections), topic, full)
        self.connections[conn.id] = conn
        self._remember(conn)
        self._open_chunk_if_needed()
        self._chunk += conn.record()
        return conn.id

    def topic_connection(self, topic: str) -> int | None:
        """The first connection recorded for ``topic`` (rosbag.Bag.write uses one per topic)."""
        return self._by_topic.get(topic)

    # -- messages --------------------------------------------------------------------------------

    def write(self, conn_id: int, ns: int, data: bytes | bytearray | memoryview) -> None:
        """Append one serialized message at receive/stamp time ``ns`` (integer nanoseconds)."""
        if self._closed:
            raise BagError(f"{self.path}: bag is closed")
        if ns < 0 or ns >= (1 << 32) * 10**9:
            raise BagError(f"{self.path}: message time {ns} ns is outside the bag's u32 seconds range")
        self._open_chunk_if_needed()
        chunk = self._chunk
        offset = len(chunk)
        index = self._chunk_index.get(conn_id)
        if index is None:
            if conn_id not in self.connections:
                raise BagError(f"{self.path}: unknown connection id {conn_id}")
            self._chunk_index[conn_id] = index = []
        elif ns < index[-1][0]:
            self._chunk_sorted = False
        index.append((ns, offset))
        if self._chunk_messages == 0:
            self._chunk_start = self._chunk_end = ns
        elif ns < self._chunk_start:
            self._chunk_start = ns
        elif ns > self._chunk_end:
            self._chunk_end = ns
        self._chunk_messages += 1
        chunk += message_record_header(conn_id, ns)
        chunk += U32.pack(len(data))
        chunk += data
        self.message_count += 1
        if len(chunk) > self.chunk_threshold or time.monotonic() - self._chunk_opened >= self.flush_interval:
            self.flush()

    def _open_chunk_if_needed(self) -> None:
        if not self._chunk:
            self._chunk_opened = time.monotonic()
            self._chunk_start = 0
            self._chunk_end = 0
            self._chunk_messages = 0

    def flush(self) -> None:
        """Write the open chunk (if it holds messages) with its index records and hand the bytes to the OS.

        A chunk holding only connection records stays open: an empty chunk would give the index a
        zero time span, and the connections reach the final index anyway.
        """
        if not self._chunk_messages:
            return
        f = self._file
        pos = f.tell()
        raw = self._chunk
        # uncompressed chunks go to the file straight from the buffer: no copy of megabyte messages
        packed = raw if self.compression == "none" else compress(self.compression, bytes(raw))
        header = encode_header(
            {"op": _CHUNK_OP, "compression": self.compression.encode(), "size": U32.pack(len(raw))}
        )
        index_parts = []
        counts: dict[int, int] = {}
        for conn_id, entries in self._chunk_index.items():
            if not self._chunk_sorted:
                entries.sort()
            index_parts.append(index_data_record(conn_id, entries))
            counts[conn_id] = len(entries)
        try:
            f.write(U32.pack(len(header)) + header + U32.pack(len(packed)))
            f.write(packed)
            f.write(b"".join(index_parts))
            f.flush()
        except OSError as exc:
            raise BagError(f"{self.write_path}: write failed ({exc.strerror})") from None
        # a chunk holding only connection records still gets an entry, so readers find them
        self.chunk_infos.append(ChunkInfo(pos, self._chunk_start, self._chunk_end, counts))
        self._chunk = bytearray()
        self._chunk_index = {}
        self._chunk_sorted = True
        self._chunk_messages = 0

    def maybe_flush(self) -> None:
        """Flush if the open chunk is older than ``flush_interval`` (a recorder calls this when idle)."""
        if self._chunk_messages and time.monotonic() - self._chunk_opened >= self.flush_interval:
            self.flush()

    @property
    def size(self) -> int:
        """Bytes written so far, including the chunk still in memory."""
        return self._file.tell() + len(self._chunk)

    def close(self) -> None:
        """Write the last chunk and the index, then rename ``*.active`` to the final name."""
        if self._closed:
            return
        self._closed = True
        f = self._file
        try:
            self.flush()
            index_pos = f.tell()
            f.write(b"".join(c.record() for c in self.connections.values()))
            f.write(b"".join(c.record() for c in self.chunk_infos))
            f.truncate()
            f.seek(len(MAGIC))
            f.write(file_header_record(index_pos, len(self.connections), len(self.chunk_infos)))
            f.close()
        except OSError as exc:
            raise BagError(f"{self.write_path}: cannot finish the bag ({exc.strerror})") from None
        if self.write_path != self.path:
            os.replace(self.write_path, self.path)

    def abandon(self) -> None:
        """Close the file without writing an index (tests use it to simulate a crash)."""
        self._closed = True
        self._file.close()

    def __enter__(self) -> BagWriter:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
