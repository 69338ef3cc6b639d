"""TCPROS framing (sans-IO): length-prefixed messages and service responses.

* A topic message and a service request are ``uint32 len`` + body.
* A service response is ``uint8 ok`` then ``uint32 len`` + body; when ok is 0 the body is the
  error string (rospy ``tcpros_service.py``).

:class:`FrameReader` is the receive side built for speed: the caller ``recv_into`` the buffer it
hands out and then asks for the complete frames. Small frames are cut from one preallocated buffer;
a large frame gets a buffer of exactly its size that the socket fills directly, and that buffer is
handed over as the frame (one copy from the kernel, none in Python).
"""

from __future__ import annotations

import struct
from collections.abc import Callable

from ninjemys.errors import ProtocolError

#: Largest message we accept on a connection. ROS 1 has no limit; 1 GiB keeps a bogus prefix from
#: exhausting memory while allowing any real point cloud or image.
MAX_FRAME_LEN = 1 << 30

_U32 = struct.Struct("<I")
#: The head of a service response: ``uint8 ok`` then ``uint32 len`` of the body that follows.
SERVICE_RESPONSE_HEAD = struct.Struct("<BI")
_pack_response_head = SERVICE_RESPONSE_HEAD.pack
pack_len = _U32.pack


def frame(payload: bytes | bytearray | memoryview) -> bytes:
    """``uint32 len`` + payload as one bytes object."""
    return _U32.pack(len(payload)) + payload


def encode_service_response(ok: bool, payload: bytes | str) -> bytes:
    """A service response: ok byte, then the framed body (or the framed error text when not ok)."""
    body = payload.encode("utf-8", "replace") if isinstance(payload, str) else payload
    return _pack_response_head(1 if ok else 0, len(body)) + body


def decode_length(prefix: bytes | bytearray | memoryview, limit: int = MAX_FRAME_LEN) -> int:
    """The length in a 4-byte prefix, refusing values above ``limit`` before anything is allocated."""
    (n,) = _U32.unpack(prefix)
    if n > limit:
        raise ProtocolError(f"message length prefix {n} exceeds the {limit}-byte limit")
    return n


class TaggedFrame(bytes):
    """A frame of a tagged stream (see :class:`FrameReader`) whose first byte is a tag other than 0."""

    __slots__ = ()


class FrameReader:
    """Incremental decoder of ``uint32 len`` + body frames fed by ``recv_into``.

    Usage: ``n = sock.recv_into(reader.buffer())``; ``frames = reader.commit(n)``. ``buffer()``
    returns a writable view of where the next bytes belong; ``commit`` returns every frame completed
    so far as ``bytes`` (small) or ``bytearray`` (large, received in place).

    ``tagged=True`` is for streams whose bodies start with a tag byte (SHMROS): a small frame tagged 0
    comes back as ``bytes`` without its tag (cut in the same copy), any other small frame as a
    :class:`TaggedFrame` with its tag, a large frame as a ``bytearray`` with its tag; ``special``
    counts the frames that are not plain ``bytes`` (the caller resets it), so a stream of small
    inline messages costs its reader no second pass over the frames.
    """

    __slots__ = (
        "_buf", "_view", "_start", "_end", "_big", "_big_view", "_big_fill", "_limit", "_large", "_skip",
        "special", "whole",
    )  # fmt: skip

    def __init__(self, size: int = 1 << 16, limit: int = MAX_FRAME_LEN, tagged: bool = False) -> None:
        self._buf = bytearray(size)
        self._view = memoryview(self._buf)
        #: the whole buffer: what :meth:`buffer` returns when no frame is pending (a read that gets it
        #: starts at a frame boundary, and what it receives is ``whole[:n]``)
        self.whole = self._view
        self._start = 0  # first unconsumed byte
        self._end = 0  # end of valid data
        self._big: bytearray | None = None  # a large frame being received in place
        self._big_view: memoryview | None = None
        self._big_fill = 0
        self._limit = limit
        self._large = size // 2  # frames at least this long are received in place
        self._skip = 5 if tagged else 4  # the body of a plain frame starts here (tag 0 dropped)
        self.special = 0

    def buffer(self) -> memoryview:
        """Where the next received bytes should go (never empty)."""
        if self._big_view is not None:
            return self._big_view[self._big_fill :]
        end = self._end
        if not end:
            return self._view
        if end == len(self._buf):
            self._compact()
        return self._view[self._end :]

    def _compact(self) -> None:
        pending = self._end - self._start
        if self._start:
            self._view[:pending] = self._view[self._start : self._end]
            self._start, self._end = 0, pending
        if pending == len(self._buf):
            # a frame header plus body larger than the buffer but below the in-place threshold
            # cannot happen (threshold is half the buffer); a full buffer of prefix bytes can't either
            raise ProtocolError("receive buffer overflow")

    def commit(self, n: int) -> list[bytes | bytearray]:
        """Account for ``n`` freshly received bytes and return the frames now complete."""
        if not self._end and n > 4 and self._big is None:  # one whole frame in one read: the usual case
            (length,) = _U32.unpack_from(self._buf, 0)
            if length == n - 4 and (self._skip == 4 or not self._buf[4]):  # (tagged: an inline frame)
                return [self._view[self._skip : n].tobytes()]
        frames: list[bytes | bytearray] = []
        if self._big is not None:
            self._big_fill += n
            if self._big_fill < len(self._big):
                return frames
            frames.append(self._big)
            self._big = self._big_view = None
            self._big_fill = 0
            if self._skip == 5:
                self.special += 1
            return frames
        self._end += n
        return self._cut(frames)

    def _cut(self, frames: list[bytes | bytearray]) -> list[bytes | bytearray]:
        """Append the complete frames between ``_start`` and ``_end`` to ``frames``; keep the rest."""
        buf, view, start, end = self._buf, self._view, self._start, self._end
        unpack_from = _U32.unpack_from
        append = frames.append
        skip = self._skip
        while start + 4 <= end:
            (length,) = unpack_from(buf, start)
            stop = start + 4 + length
            if stop <= end:  # complete, so it fits the buffer: no limit to check
                if skip == 4 or (length and not buf[start + 4]):
                    append(view[start + skip : stop].tobytes())
                else:  # a tagged stream's frame with another tag (or none): kept whole
                    append(TaggedFrame(view[start + 4 : stop]))
                    self.special += 1
                start = stop
                continue
            start = self._incomplete(length, start, end)
            break
        if start == end:
            start = end = 0
        self._start, self._end = start, end
        return frames

    def _incomplete(self, length: int, start: int, end: int) -> int:
        """The frame at ``start`` (``length`` bytes of body) is not complete: refuse a length above the
        limit, and receive a large one in place. Returns where the unconsumed bytes start now."""
        if length > self._limit:
            raise ProtocolError(f"message length prefix {length} exceeds the {self._limit}-byte limit")
        if length >= self._large:
            have = end - start - 4
            big = bytearray(length)
            big[:have] = self._buf[start + 4 : end]
            self._big, self._big_view, self._big_fill = big, memoryview(big), have
            return end
        return start

    def commit_decoded(self, n: int, decode: Callable[[bytes, int, int, list, list], int], out: list,
                       bad: list) -> list[bytes | bytearray]:  # fmt: skip
        """Like :meth:`commit`, with the complete small frames decoded by ``decode`` (a generated
        ``decode_frames`` for this stream's tagging, see :mod:`ninjemys.idl.framedecode`) into ``out``
        and their failures into ``bad``. Returns the frames left undecoded, which follow ``out``'s
        and which the caller decodes itself: a large frame received in place, or on a tagged stream
        a frame with another tag than 0 and every frame after it in this read.

        The decoder reads an immutable copy of the bytes received (decoded arrays are views of it, so
        the buffer can be reused at once): one copy per read, not one per frame."""
        if self._big is not None:
            return self.commit(n)
        end = self._end + n
        start = self._start
        start += decode(self._view[start:end].tobytes(), 0, end - start, out, bad)
        if start == end:
            self._start = self._end = 0
            return []
        self._start, self._end = start, end
        return self._cut([])

    def commit_rest(self, start: int, n: int) -> list[bytes | bytearray]:
        """For a caller that received ``n`` bytes into :attr:`whole` (no frame was pending) and
        decoded the complete frames of the first ``start`` itself (as :meth:`commit_decoded` would):
        keep the rest and return the frames :meth:`commit_decoded` would have left undecoded."""
        self._start, self._end = start, n
        return self._cut([])

    @property
    def pending(self) -> int:
        """Bytes of an unfinished frame held (0 at a frame boundary): a disconnect with pending > 0
        means the peer died mid-message."""
        if self._big is not None:
            return 4 + self._big_fill
        return self._end - self._start
