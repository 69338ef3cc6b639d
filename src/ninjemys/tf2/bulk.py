"""Many TFMessages of one layout decoded at once with numpy.

A broadcaster sends the same frames in every message (a robot_state_publisher, an odometry node),
so consecutive ``/tf`` messages from it have the same byte layout: the same frame id strings at the
same offsets, only numbers changing. :class:`Layout` learns that layout from one message and then
reads the stamps and the 7 numbers of every transform of ``k`` such messages with a few numpy
operations over their concatenated bytes, after checking that every frame id string is the
expected one. Anything that does not match goes back to the per-message decoder.

The messages are joined with padding to a multiple of 8 bytes each (a row). The id check masks the
rows, as 64-bit words, down to the bytes of the ids and their lengths and compares the result with
the expected bytes in one ``memcmp``. The numbers are read through a strided view that sees every
row as overlapping 56-byte windows, one starting at each byte: picking the windows at the
transforms' offsets copies each transform's 7 doubles as one block (and 8-byte windows give the
stamps), a handful of numpy calls whatever the alignment, where gathering single bytes or doubles
costs per element or per alignment class. A listener asked 20 times a second reads a few
messages at a time, where these calls, not the bytes, are the cost.
"""

from __future__ import annotations

from math import isfinite

import numpy

from ninjemys.tf2.wire import decode_tf_message

_NS = 1_000_000_000
_U8 = numpy.uint8
_TO_NS = numpy.array([_NS, 1], dtype=numpy.int64)


class Layout:
    """The byte layout of one TFMessage: where each transform's stamp, ids and numbers are."""

    __slots__ = (
        "length",
        "parents",
        "children",
        "stride",
        "pad",
        "value_at",
        "stamp_at",
        "mask",
        "template",
        "frames",
        "children_frames",
        "last_row",
        "owed",
        "owed_base",
        "_masks",
        "_cells",
        "_entries",
    )

    def __init__(self, data: bytes) -> None:
        """Learn the layout of ``data`` (raises DeserializationError when it does not decode)."""
        items = decode_tf_message(data)
        self.length = len(data)
        self.parents = [it[0] for it in items]
        self.children = [it[1] for it in items]
        value_at: list[int] = []
        stamp_at: list[int] = []
        text_idx: list[int] = [0, 1, 2, 3]  # the transform count, then each id's length and bytes
        pos = 4
        for parent, child in zip(self.parents, self.children, strict=True):
            p = parent.encode()
            c = child.encode()
            stamp_at.append(pos + 4)  # secs, nsecs (after the seq)
            pos += 12
            text_idx.extend(range(pos, pos + 4 + len(p)))  # the length and the bytes of frame_id
            pos += 4 + len(p)
            text_idx.extend(range(pos, pos + 4 + len(c)))
            pos += 4 + len(c)
            value_at.append(pos)
            pos += 56
        self.stride = -(-self.length // 8) * 8  # each message padded to a multiple of 8 bytes
        self.pad = bytes(self.stride - self.length)
        self.value_at = numpy.array(value_at, dtype=numpy.intp)
        self.stamp_at = numpy.array(stamp_at, dtype=numpy.intp)
        row = numpy.frombuffer(data + self.pad, dtype=_U8)
        mask = numpy.zeros(self.stride, dtype=_U8)
        mask[text_idx] = 0xFF
        self.mask = mask  # one row's mask (0xFF on id bytes) and its expected masked bytes
        self.template = row & mask
        self._masks: dict[int, tuple[numpy.ndarray, bytes]] = {}
        self.frames: list | None = None  # (parent, child) frame objects, set by the buffer that reads it
        self.children_frames: list | None = None  # their children, in order
        #: the newest stamps this layout's batches wrote into every one of its frames (None: unknown)
        self.last_row: list[int] | None = None
        #: batches read but not yet in every frame's lists: ``(stamp columns, values, k, newest stamp)``
        self.owed: list[tuple[list[tuple[int, ...]], numpy.ndarray, int, int]] = []
        self.owed_base = 0  # how many batches were owed (and settled) before ``owed[0]``
        self._cells: dict[int, list[list[tuple[int, int]]]] = {}
        self._entries: dict[int, tuple] = {}

    def cells(self, k: int) -> list[list[tuple[int, int]]]:
        """Per transform ``j``, the indices ``(row, j)`` of its ``k`` entries in a batch's values array
        (made once per batch size: the buffer keeps them as lazy references to the numbers)."""
        got = self._cells.get(k)
        if got is None:
            if len(self._cells) > 64:
                self._cells.clear()
            got = self._cells[k] = [[(r, j) for r in range(k)] for j in range(len(self.parents))]
        return got

    @property
    def owed_end(self) -> int:
        """The count of batches ever owed: a frame whose ``applied`` equals it is up to date."""
        return self.owed_base + len(self.owed)

    def owe(self, columns: list[tuple[int, ...]], values: numpy.ndarray, k: int, newest: int) -> None:
        """Keep a checked batch of ``k`` messages (its stamps by transform, ``newest`` the newest of
        them) until its frames are settled."""
        self.owed.append((columns, values, k, newest))

    def expire(self, before: int) -> None:
        """Forget the owed batches whose stamps are all older than ``before``."""
        owed = self.owed
        n = 0
        while n < len(owed) and owed[n][3] < before:
            n += 1
        if n:
            del owed[:n]
            self.owed_base += n

    def forget_owed(self) -> None:
        """Every owed batch is settled (or cleared): start counting after them."""
        self.owed_base += len(self.owed)
        self.owed = []

    def entries(self, k: int) -> tuple[tuple[list, list], list[slice], list[None]]:
        """For a batch of ``k`` messages: the parent frame and the cell ``(row, j)`` of each of the
        ``k * n`` entries, transform by transform; the slice of each transform's entries in that
        order; and ``k`` Nones (made once per batch size, once :attr:`frames` is set)."""
        got = self._entries.get(k)
        if got is None:
            if len(self._entries) > 64:
                self._entries.clear()
            assert self.frames is not None
            parents = [pair[0] for pair in self.frames for _ in range(k)]
            cells = [(r, j) for j in range(len(self.frames)) for r in range(k)]
            slices = [slice(j * k, (j + 1) * k) for j in range(len(self.frames))]
            got = self._entries[k] = ((parents, cells), slices, [None] * k)
        return got

    def matches(self, data: bytes) -> bool:
        """Cheap pre-check: same length and same transform count (the full check is in :meth:`read`)."""
        return len(data) == self.length and data[:4] == len(self.parents).to_bytes(4, "little")

    def read(self, messages: list[bytes]) -> tuple[numpy.ndarray, numpy.ndarray] | None:
        """``(stamps (k, n) int64 ns, values (k, n, 7) float64)`` of ``k`` messages of this layout, or
        None when some message's frame ids differ from the layout's."""
        k = len(messages)
        stride = self.stride
        joined = self.pad.join(messages) + self.pad  # k rows of ``stride`` bytes
        mask, template = self._text(k)
        if (numpy.frombuffer(joined, dtype="<u8") & mask).tobytes() != template:
            return None
        n = len(self.parents)
        if not n:
            return numpy.zeros((k, 0), dtype=numpy.int64), numpy.zeros((k, 0, 7))
        windows = numpy.ndarray((k, stride - 55, 56), _U8, joined, 0, (stride, 1, 1))
        values = windows[:, self.value_at].view("<f8")  # (k, n, 56 bytes) seen as (k, n, 7) doubles
        words = numpy.ndarray((k, stride - 7, 8), _U8, joined, 0, (stride, 1, 1))
        return words[:, self.stamp_at].view("<u4") @ _TO_NS, values  # (secs, nsecs) . (1e9, 1)

    def _text(self, k: int) -> tuple[numpy.ndarray, bytes]:
        """The id mask of ``k`` rows as 64-bit words, and the bytes the masked rows must equal."""
        got = self._masks.get(k)
        if got is None:
            if len(self._masks) > 64:
                self._masks.clear()
            got = self._masks[k] = (
                numpy.tile(self.mask, k).view("<u8"),
                numpy.tile(self.template, k).tobytes(),
            )
        return got


def valid(values: numpy.ndarray, tolerance: float) -> bool:
    """True when every number is finite and every quaternion is of unit length (within ``tolerance``)."""
    # few numpy calls (on a few messages they, not the numbers, are the cost): a sum is finite only
    # if every number is (a finite sum that overflows is refused here and checked one by one)
    if not isfinite(values.sum()):
        return False
    q = values[:, :, 3:]
    norm = numpy.einsum("ijk,ijk->ij", q, q)  # one call: the sum over a trailing axis of 4 is slower
    return bool(norm.max() < 1.0 + tolerance and norm.min() > 1.0 - tolerance)


__all__ = ["Layout", "valid"]
