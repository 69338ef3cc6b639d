"""Bag v2.0 reader: index-driven reads by topic and time range, and a scan mode for damaged bags.

An indexed bag is opened by reading only the file header and the index at ``index_pos`` (connections
and chunk infos); messages are then read chunk by chunk, using each chunk's INDEX_DATA records, and
only chunks that overlap the requested topics and time range are touched. A bag whose index is missing
(``*.bag.active`` after a crash), truncated or corrupt is opened by a linear scan of its chunks instead,
with a warning; a chunk cut short by a crash yields the messages that are intact.
"""

from __future__ import annotations

import heapq
import logging
import os
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import BinaryIO, NamedTuple

from ninjemys.bag.compression import decompress, decompress_partial
from ninjemys.bag.format import (
    FILE_HEADER_LENGTH,
    INDEX_ENTRY,
    MAGIC,
    NSEC,
    OP_CHUNK,
    OP_CHUNK_INFO,
    OP_CONNECTION,
    OP_FILE_HEADER,
    OP_INDEX_DATA,
    OP_MSG_DATA,
    U32,
    VERSION_PREFIX,
    ChunkHeader,
    ChunkInfo,
    Connection,
    decode_header,
    field_op,
    field_time,
    field_u32,
    field_u64,
)
from ninjemys.errors import BagError

log = logging.getLogger(__name__)

_HEADER_END = len(MAGIC) + FILE_HEADER_LENGTH
#: records larger than this are treated as corruption rather than allocated
_MAX_RECORD = 1 << 31


class RawMessage(NamedTuple):
    """One message as stored: its connection, time (ns) and serialized bytes (a view into the chunk)."""

    connection: Connection
    time: int
    data: memoryview
    chunk_pos: int
    #: the message record's offset in the decompressed chunk (rosbag's position is (chunk_pos, offset))
    offset: int = 0


class _Encrypted(BagError):
    """An encrypted bag: reported as such, never scanned as if it were damaged."""


@dataclass
class _Scanned:
    """What a scan learned about one chunk: its entries, and its bytes if the file holds only part."""

    entries: list[tuple[int, int, int]]
    data: bytes | None


class BagReader:
    """Reads one bag. ``warnings`` lists what was wrong with the file and how it was worked around."""

    def __init__(self, path: str | os.PathLike[str], scan: bool | None = None) -> None:
        self.path = Path(path)
        self.warnings: list[str] = []
        self.connections: dict[int, Connection] = {}
        self.chunk_infos: list[ChunkInfo] = []
        self.index_pos = 0
        self.indexed = False
        self.version = "2.0"
        self._scanned: dict[int, _Scanned] = {}
        self._chunk_headers: dict[int, ChunkHeader] | None = None
        try:
            self._file: BinaryIO = open(self.path, "rb")  # noqa: SIM115 - owned until close()
        except OSError as exc:
            raise BagError(f"{self.path}: cannot open bag ({exc.strerror})") from None
        try:
            self.size = os.fstat(self._file.fileno()).st_size
            self._open(scan)
        except BaseException:
            self._file.close()
            raise

    # -- opening ---------------------------------------------------------------------------------

    def _warn(self, message: str) -> None:
        self.warnings.append(message)
        log.warning("%s", message)

    def _open(self, scan: bool | None) -> None:
        f = self._file
        magic = f.read(len(MAGIC))
        if not magic:
            raise BagError(f"{self.path}: empty file, not a bag")
        if magic != MAGIC:
            if magic.startswith(VERSION_PREFIX):
                version = magic[len(VERSION_PREFIX) :].strip().decode("latin-1", "replace")
                raise BagError(f"{self.path}: bag format version {version} is not supported (only 2.0)")
            raise BagError(f"{self.path}: not a bag file (no '#ROSBAG V2.0' magic)")
        try:
            fields = self._read_header_at(len(MAGIC))
            if field_op(fields, f"{self.path}:{len(MAGIC)}") != OP_FILE_HEADER:
                raise BagError(f"{self.path}: the first record is not a file header")
            encryptor = fields.get("encryptor", b"").decode("latin-1", "replace")
            if encryptor and encryptor != "rosbag/NoEncryptor":
                raise _Encrypted(
                    f"{self.path}: bag is encrypted with {encryptor}, which ninjemys does not support"
                )
            self.index_pos = field_u64(fields, "index_pos", f"{self.path}: file header")
            conn_count = field_u32(fields, "conn_count", f"{self.path}: file header")
            chunk_count = field_u32(fields, "chunk_count", f"{self.path}: file header")
        except _Encrypted:
            raise
        except BagError as exc:
            if self.size <= len(MAGIC) + 8:
                raise BagError(f"{self.path}: truncated inside the file header ({self.size} bytes)") from None
            self._warn(f"{self.path}: file header unreadable ({exc}); scanning the chunks")
            self._scan()
            return
        if scan:
            self._scan()
            return
        if self.index_pos == 0:
            self._warn(f"{self.path}: bag is not indexed (recording did not finish); scanning the chunks")
            self._scan()
            return
        try:
            self._read_index(conn_count, chunk_count)
            self.indexed = True
        except BagError as exc:
            self._warn(f"{exc}; scanning the chunks instead")
            self.connections = {}
            self.chunk_infos = []
            self._scan()

    def _read_exact(self, pos: int, size: int, what: str) -> bytes:
        if size < 0 or pos + size > self.size:
            raise BagError(
                f"{self.path}:{pos}: {what} of {size} bytes runs past the end of the file ({self.size})"
            )
        self._file.seek(pos)
        data = self._file.read(size)
        if len(data) != size:
            raise BagError(f"{self.path}:{pos}: short read of {what}")
        return data

    def _read_header_at(self, pos: int) -> dict[str, bytes]:
        (hlen,) = U32.unpack(self._read_exact(pos, 4, "record header length"))
        if hlen > _MAX_RECORD:
            raise BagError(f"{self.path}:{pos}: record header length {hlen} is not plausible")
        return decode_header(self._read_exact(pos + 4, hlen, "record header"), f"{self.path}:{pos}")

    def _record_at(self, pos: int, read_data: bool = True) -> tuple[dict[str, bytes], int, int, bytes | None]:
        """(header fields, data position, data length, data) of the record at ``pos``."""
        (hlen,) = U32.unpack(self._read_exact(pos, 4, "record header length"))
        if hlen > _MAX_RECORD:
            raise BagError(f"{self.path}:{pos}: record header length {hlen} is not plausible")
        fields = decode_header(self._read_exact(pos + 4, hlen, "record header"), f"{self.path}:{pos}")
        dpos = pos + 8 + hlen
        (dlen,) = U32.unpack(self._read_exact(pos + 4 + hlen, 4, "record data length"))
        data = self._read_exact(dpos, dlen, "record data") if read_data else None
        return fields, dpos, dlen, data

    def _read_index(self, conn_count: int, chunk_count: int) -> None:
        if self.index_pos < _HEADER_END or self.index_pos > self.size:
            raise BagError(
                f"{self.path}: index position {self.index_pos} is outside the file ({self.size} bytes)"
            )
        pos = self.index_pos
        for _ in range(conn_count):
            fields, dpos, dlen, data = self._record_at(pos)
            where = f"{self.path}:{pos}"
            if field_op(fields, where) != OP_CONNECTION:
                raise BagError(f"{where}: expected a connection record in the index")
            self._add_connection(fields, data or b"", where)
            pos = dpos + dlen
        for _ in range(chunk_count):
            fields, dpos, dlen, data = self._record_at(pos)
            where = f"{self.path}:{pos}"
            if field_op(fields, where) != OP_CHUNK_INFO:
                raise BagError(f"{where}: expected a chunk info record in the index")
            self.chunk_infos.append(_chunk_info(fields, data or b"", where))
            pos = dpos + dlen
        for info in self.chunk_infos:
            for conn in info.counts:
                if conn not in self.connections:
                    raise BagError(f"{self.path}: chunk at {info.pos} refers to unknown connection {conn}")
            if info.pos < _HEADER_END or info.pos >= self.index_pos:
                raise BagError(f"{self.path}: chunk position {info.pos} is outside the data section")

    def _add_connection(self, fields: dict[str, bytes], data: bytes, where: str) -> None:
        conn_id = field_u32(fields, "conn", where)
        topic = fields.get("topic", b"").decode("utf-8", "replace")
        header = decode_header(data, where)
        header.setdefault("topic", topic.encode())
        self.connections.setdefault(conn_id, Connection(conn_id, topic, header))

    # -- scan mode -------------------------------------------------------------------------------

    def _scan(self) -> None:
        """Rebuild connections and chunk infos by walking every record after the file header."""
        self.indexed = False
        self._scanned = {}
        pos = _HEADER_END
        while pos < self.size:
            try:
                fields, dpos, dlen = self._scan_record_header(pos)
            except BagError as exc:
                self._warn(f"{exc}; ignoring the rest of the file")
                break
            where = f"{self.path}:{pos}"
            try:
                op = field_op(fields, where)
            except BagError as exc:
                self._warn(f"{exc}; ignoring the rest of the file")
                break
            truncated = dpos + dlen > self.size
            if op == OP_CHUNK:
                try:
                    self._scan_chunk(pos, fields, dpos, dlen, truncated)
                except BagError as exc:
                    self._warn(f"{exc}; chunk skipped")
            elif op == OP_CONNECTION and not truncated:
                try:
                    self._add_connection(fields, self._read_exact(dpos, dlen, "connection"), where)
                except BagError as exc:
                    self._warn(f"{exc}; connection record skipped")
            elif op not in (OP_INDEX_DATA, OP_CHUNK_INFO, OP_MSG_DATA):
                self._warn(f"{where}: unknown record op {op:#x} skipped")
            if truncated:
                self._warn(f"{where}: file ends inside a record (bag truncated); read what was intact")
                break
            pos = dpos + dlen
        self.chunk_infos.sort(key=lambda c: c.pos)
        known = set(self.connections)
        for info in self.chunk_infos:
            missing = set(info.counts) - known
            if missing:
                self._warn(
                    f"{self.path}: chunk at {info.pos} uses connections {sorted(missing)} never defined"
                )
                scanned = self._scanned[info.pos]
                scanned.entries = [e for e in scanned.entries if e[1] in known]
                for conn in missing:
                    del info.counts[conn]

    def _scan_record_header(self, pos: int) -> tuple[dict[str, bytes], int, int]:
        if pos + 4 > self.size:
            raise BagError(f"{self.path}:{pos}: file ends inside a record length")
        fields = self._read_header_at(pos)
        (hlen,) = U32.unpack(self._read_exact(pos, 4, "record header length"))
        dlen_pos = pos + 4 + hlen
        (dlen,) = U32.unpack(self._read_exact(dlen_pos, 4, "record data length"))
        return fields, dlen_pos + 4, dlen

    def _scan_chunk(self, pos: int, fields: dict[str, bytes], dpos: int, dlen: int, truncated: bool) -> None:
        where = f"{self.path}:{pos}"
        kind = fields.get("compression", b"none").decode("latin-1")
        size = field_u32(fields, "size", where)
        if truncated:
            self._file.seek(dpos)
            data = decompress_partial(kind, self._file.read())
        else:
            data = decompress(kind, self._read_exact(dpos, dlen, "chunk"), size, where)
        entries: list[tuple[int, int, int]] = []
        counts: dict[int, int] = {}
        off = 0
        end = len(data)
        while off + 4 <= end:
            (hlen,) = U32.unpack_from(data, off)
            if off + 8 + hlen > end:
                break
            try:
                rec = decode_header(memoryview(data)[off + 4 : off + 4 + hlen], f"{where}+{off}")
                (rdlen,) = U32.unpack_from(data, off + 4 + hlen)
                if off + 8 + hlen + rdlen > end:
                    break
                op = field_op(rec, where)
                if op == OP_MSG_DATA:
                    conn = field_u32(rec, "conn", where)
                    ns = field_time(rec, "time", where)
                    entries.append((ns, conn, off))
                    counts[conn] = counts.get(conn, 0) + 1
                elif op == OP_CONNECTION:
                    dstart = off + 8 + hlen
                    self._add_connection(rec, data[dstart : dstart + rdlen], where)
            except BagError as exc:
                self._warn(f"{exc}; rest of the chunk skipped")
                break
            off += 8 + hlen + rdlen
        if truncated and not entries:
            return
        if not entries:
            return
        entries.sort()
        times = [e[0] for e in entries]
        self.chunk_infos.append(ChunkInfo(pos, min(times), max(times), counts))
        self._scanned[pos] = _Scanned(entries, data if truncated else None)
        if self._chunk_headers is None:
            self._chunk_headers = {}
        self._chunk_headers[pos] = ChunkHeader(kind, dlen, size, dpos)

    def chunk_extent(self, info: ChunkInfo) -> tuple[int, int | None]:
        """(end of the chunk record, end of its INDEX_DATA records or None if they are not all intact)."""
        fields, dpos, dlen, _ = self._record_at(info.pos, read_data=False)
        chunk_end = dpos + dlen
        pos = chunk_end
        try:
            for _ in range(len(info.counts)):
                fields, dpos, dlen, _ = self._record_at(pos, read_data=False)
                if field_op(fields, f"{self.path}:{pos}") != OP_INDEX_DATA or dpos + dlen > self.size:
                    return chunk_end, None
                pos = dpos + dlen
        except BagError:
            return chunk_end, None
        return chunk_end, pos

    def is_partial(self, info: ChunkInfo) -> bool:
        """True for a chunk cut short in the file (its messages came from a partial decompression)."""
        scanned = self._scanned.get(info.pos)
        return scanned is not None and scanned.data is not None

    def chunk_entries(self, info: ChunkInfo) -> list[tuple[int, int, int]]:
        """(ns, conn, offset) of every message in one chunk, in time order."""
        return self._chunk_data_and_entries(info, set(info.counts))[1]

    def chunk_records(self, info: ChunkInfo) -> Iterator[RawMessage]:
        """Every message of one chunk in time order (reindex rewrites a partial chunk from these)."""
        data, entries = self._chunk_data_and_entries(info, set(info.counts))
        yield from self._emit(data, entries, info, 0, 1 << 64)

    # -- queries ---------------------------------------------------------------------------------

    @property
    def chunk_headers(self) -> dict[int, ChunkHeader]:
        """Compression and sizes of every chunk (read lazily: only ``rosbag info`` needs them)."""
        if self._chunk_headers is None or len(self._chunk_headers) < len(self.chunk_infos):
            headers = dict(self._chunk_headers or {})
            for info in self.chunk_infos:
                if info.pos in headers:
                    continue
                fields, dpos, dlen, _ = self._record_at(info.pos, read_data=False)
                where = f"{self.path}:{info.pos}"
                headers[info.pos] = ChunkHeader(
                    fields.get("compression", b"none").decode("latin-1"),
                    dlen,
                    field_u32(fields, "size", where),
                    dpos,
                )
            self._chunk_headers = headers
        return self._chunk_headers

    @property
    def message_count(self) -> int:
        return sum(c.message_count for c in self.chunk_infos)

    @property
    def start_time(self) -> int | None:
        """Start of the first chunk, in ns (what ROS 1 reports); None for a bag without messages."""
        infos = [c for c in self.chunk_infos if c.counts]
        return infos[0].start_time if infos else None

    @property
    def end_time(self) -> int | None:
        infos = [c for c in self.chunk_infos if c.counts]
        return infos[-1].end_time if infos else None

    def topic_connections(self, topics: Iterable[str] | str | None = None) -> list[Connection]:
        if topics is None:
            return list(self.connections.values())
        wanted = {topics} if isinstance(topics, str) else set(topics)
        return [c for c in self.connections.values() if c.topic in wanted]

    def count(self, connections: Iterable[Connection]) -> int:
        ids = {c.id for c in connections}
        return sum(n for info in self.chunk_infos for conn, n in info.counts.items() if conn in ids)

    def index_times(self, ids: set[int]) -> list[int]:
        """Sorted times (ns) of every message on connections ``ids``, from the index records only."""
        times: list[int] = []
        for info in self.chunk_infos:
            if not any(conn in ids for conn in info.counts):
                continue
            scanned = self._scanned.get(info.pos)
            if scanned is not None:
                times.extend(e[0] for e in scanned.entries if e[1] in ids)
                continue
            fields, dpos, dlen, _ = self._record_at(info.pos, read_data=False)
            pos = dpos + dlen
            for _ in range(len(info.counts)):
                fields, dpos, dlen, raw = self._record_at(pos)
                if field_u32(fields, "conn", f"{self.path}:{pos}") in ids:
                    times.extend(s * NSEC + n for s, n, _o in INDEX_ENTRY.iter_unpack(raw or b""))
                pos = dpos + dlen
        times.sort()
        return times

    # -- reading messages ------------------------------------------------------------------------

    def _chunk_data_and_entries(
        self, info: ChunkInfo, conns: set[int]
    ) -> tuple[bytes, list[tuple[int, int, int]]]:
        """The decompressed chunk and its (ns, conn, offset) entries for ``conns``, sorted by time."""
        scanned = self._scanned.get(info.pos)
        if scanned is not None:
            if scanned.data is not None:
                data = scanned.data
            else:
                data = self._load_chunk(info.pos)[0]
            return data, [e for e in scanned.entries if e[1] in conns]
        data, after = self._load_chunk(info.pos)
        entries: list[tuple[int, int, int]] = []
        pos = after
        for _ in range(len(info.counts)):
            fields, dpos, dlen, raw = self._record_at(pos)
            where = f"{self.path}:{pos}"
            if field_op(fields, where) != OP_INDEX_DATA:
                raise BagError(f"{where}: expected an index data record after the chunk at {info.pos}")
            conn = field_u32(fields, "conn", where)
            if conn in conns:
                count = field_u32(fields, "count", where)
                if count * INDEX_ENTRY.size != dlen:
                    raise BagError(f"{where}: index data holds {dlen} bytes for {count} entries")
                entries.extend((s * NSEC + n, conn, o) for s, n, o in INDEX_ENTRY.iter_unpack(raw or b""))
            pos = dpos + dlen
        if len(conns) > 1:
            entries.sort()
        return data, entries

    def _load_chunk(self, pos: int) -> tuple[bytes, int]:
        fields, dpos, dlen, raw = self._record_at(pos)
        where = f"{self.path}:{pos}"
        if field_op(fields, where) != OP_CHUNK:
            raise BagError(f"{where}: expected a chunk record")
        kind = fields.get("compression", b"none").decode("latin-1")
        return decompress(kind, raw or b"", field_u32(fields, "size", where), where), dpos + dlen

    def read(
        self,
        topics: Iterable[str] | str | None = None,
        start: int | None = None,
        end: int | None = None,
        connection_filter: Callable[[Connection], bool] | None = None,
    ) -> Iterator[RawMessage]:
        """Messages in time order (ties in file order), restricted to topics and [start, end] in ns."""
        conns = self.topic_connections(topics)
        if connection_filter is not None:
            conns = [c for c in conns if connection_filter(c)]
        ids = {c.id for c in conns}
        if not ids:
            return
        lo = start if start is not None else 0
        hi = end if end is not None else 1 << 64
        chunks = [
            c
            for c in self.chunk_infos
            if c.end_time >= lo and c.start_time <= hi and any(conn in ids for conn in c.counts)
        ]
        chunks.sort(key=lambda c: (c.start_time, c.pos))
        connections = self.connections
        pending: list[tuple[int, int, int, int, bytes]] = []
        for i, info in enumerate(chunks):
            while pending and pending[0][0] < info.start_time:
                yield self._pop(pending, connections)
            data, entries = self._chunk_data_and_entries(info, ids)
            nxt = chunks[i + 1] if i + 1 < len(chunks) else None
            alone = not pending and (
                nxt is None
                or info.end_time < nxt.start_time
                or (info.end_time == nxt.start_time and info.pos < nxt.pos)
            )
            if alone:
                yield from self._emit(data, entries, info, lo, hi)
            else:
                for ns, conn, off in entries:
                    if lo <= ns <= hi:
                        heapq.heappush(pending, (ns, info.pos, off, conn, data))
        while pending:
            yield self._pop(pending, connections)

    def _emit(
        self, data: bytes, entries: list[tuple[int, int, int]], info: ChunkInfo, lo: int, hi: int
    ) -> Iterator[RawMessage]:
        # the hot loop of every read: slicing is inlined, bounds are checked once per message
        view = memoryview(data)
        size = len(data)
        connections = self.connections
        unpack = U32.unpack_from
        clip = info.start_time < lo or info.end_time > hi
        pos = info.pos
        make = RawMessage
        for ns, conn, off in entries:
            if clip and not lo <= ns <= hi:
                continue
            try:
                start = off + 8 + unpack(view, off)[0]
                end = start + unpack(view, start - 4)[0]
            except Exception:
                raise BagError(
                    f"{self.path}: chunk at {pos}: index points outside the chunk (offset {off})"
                ) from None
            if end > size:
                raise BagError(f"{self.path}: chunk at {pos}: message at offset {off} overruns the chunk")
            yield make(connections[conn], ns, view[start:end], pos, off)

    def _pop(
        self, pending: list[tuple[int, int, int, int, bytes]], connections: dict[int, Connection]
    ) -> RawMessage:
        ns, chunk_pos, off, conn, data = heapq.heappop(pending)
        view = memoryview(data)
        return RawMessage(
            connections[conn],
            ns,
            self._slice(view, len(data), off, chunk_pos, U32.unpack_from),
            chunk_pos,
            off,
        )

    def _slice(self, view: memoryview, size: int, off: int, chunk_pos: int, unpack: Callable) -> memoryview:
        try:
            (hlen,) = unpack(view, off)
            start = off + 8 + hlen
            (dlen,) = unpack(view, start - 4)
        except Exception:
            raise BagError(
                f"{self.path}: chunk at {chunk_pos}: index points outside the chunk (offset {off})"
            ) from None
        if start + dlen > size:
            raise BagError(f"{self.path}: chunk at {chunk_pos}: message at offset {off} overruns the chunk")
        return view[start : start + dlen]

    def close(self) -> None:
        self._file.close()

    def __enter__(self) -> BagReader:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def _chunk_info(fields: dict[str, bytes], data: bytes, where: str) -> ChunkInfo:
    pos = field_u64(fields, "chunk_pos", where)
    start = field_time(fields, "start_time", where)
    end = field_time(fields, "end_time", where)
    count = field_u32(fields, "count", where)
    if len(data) != count * 8:
        raise BagError(f"{where}: chunk info holds {len(data)} bytes for {count} connections")
    counts = {
        conn: n
        for conn, n in (U32.unpack_from(data, i * 8) + U32.unpack_from(data, i * 8 + 4) for i in range(count))
    }
    return ChunkInfo(pos, start, end, counts)
