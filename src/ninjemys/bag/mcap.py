"""Export a bag to MCAP (``rosbag export --mcap``): ros1msg schemas, ros1 message encoding.

Each bag connection becomes an MCAP channel (topic, with callerid/latching kept as channel metadata);
each message type a ``ros1msg`` schema holding the bag's own message definition, so Foxglove and the
``mcap`` tools decode it without any ROS installation.
"""

from __future__ import annotations

from pathlib import Path

from ninjemys.bag.progress import Progress
from ninjemys.bag.reader import BagReader
from ninjemys.errors import BagError


def export_mcap(src: Path, dst: Path, progress: Progress | None = None) -> int:
    """Write every message of ``src`` to the MCAP file ``dst``; returns the message count."""
    try:
        from mcap.writer import CompressionType, Writer
    except ImportError:
        raise BagError("rosbag export --mcap needs the 'mcap' package (pip install mcap)") from None
    count = 0
    with BagReader(src) as reader:
        try:
            out = open(dst, "wb")  # noqa: SIM115 - closed below
        except OSError as exc:
            raise BagError(f"{dst}: cannot open for writing ({exc.strerror})") from None
        with out:
            writer = Writer(out, compression=CompressionType.LZ4)
            writer.start(profile="ros1", library="ninjemys rosbag export")
            schemas: dict[tuple[str, str], int] = {}
            channels: dict[int, int] = {}
            for conn in sorted(reader.connections.values(), key=lambda c: c.id):
                key = (conn.datatype, conn.msg_def)
                if key not in schemas:
                    schemas[key] = writer.register_schema(conn.datatype, "ros1msg", conn.msg_def.encode())
                meta = {"md5sum": conn.md5sum}
                if conn.callerid is not None:
                    meta["callerid"] = conn.callerid
                if "latching" in conn.header:
                    meta["latching"] = "1" if conn.latching else "0"
                channels[conn.id] = writer.register_channel(conn.topic, "ros1", schemas[key], meta)
            done = 0
            for msg in reader.read():
                writer.add_message(
                    channels[msg.connection.id], msg.time, bytes(msg.data), msg.time, sequence=count
                )
                count += 1
                done += len(msg.data)
                if progress is not None:
                    progress.step(done)
            writer.finish()
    if progress is not None:
        progress.finish()
    return count
