"""Many TFMessages of one layout decoded at once with numpy.

A broadcaster sends the same frames in every message (a robot_state_publisher, an odometry node),
so consecutive ``/tf`` messages from it have the same byte layout: the same frame id strings at the
same offsets, only numbers changing. :class:`Layout` learns that layout from one message and then
reads the stamps and the 7 numbers of every transform of ``k`` such messages with three numpy
gathers over their concatenated bytes, after checking (also vectorized) that every frame id string
is the expected one. Anything that does not match goes back to the per-message decoder.
"""

from __future__ import annotations

import numpy

from ninjemys.tf2.wire import decode_tf_message

_NS = 1_000_000_000


class Layout:
    """The byte layout of one TFMessage: where each transform's stamp, ids and numbers are."""

    __slots__ = ("length", "parents", "children", "stamp_idx", "value_idx", "text_idx", "text")

    def __init__(self, data: bytes) -> None:
        """Learn the layout of ``data`` (raises DeserializationError when it does not decode)."""
        items = decode_tf_message(data)
        self.length = len(data)
        self.parents = [it[0] for it in items]
        self.children = [it[1] for it in items]
        stamp_idx: list[int] = []
        value_idx: list[int] = []
        text_idx: list[int] = []
        pos = 4
        for parent, child in zip(self.parents, self.children, strict=True):
            p = parent.encode()
            c = child.encode()
            stamp_idx.extend(range(pos + 4, pos + 12))  # secs, nsecs (after the seq)
            pos += 12
            text_idx.extend(range(pos, pos + 4 + len(p)))  # the length and the bytes of frame_id
            pos += 4 + len(p)
            text_idx.extend(range(pos, pos + 4 + len(c)))
            pos += 4 + len(c)
            value_idx.extend(range(pos, pos + 56))
            pos += 56
        self.stamp_idx = numpy.array(stamp_idx, dtype=numpy.intp)
        self.value_idx = numpy.array(value_idx, dtype=numpy.intp)
        self.text_idx = numpy.array(text_idx, dtype=numpy.intp)
        self.text = numpy.frombuffer(data, dtype=numpy.uint8)[self.text_idx]

    def matches(self, data: bytes) -> bool:
        """Cheap pre-check: same length and same transform count (the full check is in :meth:`read`)."""
        return len(data) == self.length and data[:4] == len(self.parents).to_bytes(4, "little")

    def read(self, messages: list[bytes]) -> tuple[numpy.ndarray, numpy.ndarray] | None:
        """``(stamps (k, n) int64 ns, values (k, n, 7) float64)`` of ``k`` messages of this layout, or
        None when some message's frame ids differ from the layout's."""
        raw = numpy.frombuffer(b"".join(messages), dtype=numpy.uint8).reshape(len(messages), self.length)
        if not (raw[:, self.text_idx] == self.text).all():
            return None
        n = len(self.parents)
        secs = raw[:, self.stamp_idx].copy().view("<u4").reshape(len(messages), n, 2).astype(numpy.int64)
        stamps = secs[:, :, 0] * _NS + secs[:, :, 1]
        values = raw[:, self.value_idx].copy().view("<f8").reshape(len(messages), n, 7)
        return stamps, values


def valid(values: numpy.ndarray, tolerance: float) -> bool:
    """True when every number is finite and every quaternion is of unit length (within ``tolerance``)."""
    if not numpy.isfinite(values).all():
        return False
    q = values[:, :, 3:]
    return bool((numpy.abs((q * q).sum(axis=2) - 1.0) < tolerance).all())


__all__ = ["Layout", "valid"]
