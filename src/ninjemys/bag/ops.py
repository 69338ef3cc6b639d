"""Whole-bag operations the tools share: copy with new compression, filter, integrity check.

They work on serialized bytes and keep every connection header as recorded (callerid, latching ...),
so a compressed or filtered bag is the same recording, byte for byte per message.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from ninjemys.bag.format import DEFAULT_CHUNK_THRESHOLD
from ninjemys.bag.progress import Progress
from ninjemys.bag.reader import BagReader, RawMessage
from ninjemys.bag.writer import BagWriter


def uncompressed_size(reader: BagReader) -> int:
    return sum(h.uncompressed_size for h in reader.chunk_headers.values())


def copy_bag(
    src: Path,
    dst: Path,
    compression: str,
    keep: Callable[[RawMessage], bool] | None = None,
    progress: Progress | None = None,
    chunk_threshold: int = DEFAULT_CHUNK_THRESHOLD,
) -> int:
    """Rewrite ``src`` into ``dst`` (time order) with ``compression``; returns the messages written."""
    written = 0
    with (
        BagReader(src) as reader,
        BagWriter(dst, compression=compression, chunk_threshold=chunk_threshold) as writer,
    ):
        ids: dict[int, int] = {}
        done = 0
        for msg in reader.read():
            done += len(msg.data)
            if progress is not None:
                progress.step(done)
            if keep is not None and not keep(msg):
                continue
            conn = msg.connection
            new_id = ids.get(conn.id)
            if new_id is None:
                header = {k: v for k, v in conn.header.items() if k != "topic"}
                ids[conn.id] = new_id = writer.connection(conn.topic, header)
            writer.write(new_id, msg.time, msg.data)
            written += 1
    if progress is not None:
        progress.finish()
    return written


def check_bag(path: Path) -> list[str]:
    """Problems found by reading every chunk and message of ``path`` (empty list: the bag is sound)."""
    problems: list[str] = []
    with BagReader(path) as reader:
        problems.extend(reader.warnings)
        count = 0
        for _ in reader.read():
            count += 1
        if count != reader.message_count:
            problems.append(f"{path}: index promises {reader.message_count} messages, {count} were readable")
    return problems
