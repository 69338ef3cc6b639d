"""The ROS 1 Python bag API (``rosbag.Bag``) over the format library.

Semantics follow ROS 1's ``rosbag.Bag``: modes ``r``/``w``/``a``, ``read_messages`` yielding
``BagMessage(topic, message, timestamp)`` in time order, ``raw=True`` giving
``(datatype, data, md5sum, position, pytype)``, counts and times from the index. Beyond ROS 1: a bag
with a missing or damaged index is read by scanning (with a warning) instead of raising, and messages of
types this installation does not know are decoded from the definition stored in the bag itself.
"""

from __future__ import annotations

import collections
import os
from collections.abc import Callable, Iterable, Iterator
from pathlib import Path
from typing import Any

from ninjemys.bag.format import DEFAULT_CHUNK_THRESHOLD, NSEC, Connection
from ninjemys.bag.info import info_key, info_text, info_yaml, topic_frequencies
from ninjemys.bag.reader import BagReader, RawMessage
from ninjemys.bag.writer import BagWriter
from ninjemys.errors import BagError, NinjemysError
from ninjemys.rostime import Time

BagMessage = collections.namedtuple("BagMessage", "topic message timestamp")
BagMessageWithConnectionHeader = collections.namedtuple(
    "BagMessageWithConnectionHeader", "topic message timestamp connection_header"
)
TopicTuple = collections.namedtuple("TopicTuple", ["msg_type", "message_count", "connections", "frequency"])
TypesAndTopicsTuple = collections.namedtuple("TypesAndTopicsTuple", ["msg_types", "topics"])
CompressionTuple = collections.namedtuple("CompressionTuple", ["compression", "uncompressed", "compressed"])


class ROSBagException(BagError):
    """Base of the rosbag errors (a BagError, so ``except NinjemysError`` catches it too)."""

    def __init__(self, value: str = "") -> None:
        self.value = value
        super().__init__(value)


class ROSBagFormatException(ROSBagException):
    """The bag file is malformed."""


class ROSBagUnindexedException(ROSBagException):
    """The bag has no index (ROS 1 raises this; ninjemys scans instead, only append mode raises it)."""

    def __init__(self) -> None:
        super().__init__("Unindexed bag")


class Compression:
    NONE = "none"
    BZ2 = "bz2"
    LZ4 = "lz4"


def to_ns(t: Any, what: str = "time") -> int:
    """Nanoseconds of a Time/Duration-like value (``secs``/``nsecs`` or ``to_nsec``), int or float seconds."""
    if t is None:
        raise ROSBagException(f"{what} is None")
    to_nsec = getattr(t, "to_nsec", None)
    if to_nsec is not None:
        return int(to_nsec())
    if isinstance(t, int):
        return t * NSEC
    if isinstance(t, float):
        return round(t * NSEC)
    raise ROSBagException(f"{what}: expected a rospy.Time, got {type(t).__name__}")


class _Decoders:
    """Message classes per (type, md5): shipped ones when the md5 matches, else built from the bag."""

    def __init__(self) -> None:
        self._cache: dict[tuple[str, str], type] = {}
        self._failed: set[tuple[str, str]] = set()

    def get_or_none(self, conn: Connection) -> type | None:
        key = (conn.datatype, conn.md5sum)
        if key in self._failed:
            return None
        try:
            return self.get(conn)
        except (NinjemysError, ImportError):
            self._failed.add(key)
            return None

    def get(self, conn: Connection) -> type:
        key = (conn.datatype, conn.md5sum)
        cls = self._cache.get(key)
        if cls is None:
            from ninjemys.idl import loader

            try:
                cls = loader.get_message_class(conn.datatype)
                if conn.md5sum not in ("*", cls._md5sum):
                    cls = None
            except NinjemysError:
                cls = None
            if cls is None:
                cls = loader.message_class_from_definition(conn.datatype, conn.msg_def, conn.md5sum)
            self._cache[key] = cls
        return cls


class Bag:
    """A bag file opened for reading (``r``), writing (``w``) or appending (``a``)."""

    def __init__(
        self,
        f: str | os.PathLike[str],
        mode: str = "r",
        compression: str = Compression.NONE,
        chunk_threshold: int = DEFAULT_CHUNK_THRESHOLD,
        allow_unindexed: bool = False,
        options: dict[str, Any] | None = None,
        skip_index: bool = False,
    ) -> None:
        if options:
            compression = options.get("compression", compression)
            chunk_threshold = options.get("chunk_threshold", chunk_threshold)
        if mode not in ("r", "w", "a"):
            raise ValueError(f"mode {mode!r} is invalid; expected 'r', 'w' or 'a'")
        if not isinstance(f, (str, os.PathLike)):
            raise ValueError("file must be a path (str or os.PathLike)")
        self._filename = str(Path(f))
        self._mode = mode
        self._compression = compression
        self._chunk_threshold = chunk_threshold
        self._reader: BagReader | None = None
        self._writer: BagWriter | None = None
        self._decoders = _Decoders()
        self._unindexed = False
        # rosbag's str(bag) gives each topic's rate when it has read the connection indexes (the
        # default; `rosbag info` opens with skip_index unless --freq): our reader always has them
        self._skip_index = skip_index
        try:
            if mode == "r":
                self._reader = BagReader(f)
            else:
                unindexed = False
                if mode == "a" and Path(f).exists():
                    with BagReader(f) as probe:
                        unindexed = not probe.indexed
                    if unindexed and not allow_unindexed:
                        raise ROSBagUnindexedException()
                if unindexed:
                    # allow_unindexed: the caller will reindex() first; the writer opens after that
                    self._unindexed = True
                else:
                    self._writer = BagWriter(
                        f, compression=compression, chunk_threshold=chunk_threshold, append=(mode == "a")
                    )
        except ROSBagException:
            raise
        except BagError as exc:
            raise ROSBagException(str(exc)) from None

    # -- properties ------------------------------------------------------------------------------

    @property
    def filename(self) -> str:
        return self._filename

    @property
    def mode(self) -> str:
        return self._mode

    @property
    def size(self) -> int:
        if self._writer is not None:
            return self._writer.size
        return self._require_reader().size

    @property
    def version(self) -> int:
        return 200

    @property
    def warnings(self) -> list[str]:
        """What was wrong with the file and how it was worked around (empty for a healthy bag)."""
        return list(self._reader.warnings) if self._reader else []

    def _get_compression(self) -> str:
        return self._compression

    def _set_compression(self, compression: str) -> None:
        if self._writer is None:
            raise ROSBagException("compression can only be set on a bag opened for writing")
        if compression not in (Compression.NONE, Compression.BZ2, Compression.LZ4):
            raise ROSBagException(f"unsupported compression {compression!r}")
        self._writer.flush()
        self._writer.compression = compression
        self._compression = compression

    compression = property(_get_compression, _set_compression)

    def _get_chunk_threshold(self) -> int:
        return self._chunk_threshold

    def _set_chunk_threshold(self, value: int) -> None:
        self._chunk_threshold = value
        if self._writer is not None:
            self._writer.flush()
            self._writer.chunk_threshold = value

    chunk_threshold = property(_get_chunk_threshold, _set_chunk_threshold)

    @property
    def options(self) -> dict[str, Any]:
        return {"compression": self._compression, "chunk_threshold": self._chunk_threshold}

    def _require_reader(self) -> BagReader:
        if self._reader is None:
            if self._writer is not None:
                raise ROSBagException(
                    f"{self._filename}: bag is open for writing ('{self._mode}'), not reading"
                )
            raise ValueError("I/O operation on closed bag")
        return self._reader

    # -- writing ---------------------------------------------------------------------------------

    def write(
        self,
        topic: str,
        msg: Any,
        t: Any = None,
        raw: bool = False,
        connection_header: dict[str, str] | None = None,
    ) -> None:
        """Write ``msg`` (a message, or with ``raw`` a (datatype, data, md5sum, pytype) tuple) at ``t``."""
        writer = self._writer
        if writer is None:
            if self._unindexed:
                raise ROSBagUnindexedException()
            if self._reader is None:
                raise ValueError("I/O operation on closed bag")
            raise ROSBagException(f"{self._filename}: bag is open for reading, not writing")
        if not topic:
            raise ValueError("topic is not specified")
        ns = to_ns(Time.now() if t is None else t, f"{topic}: time")
        if raw:
            if len(msg) == 5:
                datatype, data, md5sum, _pos, pytype = msg
            elif len(msg) == 4:
                datatype, data, md5sum, pytype = msg
            else:
                raise ValueError("raw message must be (datatype, data, md5sum, pytype)")
            definition = getattr(pytype, "_full_text", None) if pytype is not None else None
            if definition is None and connection_header is None:
                definition = self._definition_for(datatype)
        else:
            cls = type(msg)
            datatype = getattr(cls, "_type", None)
            md5sum = getattr(cls, "_md5sum", None)
            definition = getattr(cls, "_full_text", "")
            if datatype is None or md5sum is None:
                raise ROSBagException(f"{topic}: {cls.__name__} is not a ROS message (no _type/_md5sum)")
            data = _serialize(msg, topic)
        conn_id = writer.topic_connection(topic) if connection_header is None else None
        if conn_id is None:
            if connection_header is not None:
                header = {
                    k: v.encode() if isinstance(v, str) else bytes(v) for k, v in connection_header.items()
                }
            else:
                header = {
                    "type": datatype.encode(),
                    "md5sum": md5sum.encode(),
                    "message_definition": (definition or "").encode(),
                }
            conn_id = writer.connection(topic, header)
        try:
            writer.write(conn_id, ns, data)
        except BagError as exc:
            raise ROSBagException(str(exc)) from None

    def _definition_for(self, datatype: str) -> str:
        from ninjemys.idl import loader

        try:
            return loader.get_message_class(datatype)._full_text
        except NinjemysError as exc:
            raise ROSBagException(
                f"cannot locate message class and no message class provided for [{datatype}]"
            ) from exc

    def flush(self) -> None:
        """Write everything buffered so far (ROS 1's ``Bag.flush``)."""
        if self._writer is not None:
            self._writer.flush()

    # -- reading ---------------------------------------------------------------------------------

    def read_messages(
        self,
        topics: Iterable[str] | str | None = None,
        start_time: Any = None,
        end_time: Any = None,
        connection_filter: Callable[..., bool] | None = None,
        raw: bool = False,
        return_connection_header: bool = False,
    ) -> Iterator[Any]:
        """Messages in time order as BagMessage(topic, message, timestamp)."""
        reader = self._require_reader()
        start = None if start_time is None else to_ns(start_time, "start_time")
        end = None if end_time is None else to_ns(end_time, "end_time")
        conn_filter = None
        if connection_filter is not None:

            def conn_filter(c: Connection) -> bool:
                return bool(connection_filter(c.topic, c.datatype, c.md5sum, c.msg_def, c.string_header()))

        return self._iterate(reader.read(topics, start, end, conn_filter), raw, return_connection_header)

    def _iterate(self, source: Iterator[RawMessage], raw: bool, with_header: bool) -> Iterator[Any]:
        decoders = self._decoders
        make_time = Time._raw
        new_tuple = tuple.__new__  # namedtuple construction without its Python-level __new__
        # per-connection work (class lookup, header text) is done once, not per message
        per_conn: dict[int, Any] = {}
        cls: Any  # None only for a raw read of a type that cannot be loaded (never deserialized)
        try:
            for conn, ns, data, chunk_pos, offset in source:
                cached = per_conn.get(conn.id)
                if cached is None:
                    cls = _pytype_or_none(decoders, conn) if raw else decoders.get(conn)
                    cached = per_conn[conn.id] = (cls, conn.string_header() if with_header else None)
                cls = cached[0]
                secs, nsecs = divmod(ns, NSEC)
                stamp = make_time(secs, nsecs)
                if raw:
                    message: Any = (conn.datatype, bytes(data), conn.md5sum, (chunk_pos, offset), cls)
                else:
                    message = _deserialize(cls, data, conn)
                if with_header:
                    yield new_tuple(BagMessageWithConnectionHeader, (conn.topic, message, stamp, cached[1]))
                else:
                    yield new_tuple(BagMessage, (conn.topic, message, stamp))
        except ROSBagException:
            raise
        except NinjemysError as exc:  # damaged chunk, or a definition in the bag that does not parse
            raise ROSBagFormatException(str(exc)) from None

    def __iter__(self) -> Iterator[Any]:
        return self.read_messages()

    def get_message_count(self, topic_filters: Iterable[str] | str | None = None) -> int:
        reader = self._require_reader()
        return reader.count(reader.topic_connections(topic_filters))

    def get_start_time(self) -> float:
        start = self._require_reader().start_time
        if start is None:
            raise ROSBagException("Bag contains no message")
        return start / NSEC

    def get_end_time(self) -> float:
        end = self._require_reader().end_time
        if end is None:
            raise ROSBagException("Bag contains no message")
        return end / NSEC

    def get_type_and_topic_info(
        self, topic_filters: Iterable[str] | str | None = None
    ) -> TypesAndTopicsTuple:
        reader = self._require_reader()
        types: dict[str, str] = {}
        for conn in sorted(reader.connections.values(), key=lambda c: c.id):
            types.setdefault(conn.datatype, conn.md5sum)
        types = dict(sorted(types.items()))
        if topic_filters is None:
            wanted = sorted({c.topic for c in reader.connections.values()})
        else:
            wanted = sorted({topic_filters} if isinstance(topic_filters, str) else set(topic_filters))
        freqs = topic_frequencies(reader)
        topics: dict[str, TopicTuple] = {}
        for topic in wanted:
            conns = reader.topic_connections(topic)
            if conns:
                topics[topic] = TopicTuple(
                    conns[0].datatype, reader.count(conns), len(conns), freqs.get(topic)
                )
        return TypesAndTopicsTuple(types, topics)

    def get_compression_info(self) -> CompressionTuple:
        reader = self._require_reader()
        counts: dict[str, int] = {}
        raw = packed = 0
        for header in reader.chunk_headers.values():
            counts[header.compression] = counts.get(header.compression, 0) + 1
            raw += header.uncompressed_size
            packed += header.compressed_size
        main = sorted(((v, k) for k, v in counts.items()), reverse=True)[0][1] if counts else Compression.NONE
        return CompressionTuple(main, raw, packed)

    def reindex(self) -> Iterator[int]:
        """Rebuild the index of a bag opened with ``allow_unindexed``; yields chunk offsets for progress."""
        from ninjemys.bag.reindex import reindex_in_place

        if self._writer is not None:
            self._writer.abandon()
            self._writer = None
        self._reader = None
        try:
            yield from reindex_in_place(self._filename)
        except ROSBagException:
            raise
        except BagError as exc:
            raise ROSBagFormatException(str(exc)) from None
        self._unindexed = False
        self._writer = BagWriter(
            self._filename, compression=self._compression, chunk_threshold=self._chunk_threshold, append=True
        )

    def __str__(self) -> str:
        return info_text(self._require_reader(), self._filename, freq=not self._skip_index)

    def _get_yaml_info(self, key: str | None = None) -> str | None:
        text = info_yaml(self._require_reader(), self._filename)
        return text if not key else info_key(text, key)

    # -- lifetime --------------------------------------------------------------------------------

    def close(self) -> None:
        """Close the bag (writing its index when writing). Closing twice does nothing."""
        if self._writer is not None:
            writer, self._writer = self._writer, None
            try:
                writer.close()
            except BagError as exc:
                raise ROSBagException(str(exc)) from None
        if self._reader is not None:
            self._reader.close()
            self._reader = None

    def __enter__(self) -> Bag:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def _serialize(msg: Any, topic: str) -> bytes:
    fast = getattr(msg, "serialize_to_bytes", None)
    if fast is not None:
        return fast()
    import io

    buff = io.BytesIO()
    msg.serialize(buff)
    return buff.getvalue()


def _deserialize(cls: type, data: memoryview, conn: Connection) -> Any:
    try:
        fast = getattr(cls, "deserialize_from", None)
        if fast is not None:
            return fast(data)
        return cls().deserialize(bytes(data))
    except Exception as exc:  # bytes from a file: any decoding failure is a format error, named
        raise ROSBagFormatException(f"{conn.topic} ({conn.datatype}): cannot deserialize: {exc}") from None


def _pytype_or_none(decoders: _Decoders, conn: Connection) -> type | None:
    """The class for raw tuples, or None when it cannot be built (raw reading never needs it)."""
    return decoders.get_or_none(conn)
