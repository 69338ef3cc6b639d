"""``SHMROS``: TCPROS connections whose large messages travel through a shared-memory ring.

Negotiation (same shape as UNIXROS): a subscriber offers ``["SHMROS", host_identity]`` first in
``requestTopic``; a ninjemys publisher on the same host answers ``["SHMROS", host, port]``; rospy and
roscpp, which do not know the name, answer TCPROS from the next offer. The subscriber then sends the
usual connection header plus ``ninjemys_shm=<host identity>``; the publisher agrees in its reply
header (``ninjemys_shm=1``). Without that field in the reply the stream is plain TCPROS.

On an SHMROS stream every TCPROS frame starts with a tag byte: 0 = the message follows inline,
1 = a notice ``(slot u32, generation u64, offset u64, length u64)`` naming a span of a slot of the
ring (offset 0 except for loaned messages, :mod:`ninjemys.node.shm_loan`), 2 = the ring's
segment name (sent once, before the first notice: the ring is made with the first large message, so
a topic of small messages costs no segment, mapping or file descriptor). Messages of at
least :data:`THRESHOLD` bytes go through the ring; smaller ones inline, and so does a large one when
every slot is still held by the subscriber (a user keeping messages) or /dev/shm is full: the
publisher never waits for a slot and never overwrites one still referenced. ``queue_size`` applies
to notices exactly as to frames (a dropped notice frees its slot).

Why 64 KiB: below it a message costs about the same either way (two system calls dominate); above
it the socket's two copies and the kernel's wake-ups per 64 KiB grow with the size while the ring
costs one ``memcpy`` on the publisher and none on the subscriber.
"""

from __future__ import annotations

import logging
import os
import socket
import threading

from ninjemys.node import shm_ring, transport
from ninjemys.node.subscriber import SubConnection
from ninjemys.node.topics import PubConnection
from ninjemys.wire.tcpros import FrameReader, pack_len

TYPE_CHECKING = False
if TYPE_CHECKING:
    from collections.abc import Mapping
    from typing import Any

    from ninjemys.node.context import NodeContext
    from ninjemys.node.subscriber import Subscription

_log = logging.getLogger(__name__)

SHMROS = "SHMROS"
#: the connection-header field both sides use
FIELD = "ninjemys_shm"
#: payloads of at least this many bytes go through the ring (see the module docstring)
THRESHOLD = 64 * 1024
#: slots per connection and the largest payload a slot takes (tmpfs pages are allocated per slot as
#: it is first used, so an idle ring costs address space, not memory). 32 MiB fits a 4K rgb8 image.
SLOTS = 4
SLOT_SIZE = 32 << 20
#: a synchronous publisher (queue_size=None) waits this long for a slot before sending inline: its
#: subscriber is usually just behind (messages queued for its callback hold slots), not keeping them
SLOT_WAIT = 0.05
_INLINE = b"\0"


def enabled() -> bool:
    """On by default on Linux; ``NINJEMYS_SHM=0`` turns it off (then every stream is TCPROS/UNIXROS)."""
    return (
        os.environ.get("NINJEMYS_SHM", "1") != "0"
        and shm_ring.available()
        and bool(transport.host_identity())
    )


def offer() -> list[str] | None:
    """What a subscriber puts first in ``requestTopic``, or None when disabled."""
    return [SHMROS, transport.host_identity()] if enabled() else None


def grants(proto: list[Any]) -> bool:
    """A publisher's test of one ``requestTopic`` offer."""
    return proto[0] == SHMROS and proto[1:2] == [transport.host_identity()] and enabled()


def tag_inline(frame: bytes) -> bytes:
    """A plain TCPROS frame (length prefix + payload) as an SHMROS inline frame."""
    return pack_len(len(frame) - 3) + _INLINE + frame[4:]


def publisher_connection(
    node: NodeContext, sock: socket.socket, topic: str, subscriber: str, header: Mapping[str, str]
) -> tuple[PubConnection, dict[str, str]]:
    """The connection for an accepted subscriber and the extra reply-header fields: an SHMROS one when
    its header asks for it from this host, else plain TCPROS. The ring itself is made with the first
    large message (most topics never send one, and then cost no segment, mapping or descriptor)."""
    if header.get(FIELD) and header.get(FIELD) == transport.host_identity() and enabled():
        return ShmPubConnection(node, sock, topic, subscriber), {FIELD: "1"}
    return PubConnection(node, sock, topic, subscriber), {}


def announcement(name: str) -> bytes:
    """The frame that names a new ring to the subscriber (tag 2, then the segment name)."""
    body = name.encode()
    return pack_len(len(body) + 1) + bytes([shm_ring.RING_TAG]) + body


class ShmPubConnection(PubConnection):
    """A subscriber on this host: large messages into the ring, a notice on the socket."""

    #: frames below topics._LARGE (<= THRESHOLD) are always inline: the publication tags them itself
    tag_small = True

    @property
    def transport(self) -> str:
        """What getBusInfo reports (rosnode info shows it)."""
        return SHMROS

    def __init__(self, node: NodeContext, sock: socket.socket, topic: str, subscriber: str) -> None:
        super().__init__(node, sock, topic, subscriber)
        self.ring: shm_ring.WriterRing | None = None
        self._no_ring = False  # the ring could not be made: inline for good
        self._ring_lock = threading.Lock()

    def _ring(self) -> shm_ring.WriterRing | None:
        """The ring, made and announced on first use (the announcement precedes every notice: the
        ring is visible to other publishing threads only once it is queued)."""
        ring = self.ring
        if ring is not None or self._no_ring:
            return ring
        with self._ring_lock:
            if self.ring is None and not self._no_ring and not self.closed:
                try:
                    ring = shm_ring.WriterRing(SLOTS, SLOT_SIZE)
                except shm_ring.ShmError as exc:
                    _log.info(
                        "topic %s: shared memory unavailable for %s (%s): inline",
                        self.topic,
                        self.subscriber,
                        exc,
                    )
                    self._no_ring = True
                    return None
                PubConnection.send(self, announcement(ring.name), 0)
                self.ring = ring
                if self.closed:  # closed meanwhile: _release_socket may have missed it
                    ring.close()
        return self.ring

    def send_hello(self, reply: bytes, latched: list[bytes]) -> None:
        """The reply header (untagged, as in TCPROS) then latched frames, tagged inline."""
        PubConnection.send(self, reply + b"".join(tag_inline(f) for f in latched), 0)

    def send(self, data: bytes, queue_size: int | None) -> None:
        length = len(data) - 4
        if length < THRESHOLD:  # inline: tag_inline written out, in one copy (every small message)
            PubConnection.send(
                self, b"".join((pack_len(length + 1), _INLINE, memoryview(data)[4:])), queue_size
            )
            return
        ring = self._ring() if not self.closed else None
        if ring is not None:
            notice = ring.put([memoryview(data)[4:]], length, SLOT_WAIT if queue_size is None else 0.0)
            if notice is not None:
                PubConnection.send(self, notice, queue_size)
                return
        PubConnection.send(self, tag_inline(data), queue_size)

    def send_parts(self, parts: list[Any], total: int, queue_size: int | None) -> None:
        length = total - 4
        ring = self._ring() if length >= THRESHOLD and not self.closed else None
        if ring is not None:
            notice = ring.put_lent(parts[1:], length) if ring.lending else None  # see shm_loan
            if notice is None:
                notice = ring.put(parts[1:], length, SLOT_WAIT if queue_size is None else 0.0)
            if notice is not None:
                PubConnection.send(self, notice, queue_size)
                return
        PubConnection.send(self, b"".join([pack_len(length + 1), _INLINE, *parts[1:]]), queue_size)

    def _trim(self, queue_size: int) -> None:
        """queue_size drops the oldest frames as over TCPROS, and frees the slots of dropped notices;
        a ring's announcement is never dropped (the notices after it name its slots)."""
        queue = self._queue
        kept: list[bytes] = []
        while len(queue) > queue_size:
            frame = queue.popleft()
            if shm_ring.is_announcement(frame):
                kept.append(frame)
                continue
            self._queued_bytes -= len(frame)
            self.dropped += 1
            if shm_ring.is_notice(frame) and self.ring is not None:
                self.ring.reclaim(frame)
        queue.extendleft(reversed(kept))

    def _release_socket(self) -> None:
        super()._release_socket()
        with self._ring_lock:
            ring, self._no_ring = self.ring, True
        if ring is not None:
            ring.close()


def subscriber_connection(
    sub: Subscription, sock: socket.socket, uri: str, header: Mapping[str, str]
) -> SubConnection:
    """The connection for a publisher's reply header: SHMROS when it names a ring (ShmError when that
    ring cannot be mapped: the caller retries over TCPROS), else plain TCPROS."""
    if not header.get(FIELD):
        return SubConnection(sub, sock, uri, header)
    return ShmSubConnection(sub, sock, uri, header)


class ShmSubConnection(SubConnection):
    """A publisher on this host: tagged frames; notices become read-only views into the ring."""

    @property
    def transport(self) -> str:
        """What getBusInfo reports (rosnode info shows it)."""
        return SHMROS

    def __init__(
        self,
        sub: Subscription,
        sock: socket.socket,
        uri: str,
        header: Mapping[str, str],
    ) -> None:
        super().__init__(sub, sock, uri, header)
        self.ring: shm_ring.ReaderRing | None = None  # mapped when the publisher announces it
        self._reader = FrameReader(tagged=True)  # small inline messages come untagged already

    tagged = True

    def read(self, budget: int | None = None, first: int | None = None) -> list[bytes | bytearray] | None:
        last = self.last
        frames = super().read(budget, first)
        if not frames:
            return frames
        out = self.untag(frames)
        if self.latching and out is not None:  # the latched message, not the tagged frame super() kept
            self.last = out[-1] if out else last
        return out

    def untag(self, frames: list[Any]) -> list[Any] | None:
        """Frames cut by the tagged reader -> the messages' bytes: inline ones as they are, notices as
        read-only views into the ring, the ring's announcement mapped. None (the connection closed,
        after one line) when the stream is malformed and nothing came before."""
        reader = self._reader
        if not reader.special:
            return frames  # small inline messages only: cut without their tag by the reader
        reader.special = 0
        out: list[Any] = []
        for frame in frames:
            if frame.__class__ is bytes:  # inline, tag dropped by the reader
                out.append(frame)
                continue
            tag = frame[0] if frame else -1
            if tag == shm_ring.INLINE_TAG:
                out.append(frame[1:] if len(frame) < THRESHOLD else memoryview(frame)[1:])
            elif tag == shm_ring.NOTICE_TAG:
                try:
                    if self.ring is None:
                        raise shm_ring.ShmError("a notice before any ring was announced")
                    out.append(self.ring.view(frame))
                except shm_ring.ShmError as exc:
                    self._malformed(str(exc))
                    return out or None
            elif tag == shm_ring.RING_TAG:
                try:
                    if self.ring is not None:
                        raise shm_ring.ShmError("a second ring announced")
                    self.ring = shm_ring.ReaderRing(bytes(frame[1:]).decode("utf-8", "replace"))
                except shm_ring.ShmError as exc:
                    self._malformed(str(exc))
                    return out or None
            else:
                self._malformed(f"a frame with tag {tag}")
                return out or None
        return out

    def _malformed(self, why: str) -> None:
        """One line, then close; the subscription reconnects over TCPROS (inline from then on)."""
        _log.warning(
            "topic %s: malformed shared-memory notice from %s: %s; closing, reconnecting over TCPROS",
            self.sub.topic,
            self.publisher,
            why,
        )
        self.sub.shm_refused.add(self.uri)
        self.close()
        self.sub.node.runtime.call_soon(self.sub.connection_lost, self, True)
