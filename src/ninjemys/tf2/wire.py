"""``tf2_msgs/TFMessage`` straight from and to its ROS 1 bytes, as the buffer's tuples.

A listener on ``/tf`` decodes thousands of transforms a second (geometry2#513: ROS 1's Python
listener spends most of its CPU there). Building message objects only to read their fields back
is the cost; this reads the fixed layout with ``struct`` directly into
``(parent, child, stamp_ns, tx, ty, tz, qx, qy, qz, qw)`` tuples that
:meth:`ninjemys.tf2.core.BufferCore.set_transforms` takes in one batch.
"""

from __future__ import annotations

import struct
from collections.abc import Iterable, Sequence

from ninjemys.errors import DeserializationError

_U32 = struct.Struct("<I")
_STAMP_LEN = struct.Struct("<3I")  # secs, nsecs, len(frame_id) after the seq
_SEVEN = struct.Struct("<7d")
_NS = 1_000_000_000


def decode_tf_message(buf: bytes | bytearray | memoryview) -> list[tuple]:
    """The transforms of a serialized TFMessage; DeserializationError naming the offset if truncated."""
    if not isinstance(buf, bytes):
        buf = bytes(buf)
    try:
        (count,) = _U32.unpack_from(buf, 0)
        pos = 4
        out: list[tuple] = []
        append = out.append
        names: dict[bytes, str] = {}
        stamp_len = _STAMP_LEN.unpack_from
        u32 = _U32.unpack_from
        seven = _SEVEN.unpack_from
        for _ in range(count):
            secs, nsecs, n = stamp_len(buf, pos + 4)
            pos += 16
            raw = buf[pos : pos + n]
            if len(raw) != n:
                raise struct.error("frame_id runs past the end")
            parent = names.get(raw)
            if parent is None:
                parent = names[raw] = raw.decode()
            pos += n
            (n,) = u32(buf, pos)
            pos += 4
            raw = buf[pos : pos + n]
            if len(raw) != n:
                raise struct.error("child_frame_id runs past the end")
            child = names.get(raw)
            if child is None:
                child = names[raw] = raw.decode()
            pos += n
            append((parent, child, secs * _NS + nsecs, *seven(buf, pos)))
            pos += 56
    except (struct.error, UnicodeDecodeError) as exc:
        raise DeserializationError(f"tf2_msgs/TFMessage: cannot decode {len(buf)} bytes: {exc}") from None
    return out


def encode_tf_message(items: Iterable[Sequence]) -> bytes:
    """Serialize ``(parent, child, stamp_ns, 7 floats)`` tuples as a TFMessage (header seq 0)."""
    parts = []
    count = 0
    for parent, child, stamp, *seven in items:
        p = parent.encode()
        c = child.encode()
        secs, nsecs = divmod(int(stamp), _NS)
        parts.append(_U32.pack(0) + _STAMP_LEN.pack(secs, nsecs, len(p)) + p + _U32.pack(len(c)) + c)
        parts.append(_SEVEN.pack(*seven))
        count += 1
    return _U32.pack(count) + b"".join(parts)


__all__ = ["decode_tf_message", "encode_tf_message"]
