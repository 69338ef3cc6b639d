"""Many TFMessages of one layout decoded at once with numpy.

A broadcaster sends the same frames in every message (a robot_state_publisher, an odometry node),
so consecutive ``/tf`` messages from it have the same byte layout: the same frame id strings at the
same offsets, only numbers changing. :class:`Layout` learns that layout from one message and then
reads the stamps and the 7 numbers of every transform of ``k`` such messages with a few numpy
gathers over their concatenated bytes, after checking (also vectorized) that every frame id string
is the expected one. Anything that does not match goes back to the per-message decoder.

The numbers are gathered as whole doubles (and the stamps as whole uint32), not byte by byte: the
messages are joined with padding to a multiple of 8 bytes each, so a number at byte offset ``p`` of
a message is element ``(p - p % 8) / 8`` of that row in the float64 view of the buffer shifted by
``p % 8``; one gather per distinct shift (at most 8) reads them all, 8 times fewer elements than
gathering bytes. Runs of up to ``SMALL_RUN`` messages (a node that looks transforms up often drains a
few at a time) are gathered byte by byte instead, in one numpy call per kind: there the number of
calls, not of bytes, is the cost.
"""

from __future__ import annotations

import numpy

from ninjemys.tf2.wire import decode_tf_message

_NS = 1_000_000_000
# up to this many messages the numbers are gathered byte by byte in one numpy call (a node that looks
# transforms up often decodes a few messages at a time, where the calls cost more than the bytes)
SMALL_RUN = 24


class Layout:
    """The byte layout of one TFMessage: where each transform's stamp, ids and numbers are."""

    __slots__ = (
        "length",
        "parents",
        "children",
        "text_idx",
        "text",
        "stride",
        "pad",
        "values",
        "stamps",
        "frames",
        "_cells",
        "value_bytes",
        "stamp_bytes",
    )

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
        self.text_idx = numpy.array(text_idx, dtype=numpy.intp)
        self.text = numpy.frombuffer(data, dtype=numpy.uint8)[self.text_idx]
        self.stride = -(-self.length // 8) * 8  # each message padded to a multiple of 8 bytes
        self.pad = bytes(self.stride - self.length)
        self.values = _groups(value_idx[::8], 8)  # the first byte of every double
        self.stamps = _groups(stamp_idx[::4], 4)  # of every uint32 (secs, nsecs)
        self.value_bytes = numpy.array(value_idx, dtype=numpy.intp)
        self.stamp_bytes = numpy.array(stamp_idx, dtype=numpy.intp)
        self.frames: list | None = None  # (parent, child) frame objects, set by the buffer that reads it
        self._cells: dict[int, list[list[tuple[int, int]]]] = {}

    def cells(self, k: int) -> list[list[tuple[int, int]]]:
        """Per transform ``j``, the indices ``(row, j)`` of its ``k`` entries in a batch's values array
        (made once per batch size: the buffer keeps them as lazy references to the numbers)."""
        got = self._cells.get(k)
        if got is None:
            if len(self._cells) > 64:
                self._cells.clear()
            got = self._cells[k] = [[(r, j) for r in range(k)] for j in range(len(self.parents))]
        return got

    def matches(self, data: bytes) -> bool:
        """Cheap pre-check: same length and same transform count (the full check is in :meth:`read`)."""
        return len(data) == self.length and data[:4] == len(self.parents).to_bytes(4, "little")

    def read(self, messages: list[bytes]) -> tuple[numpy.ndarray, numpy.ndarray] | None:
        """``(stamps (k, n) int64 ns, values (k, n, 7) float64)`` of ``k`` messages of this layout, or
        None when some message's frame ids differ from the layout's."""
        k = len(messages)
        stride = self.stride
        # padded rows, plus 8 bytes so that every shifted view below has k whole rows
        joined = self.pad.join([*messages, bytes(8)])
        raw = numpy.frombuffer(joined, dtype=numpy.uint8, count=k * stride).reshape(k, stride)
        if not (raw[:, self.text_idx] == self.text).all():
            return None
        n = len(self.parents)
        if k <= SMALL_RUN:  # one byte gather each: fewer numpy calls than one per shift
            secs = raw.take(self.stamp_bytes, axis=1).view("<u4").reshape(k, n, 2).astype(numpy.int64)
            values = raw.take(self.value_bytes, axis=1).view("<f8").reshape(k, n, 7)
        else:
            secs = _gather(joined, k, stride, "<u4", self.stamps).reshape(k, n, 2).astype(numpy.int64)
            values = _gather(joined, k, stride, "<f8", self.values).reshape(k, n, 7)
        stamps = secs[:, :, 0] * _NS + secs[:, :, 1]
        return stamps, values


def _groups(offsets: list[int], size: int) -> list[tuple[int, numpy.ndarray, numpy.ndarray | None]]:
    """``(shift, element indices in a row of the view shifted by shift, output columns)`` for items of
    ``size`` bytes at byte ``offsets`` of a message; columns None when one shift covers them all."""
    by_shift: dict[int, tuple[list[int], list[int]]] = {}
    for col, off in enumerate(offsets):
        idx, cols = by_shift.setdefault(off % size, ([], []))
        idx.append(off // size)
        cols.append(col)
    if len(by_shift) == 1:
        ((shift, (idx, _cols)),) = by_shift.items()
        return [(shift, numpy.array(idx, dtype=numpy.intp), None)]
    return [
        (shift, numpy.array(idx, dtype=numpy.intp), numpy.array(cols, dtype=numpy.intp))
        for shift, (idx, cols) in sorted(by_shift.items())
    ]


def _gather(
    joined: bytes,
    k: int,
    stride: int,
    dtype: str,
    groups: list[tuple[int, numpy.ndarray, numpy.ndarray | None]],
) -> numpy.ndarray:
    """The items of :func:`_groups` from ``k`` padded rows of ``joined``, as a ``(k, items)`` array."""
    size = numpy.dtype(dtype).itemsize
    per_row = stride // size
    if len(groups) == 1:
        shift, idx, _ = groups[0]
        return numpy.frombuffer(joined, dtype=dtype, count=k * per_row, offset=shift).reshape(k, per_row)[
            :, idx
        ]
    out = numpy.empty((k, sum(len(g[1]) for g in groups)), dtype=dtype)
    for shift, idx, cols in groups:
        view = numpy.frombuffer(joined, dtype=dtype, count=k * per_row, offset=shift).reshape(k, per_row)
        out[:, cols] = view[:, idx]
    return out


def valid(values: numpy.ndarray, tolerance: float) -> bool:
    """True when every number is finite and every quaternion is of unit length (within ``tolerance``)."""
    if not numpy.isfinite(values).all():
        return False
    # the squares added column by column: numpy's sum over a trailing axis of 4 is several times slower
    qx, qy, qz, qw = values[:, :, 3], values[:, :, 4], values[:, :, 5], values[:, :, 6]
    norm = qx * qx + qy * qy + qz * qz + qw * qw
    return bool((numpy.abs(norm - 1.0) < tolerance).all())


__all__ = ["Layout", "valid"]
