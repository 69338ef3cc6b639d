"""Publishing over TCPROS: one Publication per topic per node, any number of Publisher handles.

The publish path is built for latency and throughput:

* the message is serialized once, in the caller's thread, whatever the number of subscribers (so
  the caller may modify it afterwards, as in rospy);
* for each idle connection the frame is written straight to the (non-blocking) socket from the
  caller's thread: no hand-off, no wake-up of another thread;
* in a burst (a publish that starts less than ``HOT_INTERVAL`` after the previous one ended) frames
  are queued and the caller's thread
  writes them a batch at a time (many frames joined into one ``send``, one wake-up of the
  subscriber); the I/O loop only writes what is left once the burst ends, or what the kernel refused;
* ``queue_size=N`` bounds each connection's queue and drops the oldest frame; ``queue_size=None``
  makes the caller write the backlog itself, at the subscriber's pace, once it passes a high-water
  mark (synchronous, lossless, as rospy).

A slow subscriber therefore costs the publisher nothing but its own connection's queue.
Latching is per Publisher handle: a new subscriber receives the last message of every latched
handle of the topic right after the connection header (ROS 1 kept one per topic per process).
"""

from __future__ import annotations

import itertools
import logging
import select
import socket
import struct
import threading
import time
from collections import deque
from collections.abc import Callable, Mapping

from ninjemys.errors import SerializationError, ShutdownError
from ninjemys.net import auth
from ninjemys.node import transport
from ninjemys.node.intraprocess import Handoff, IntraLink, is_local_node
from ninjemys.wire import headers
from ninjemys.wire.tcpros import pack_len

TYPE_CHECKING = False  # importing typing costs ~7 ms of every node's start-up; checkers set it

if TYPE_CHECKING:
    from typing import Any

    from ninjemys.node.context import NodeContext
    from ninjemys.node.shm_loan import LoanedMessage

_log = logging.getLogger(__name__)

#: Connection ids for getBusStats/getBusInfo, unique in the process.
connection_ids = itertools.count(1)

#: Most bytes joined into one send when the loop drains a queue.
_BATCH_BYTES = 1 << 20
#: A publish that starts less than this (seconds) after the previous one's write ended is part of a
#: burst and batched instead of sent alone. Measured from the end of the write, not its start: a
#: flat-out loop comes back within a few microseconds, a ping-pong only after a whole round trip
#: (on this VM 3 us against 30 us and more), so a fast ping-pong is never mistaken for a burst.
#: A write that itself took this long counts from its start: the thread was off the CPU inside it
#: (on one CPU the reply to a ping can arrive before the ping's ``send`` returns).
HOT_INTERVAL = 20e-6
#: Within HOT_INTERVAL but at least this late (seconds), a Unix socket whose subscriber has read
#: everything is written at once (it waits for the frame); sooner, it is a burst without asking.
_SURE_BURST = 5e-6
#: A direct write that took at least this long (seconds) had the thread off the CPU inside it, so the
#: next publish's gap counts from its start. A small frame's ``send`` takes 2-4 us here; in a one-CPU
#: ping-pong the peer's whole turn can fit in the write's return (measured 12-19 us), after which a
#: subscriber that waits in ``recv`` gets the next ping and replies within _SURE_BURST of the write's
#: end: counted from there, 5 % of the replies were taken for a burst and left to the I/O loop.
_WRITE_OFF_CPU = 8e-6
#: In a burst, the publishing thread writes once this many frames are queued ...
_FLUSH_FRAMES = 32
#: ... or this long after the last try (seconds), so a slow trickle of a burst still goes out.
_MAX_HOLD = 200e-6
#: While a burst goes on, the loop looks at its leftovers this often (seconds).
_CHECK_INTERVAL = 1e-3
#: queue_size=None: frames queued before publish() writes the backlog itself ...
_SYNC_HIGH_WATER = 256
_SYNC_HIGH_WATER_BYTES = 8 << 20
#: ... and then writes until the backlog is down to this (the pipeline never runs dry).
_SYNC_LOW_WATER = 128
_SYNC_LOW_WATER_BYTES = 4 << 20
#: Frames at least this big are never held back to batch them.
_LARGE = 1 << 16
#: A big frame in more pieces than this is joined before sending (sendmsg takes at most IOV_MAX).
_MAX_PARTS = 64
#: A bounded publisher in a burst whose subscriber lags (the kernel refused a batch) and lives in this
#: same process sleeps this long once per refused batch, outside every lock: long enough (with the
#: kernel's timer slack, ~50 us) for a thread waiting for the GIL to take it. Without it a flat-out
#: publisher in the subscriber's own process holds the GIL between system calls too short for a
#: waiter to win (a Unix socket's send is ~2 us; loopback TCP's ~10 us hid this), and the reader
#: starved for tenths of a second. A subscriber in another process has its own GIL: no pause.
_LAG_YIELD = 20e-6
_clock = time.perf_counter
#: an SHMROS inline frame's head: its length prefix and the tag byte 0 (shm_link)
_pack_tagged_head = struct.Struct("<IB").pack


def _unsent(buffers: list[Any], sent: int) -> list[Any] | None:
    """What is left of ``buffers`` (one-byte items) after ``sent`` bytes were written; None if nothing."""
    for i, buf in enumerate(buffers):
        size = len(buf)
        if sent < size:
            rest = [memoryview(buf)[sent:]] if sent else [buf]
            return rest + buffers[i + 1 :]
        sent -= size
    return None


class PubConnection:
    """One subscriber of one topic: a non-blocking socket plus the frames the kernel did not take yet.

    Who writes: the publishing thread, always (directly when the connection is idle, a batch at a
    time in a burst, and until the kernel takes it when ``queue_size=None`` must block). The I/O loop
    only finishes what a burst leaves behind once the publisher goes quiet (:meth:`_check`) and drains
    a bounded queue the kernel refused (:meth:`_drain`). So a flood keeps one thread busy, not two
    threads fighting over the GIL and this connection's lock.
    """

    #: small frames go to this connection with a tag byte (SHMROS: see :meth:`Publication.publish_small`)
    tag_small = False

    def __init__(
        self, node: NodeContext, sock: socket.socket, topic: str, subscriber: str, uri: str = ""
    ) -> None:
        self.node = node
        self.sock = sock
        self.fd = sock.fileno()
        self.topic = topic
        self.subscriber = subscriber
        self.uri = uri
        self.id = next(connection_ids)
        self.bytes_sent = 0
        self.num_sent = 0
        self.dropped = 0
        self.closed = False
        self._lock = threading.Lock()
        self._partial: list[Any] | None = None  # buffers of the head frame(s) not written yet
        self._queue: deque[bytes] = deque()
        self._queued_bytes = 0
        self._tried = 0.0  # when this thread last tried to write a burst's queue (or it began)
        self._last = 0.0  # time of the previous publish (detects bursts)
        self._published = 0  # publishes so far; the loop's check compares it to see a burst go on
        self._seen = 0
        self._since_try = 0  # publishes queued since this thread last tried to write
        self._armed = False  # the loop waits for the socket to become writable
        self._checking = False  # a check of the queue is scheduled on the loop
        self._refused = False  # the kernel refused a burst's batch: the publisher yields once
        #: the subscriber is a Node of this process (shares our GIL): yield to it when it lags
        self._same_process = is_local_node(subscriber)
        #: Unix sockets: what the subscriber has not read yet (see :meth:`send`); None on TCP
        self._unread = transport.unread_probe(sock)

    @property
    def transport(self) -> str:
        """The transport name getBusInfo reports (TCPROS or UNIXROS)."""
        return transport.transport_of(self.sock)

    def send(self, data: bytes, queue_size: int | None) -> None:
        """Send ``data`` (one or more frames) to this subscriber; blocks only when ``queue_size`` is
        None and the kernel lags (synchronous, lossless: rospy's blocking send, with a short buffer).

        An idle connection is written to directly (lowest latency). A publish that comes less than
        :data:`HOT_INTERVAL` after the previous write is queued instead, and the queue is written
        :data:`_FLUSH_FRAMES` at a time, or :data:`_MAX_HOLD` after the last try: one system call and
        one wake-up of the subscriber per batch. Between :data:`_SURE_BURST` and
        :data:`HOT_INTERVAL`, over a Unix socket, a subscriber that has read everything (it waits for
        data) still gets the frame at once: a ping-pong is never held for the I/O loop.
        """
        with self._lock:
            if self.closed:
                return
            now = _clock()
            gap = now - self._last
            self._last = now
            self._published += 1
            if (
                self._partial is None
                and not self._queue
                and (
                    gap >= HOT_INTERVAL
                    or len(data) >= _LARGE
                    or (gap >= _SURE_BURST and self._unread is not None and not self._unread())
                )
            ):
                try:  # _write_direct, inlined: this is every idle publish's path
                    n = self.sock.send(data)
                except (BlockingIOError, InterruptedError):
                    n = 0
                except OSError as exc:
                    self._fail(f"write failed: {exc}")
                    return
                self.bytes_sent += n
                self.num_sent += 1
                if n == len(data):
                    end = _clock()
                    if end - now < _WRITE_OFF_CPU:
                        # the next publish's gap counts from the end of this write; unless the write
                        # took a burst's whole gap (this thread was off the CPU inside it, and the
                        # subscriber ran: on one CPU a ping-pong's reply can come back before send
                        # returns): then from its start, or the next ping would look like a burst
                        self._last = end
                    return
                self._partial = [memoryview(data)[n:]]
                if queue_size is not None or len(data) < _LARGE:
                    self._kernel_full()
                    return
                must_wait = True  # a big synchronous message: finish it here, at the subscriber's pace
            else:
                queue = self._queue
                queued = len(queue)
                if (
                    queued
                    and (self._checking or self._armed)
                    and self._since_try < _FLUSH_FRAMES - 1
                    and now - self._tried <= _MAX_HOLD
                    and (
                        (not queue_size or queued < queue_size)
                        if queue_size is not None
                        else queued + 1 < _SYNC_HIGH_WATER
                        and self._queued_bytes + len(data) < _SYNC_HIGH_WATER_BYTES
                    )
                ):
                    # the middle of a burst: _enqueue's common case inlined (a flood's every publish
                    # but one in _FLUSH_FRAMES): no batch is due, no bound or high-water mark is
                    # reached, the loop's check is scheduled already: just queue it
                    queue.append(data)
                    self._queued_bytes += len(data)
                    self._since_try += 1
                    return
                must_wait = self._enqueue(data, queue_size, now)
        if must_wait:
            self._write_until_below(len(data) >= _LARGE)
        elif self._refused:
            self._refused = False
            time.sleep(_LAG_YIELD)  # let the lagging reader's thread have the GIL (see _LAG_YIELD)

    def send_hello(self, reply: bytes, latched: list[bytes]) -> None:
        """The reply header and the latched frames, as a new subscriber first gets them."""
        self.send(reply + b"".join(latched), queue_size=0)

    def send_parts(self, parts: list[Any], total: int, queue_size: int | None) -> None:
        """Like :meth:`send` for a big frame still in pieces (see ``Message.frame_parts``): an idle
        connection gets them in one ``sendmsg``, so the payload is never copied in Python."""
        with self._lock:
            if self.closed:
                return
            idle = self._partial is None and not self._queue
            if idle:
                self._last = _clock()
                self._published += 1
                n = self._write_direct(self.sock.sendmsg, parts)
                if n is None or n == total:
                    return
                rest = _unsent(parts, n)
                assert rest is not None  # n < total: part of the frame is left
                if queue_size is not None:
                    # the caller may change its buffers once publish returns: keep a copy of the rest
                    self._partial = [b"".join(rest)]
                    self._kernel_full()
                    return
                self._partial = rest
        if idle:
            self._write_until_below(True)  # synchronous: finish here, at the subscriber's pace
        else:
            self.send(b"".join(parts), queue_size)

    def _write_direct(self, write: Callable[[Any], int], data: Any) -> int | None:
        """One frame straight to an idle socket (lock held): bytes the kernel took, None if the
        connection failed (then it is closed)."""
        try:
            n = write(data)
        except (BlockingIOError, InterruptedError):
            n = 0
        except OSError as exc:
            self._fail(f"write failed: {exc}")
            return None
        self.bytes_sent += n
        self.num_sent += 1
        return n

    def _enqueue(self, data: bytes, queue_size: int | None, now: float) -> bool:
        """Queue a frame of a burst (lock held) and write a batch when one is due. True when a
        synchronous publisher must now wait for the kernel to take the backlog."""
        queue = self._queue
        if not queue:
            self._tried = now
        queue.append(data)
        self._queued_bytes += len(data)
        self._since_try += 1
        limit = queue_size or 0  # None and 0: unbounded
        over = 0 < limit < len(queue)
        # queue_size bounds only what waits because the kernel refused it (the subscriber lags), as
        # in ROS 1: a burst queued merely to batch its writes goes to the kernel before anything is
        # dropped. A refusal leaves a partial frame; until then, a queue past its bound is written now.
        if (
            (over and self._partial is None)
            or self._since_try >= _FLUSH_FRAMES
            or now - self._tried > _MAX_HOLD
        ):
            self._since_try = 0
            self._tried = now
            # what the kernel refuses stays queued: this thread tries again a batch later, and the
            # loop's check takes over once the burst ends (handing it to the loop now would have two
            # threads contend for the GIL and this lock for the rest of the burst)
            written = self._write_locked()
            self._refused = self._same_process and not written and self._partial is not None
        if over and len(queue) > limit:
            self._trim(limit)
        if (queue or self._partial is not None) and not self._checking and not self._armed:
            self._checking = True
            self._seen = self._published
            self.node.runtime.call_soon(self._check)
        return queue_size is None and (
            len(queue) >= _SYNC_HIGH_WATER or self._queued_bytes >= _SYNC_HIGH_WATER_BYTES
        )

    def _write_until_below(self, drained: bool) -> None:
        """Synchronous publishing: write from the caller's thread as the kernel takes it (the
        subscriber's pace), like a blocking send, without involving the loop; until everything is
        sent (``drained``) or the backlog is under the low-water marks (the publisher goes on
        serializing while the kernel still holds plenty to send)."""
        while True:
            with self._lock:
                if self.closed:
                    return
                self._write_locked()
                if self._partial is None and not self._queue:
                    return
                if not drained and (
                    len(self._queue) <= _SYNC_LOW_WATER and self._queued_bytes <= _SYNC_LOW_WATER_BYTES
                ):
                    return
            try:
                select.select([], [self.sock], [], 1.0)
            except (OSError, ValueError):
                pass  # closed under us: the next round sees it

    def _kernel_full(self) -> None:
        """The kernel refused part of a write (lock held): have the loop finish when writable."""
        if not self._armed:
            self._armed = True
            self.node.runtime.call_soon(self._arm)

    def _check(self) -> None:
        """On the loop, after a burst queued frames: write them once the publisher has gone quiet
        (while it keeps publishing it writes batches itself; look again in :data:`_CHECK_INTERVAL`)."""
        with self._lock:
            if self.closed or self._armed:
                self._checking = False
                return
            if self._published != self._seen:
                # the burst goes on (even if its last batch left nothing queued): stay scheduled
                # rather than be woken again by the next queued frame
                self._seen = self._published
                self.node.runtime.loop.call_later(_CHECK_INTERVAL, self._check)
                return
            self._checking = False
            if self._write_locked():
                return
            self._armed = True
        self._arm()

    def watch(self) -> None:
        """Notice a subscriber that goes away even while we have nothing to send (on the loop)."""
        self.node.runtime.loop.add_reader(self.fd, self._on_readable)

    def _on_readable(self) -> None:
        try:
            data = self.sock.recv(4096)
        except (BlockingIOError, InterruptedError):
            return
        except OSError as exc:
            data = b""
            why = f"connection error: {exc}"
        else:
            why = "subscriber closed the connection"
        if not data:
            with self._lock:
                if not self.closed:
                    _log.debug("topic %s: %s (%s)", self.topic, why, self.subscriber)
                self._close_locked()

    def _arm(self) -> None:
        if self.closed:
            return
        try:
            self.node.runtime.loop.add_writer(self.fd, self._drain)
        except (ValueError, OSError) as exc:
            with self._lock:
                self._fail(f"cannot watch socket: {exc}")

    def _drain(self) -> None:
        """Writable: push the partial frame, then batches of queued frames (on the loop)."""
        with self._lock:
            if self.closed or not self._write_locked():
                return
            self._armed = False
            self.node.runtime.loop.remove_writer(self.fd)

    def _write_locked(self) -> bool:
        """Write what the kernel takes (lock held); True once nothing is left queued."""
        try:
            while True:
                partial = self._partial
                if partial is None:
                    if not self._queue:
                        return True
                    batch = self._take_batch()
                    try:
                        n = self.sock.send(batch)
                    except (BlockingIOError, InterruptedError):
                        n = 0  # the batch is off the queue already: keep it as the partial frame(s)
                    self.bytes_sent += n
                    if n < len(batch):
                        self._partial = [memoryview(batch)[n:]]
                        return False
                    continue
                n = self.sock.sendmsg(partial)
                self.bytes_sent += n
                self._partial = _unsent(partial, n)
                if self._partial is not None:
                    return False
        except (BlockingIOError, InterruptedError):
            return False
        except OSError as exc:
            self._fail(f"write failed: {exc}")
            return False

    def _trim(self, queue_size: int) -> None:
        """Drop the oldest queued frames beyond ``queue_size`` (lock held); a frame the kernel has
        begun to take (``_partial``) is never dropped, or the stream would lose its framing."""
        queue = self._queue
        while len(queue) > queue_size:
            self._queued_bytes -= len(queue.popleft())
            self.dropped += 1

    def _take_batch(self) -> bytes:
        queue = self._queue
        if len(queue) == 1 or len(queue[0]) >= _BATCH_BYTES:  # never copy a big frame to join it
            self.num_sent += 1
            item = queue.popleft()
            self._queued_bytes -= len(item)
            return item
        parts, size = [], 0
        while queue and size < _BATCH_BYTES:
            item = queue.popleft()
            parts.append(item)
            size += len(item)
        self.num_sent += len(parts)
        self._queued_bytes -= size
        return b"".join(parts)

    def _fail(self, why: str) -> None:
        """Called with the lock held: log once and close (a publisher writing in its own thread sees it)."""
        if not self.closed:
            _log.info("topic %s: dropped subscriber %s: %s", self.topic, self.subscriber, why)
        self._close_locked()

    def _close_locked(self) -> None:
        if self.closed:
            return
        self.closed = True
        self._queue.clear()
        self._queued_bytes = 0
        self._partial = None
        self.node.runtime.call_soon(self._release_socket)
        # deferred: a connection fails under locks (accept sends its hello holding the publication's
        # lock, which connection_closed takes)
        self.node.runtime.defer(self.node.connection_closed, self)

    def _release_socket(self) -> None:
        loop = self.node.runtime.loop
        try:
            loop.remove_writer(self.fd)
            loop.remove_reader(self.fd)
        except (ValueError, OSError):
            pass
        transport.close_quietly(self.sock)

    def close(self) -> None:
        with self._lock:
            self._close_locked()


#: ``PubConnection.send`` itself, also for its subclasses (a frame already in their format)
_send = PubConnection.send


class Publication:
    """A topic this node publishes: type, connections, and the Publisher handles sharing them."""

    def __init__(self, node: NodeContext, topic: str, msg_class: Any) -> None:
        self.node = node
        self.topic = topic
        self.msg_class = msg_class
        self.type_name: str = msg_class._type
        self.md5sum: str = msg_class._md5sum
        self.definition: str = getattr(msg_class, "_full_text", "")
        self.connections: tuple[PubConnection, ...] = ()
        #: in-process subscribers (see ninjemys.node.intraprocess); replaced whole, like connections
        self.intra: tuple[IntraLink, ...] = ()
        self.handles: list[Publisher] = []
        self.lock = threading.Lock()
        self.bytes_sent_closed = 0

    def reply_header(self, extra: Mapping[str, str]) -> dict[str, str]:
        latching = any(h.latch for h in self.handles)
        fields = {
            "callerid": self.node.name,
            "topic": self.topic,
            "type": self.type_name,
            "md5sum": self.md5sum,
            "message_definition": self.definition,
            "latching": "1" if latching else "0",
        }
        for handle in self.handles:
            fields.update(handle.headers)
        fields.update(extra)
        return fields

    async def accept(self, sock: socket.socket, header: Mapping[str, str]) -> None:
        """A subscriber connected (on the loop): check its header, answer, start streaming."""
        error = headers.check_subscriber_header(header, self.topic, self.type_name, self.md5sum)
        who = header.get("callerid", transport.peer_name(sock))
        if error is not None:
            _log.warning("topic %s: refused subscriber %s: %s", self.topic, who, error)
            await transport.send_error_header(sock, error)
            transport.close_quietly(sock)
            return
        # TCP_NODELAY on every subscriber's socket, whatever its header asks (rospy subscribers ask
        # for "0" by default): this publisher joins a burst's frames into one send itself, so Nagle
        # would only hold back a small message behind the peer's delayed ACK (up to 40 ms); the
        # option is ours and leaves the bytes on the wire unchanged
        if sock.family != socket.AF_UNIX:
            sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        from ninjemys.node import shm_link  # SHMROS when asked for (it builds on this module)

        conn, extra = shm_link.publisher_connection(self.node, sock, self.topic, who, header)
        with self.lock:
            reply = headers.encode_header(auth.sign_fields(self.reply_header(extra)))
            frames = [f for f in (h.latched_frame() for h in self.handles if h.latch) if f is not None]
            conn.send_hello(reply, frames)
            if conn.closed:  # the subscriber hung up before its answer went out (logged by _fail)
                return
            conn.num_sent = 1 if frames else 0
            self.connections = (*self.connections, conn)
        conn.watch()

    def publish_frame(self, data: bytes, handle: Publisher, item: Handoff | None = None) -> None:
        if handle.latch:
            # under the lock: a subscriber being accepted gets either this frame latched or live
            with self.lock:
                handle.latched = data
                handle.latched_item = item
                conns = self.connections
        else:
            conns = self.connections  # a tuple, replaced whole when connections change
        queue_size = handle.queue_size
        for conn in conns:
            conn.send(data, queue_size)

    def publish_small(
        self, parts: list[Any], total: int, handle: Publisher, item: Handoff | None = None
    ) -> None:
        """A frame below :data:`_LARGE` in pieces: joined once for plain connections and once, with the
        inline tag byte, for SHMROS ones (which send every frame that small inline)."""
        if handle.latch:
            with self.lock:
                plain: bytes | None = b"".join(parts)
                handle.latched = plain
                handle.latched_item = item
                conns = self.connections
        else:
            conns = self.connections
            plain = None
        queue_size = handle.queue_size
        tagged = None
        for conn in conns:
            if conn.tag_small:
                if tagged is None:
                    head = parts[0]
                    parts[0] = _pack_tagged_head(total - 3, 0)  # the length prefix, then tag 0
                    tagged = b"".join(parts)
                    parts[0] = head
                PubConnection.send(conn, tagged, queue_size)
            else:
                if plain is None:
                    plain = b"".join(parts)
                conn.send(plain, queue_size)

    def publish_wire(self, msg: Any, wire: Callable[[Any, int], bytes], handle: Publisher) -> bool:
        """A message of a small generated type (``_wire_small``): its frame made in one piece by the
        generated ``_wire_frame`` (length prefix packed with the first fields), once untagged for plain
        connections and once tagged for SHMROS ones, then written to each. False, with nothing sent
        or latched, when the frame turns out big (a long string): the caller then takes the general
        path, which hands a big payload to the socket or the ring without copying it."""
        conns = self.connections
        tagged = plain = None
        if handle.latch:
            plain = wire(msg, 0)
            if len(plain) >= _LARGE:
                return False
            with self.lock:  # a subscriber being accepted gets either this frame latched or live
                handle.latched = plain
                handle.latched_item = Handoff(msg) if handle.intraprocess else None
                conns = self.connections
        elif conns and conns[0].tag_small:
            tagged = wire(msg, 1)
            if len(tagged) > _LARGE:  # the tag byte counts: the payload is what decides
                return False
        else:
            plain = wire(msg, 0)  # also with no subscriber: a bad message raises all the same
            if len(plain) >= _LARGE:
                return False
        queue_size = handle.queue_size
        for conn in conns:
            if conn.tag_small:
                if tagged is None:
                    tagged = wire(msg, 1)
                _send(conn, tagged, queue_size)  # already tagged: not ShmPubConnection.send
            else:
                if plain is None:
                    plain = wire(msg, 0)
                conn.send(plain, queue_size)
        return True

    def publish_parts(
        self, parts: list[Any], total: int, handle: Publisher, item: Handoff | None = None
    ) -> None:
        if handle.latch:
            with self.lock:
                handle.latched = b"".join(parts)
                handle.latched_item = item
                conns = self.connections
        else:
            conns = self.connections
        queue_size = handle.queue_size
        for conn in conns:
            conn.send_parts(parts, total, queue_size)

    def all_connections(self) -> list[PubConnection | IntraLink]:
        """Socket and in-process subscribers (getBusInfo, getBusStats)."""
        return [*self.connections, *self.intra]

    def publish_intra(self, item: Handoff, handle: Publisher) -> None:
        """Hand ``item`` to every in-process subscriber (the caller's thread, like a socket write)."""
        if handle.latch:
            with self.lock:
                handle.latched_item = item
                handle.latched = None  # serialized only if a socket subscriber comes for it
                links = self.intra
        else:
            links = self.intra
        queue_size = handle.queue_size
        for link in links:
            link.deliver(item, queue_size, True)

    def add_intra(self, link: IntraLink) -> None:
        """An in-process subscriber joined: it gets the latched messages first, as over a socket."""
        with self.lock:
            for h in self.handles:
                if h.latch:
                    item = h.latched_handoff()
                    if item is not None:
                        link.deliver(item)
            self.intra = (*self.intra, link)

    def remove_intra(self, link: IntraLink) -> None:
        with self.lock:
            if link in self.intra:
                self.intra = tuple(c for c in self.intra if c is not link)

    def remove_connection(self, conn: PubConnection) -> None:
        with self.lock:
            if conn in self.connections:
                self.connections = tuple(c for c in self.connections if c is not conn)
                self.bytes_sent_closed += conn.bytes_sent

    def close(self) -> None:
        with self.lock:
            conns, self.connections = self.connections, ()
            links = self.intra
        for conn in conns:
            conn.close()
        for link in links:
            link.close()


class Publisher:
    """A handle to publish on a topic; see :meth:`ninjemys.node.Node.publisher`."""

    def __init__(
        self,
        publication: Publication,
        queue_size: int | None,
        latch: bool,
        headers: Mapping[str, str] | None,
        intraprocess: bool = False,
    ) -> None:
        self._pub = publication
        #: the topic's Publication, shared by every handle of it (its ``connections`` and ``intra``
        #: tuples say who listens now, without a call: rospy.Publisher reads them per publish)
        self.publication = publication
        self.name = publication.topic
        self.resolved_name = publication.topic
        self.data_class = publication.msg_class
        self.type = publication.type_name
        self.md5sum = publication.md5sum
        self.queue_size = queue_size
        self.latch = latch
        self.headers = dict(headers or {})
        self.latched: bytes | None = None
        #: the latched message as in-process subscribers get it (with or instead of ``latched``)
        self.latched_item: Handoff | None = None
        #: in-process subscribers that opted in too get the published object itself (never changed after)
        self.intraprocess = intraprocess
        self._has_header = bool(getattr(publication.msg_class, "_has_header", False))
        #: the generated one-piece frame builder of a small type (see Publication.publish_wire)
        self._wire: Callable[[Any, int], bytes] | None = (
            publication.msg_class._wire_frame
            if getattr(publication.msg_class, "_wire_small", False)
            else None
        )
        self._seq = 0
        self._closed = False

    def publish(self, msg: Any) -> None:
        """Serialize ``msg`` once and send it to every subscriber (see the module docstring)."""
        if self._closed:
            raise ShutdownError(f"publisher of {self.name} is unregistered")
        if self._has_header:
            self._seq += 1  # rospy counts from 1
            msg.header.seq = self._seq
        pub = self._pub
        if pub.intra:
            # the object itself for a publisher that opted in; else (or for socket subscribers too)
            # the bytes, serialized once for everyone
            frame = self._frame(msg) if pub.connections or not self.intraprocess else None
            body = None if frame is None else memoryview(frame)[4:]
            handoff = Handoff(msg if self.intraprocess else None, body)
            pub.publish_intra(handoff, self)
            if pub.connections:
                pub.publish_frame(self._frame(msg) if frame is None else frame, self, handoff)
            return
        wire = self._wire
        if wire is not None and msg.__class__ is self.data_class:
            conns = pub.connections
            if len(conns) == 1 and not self.latch:
                # one subscriber (the common case), publish_wire inlined: one call less per message
                conn = conns[0]
                tag = conn.tag_small
                frame = wire(msg, tag)
                if len(frame) - tag < _LARGE:
                    if tag:
                        _send(conn, frame, self.queue_size)  # already tagged: not ShmPubConnection.send
                    else:
                        conn.send(frame, self.queue_size)
                    return
            elif pub.publish_wire(msg, wire, self):
                return
        # a latched object an in-process subscriber that comes later may share
        item = Handoff(msg) if self.latch and self.intraprocess else None
        try:
            total, parts = msg.frame_parts()
        except AttributeError:
            if hasattr(msg, "frame_parts"):
                raise
            self._pub.publish_frame(self._frame_other(msg), self, item)
            return
        if total < _LARGE:
            self._pub.publish_small(parts, total, self, item)
        elif len(parts) <= _MAX_PARTS:
            self._pub.publish_parts(parts, total, self, item)
        else:
            self._pub.publish_frame(b"".join(parts), self, item)

    def loan(self, length: int, field: str | None = None, **fields: Any) -> LoanedMessage:
        """A message of this topic's type whose ``uint8[]`` array (``field``, found by itself when the
        type has one) of ``length`` bytes lives in a free shared-memory slot of an SHMROS subscriber:
        fill it, then :meth:`publish` sends only a slot notice (no copy). ``fields`` set the others.
        Falls back to a heap array when no slot is available; see :mod:`ninjemys.node.shm_loan`."""
        if self._closed:
            raise ShutdownError(f"publisher of {self.name} is unregistered")
        from ninjemys.node import shm_loan  # only a loaning publisher needs it

        return shm_loan.loan(self, length, field, fields)

    def _frame(self, msg: Any) -> bytes:
        """``msg``'s whole TCPROS frame in one buffer."""
        try:
            _, parts = msg.frame_parts()
        except AttributeError:
            if hasattr(msg, "frame_parts"):
                raise
            return self._frame_other(msg)
        return b"".join(parts)

    def latched_frame(self) -> bytes | None:
        """The latched message as a socket subscriber gets it (serialized now if only in-process
        subscribers had it so far)."""
        if self.latched is None and self.latched_item is not None:
            self.latched = self.latched_item.frame()
        return self.latched

    def latched_handoff(self) -> Handoff | None:
        """The latched message as an in-process subscriber gets it."""
        if self.latched_item is not None:
            return self.latched_item
        if self.latched is not None:
            return Handoff(None, memoryview(self.latched)[4:])
        return None

    def _frame_other(self, msg: Any) -> bytes:
        """A message class outside the generated ones that has only ``serialize_to_bytes`` (the
        contract's minimum, docs/CONTRACTS.md)."""
        if not hasattr(msg, "serialize_to_bytes"):
            raise SerializationError(
                f"topic {self.name}: expected a {self.type} message, got {type(msg).__name__}"
            )
        payload = msg.serialize_to_bytes()
        return pack_len(len(payload)) + payload

    def publish_raw(self, payload: bytes | bytearray | memoryview) -> None:
        """Send already-serialized bytes (relays, bag play, AnyMsg)."""
        if self._closed:
            raise ShutdownError(f"publisher of {self.name} is unregistered")
        self.publish_framed(pack_len(len(payload)) + bytes(payload))

    def publish_framed(self, frame: bytes) -> None:
        """Send a TCPROS frame built by the caller (``uint32`` length, then the serialized message):
        :meth:`publish_raw` without its copy, for a node that packs the length with the message
        (robot_state_publisher's plans, whose messages have a constant size)."""
        if self._closed:
            raise ShutdownError(f"publisher of {self.name} is unregistered")
        if self._pub.intra:
            item = Handoff(None, memoryview(frame)[4:])
            self._pub.publish_intra(item, self)
            self._pub.publish_frame(frame, self, item)
            return
        conns = self._pub.connections
        if len(conns) == 1 and not self.latch:  # one subscriber: publish_frame inlined (a call less)
            conns[0].send(frame, self.queue_size)
            return
        self._pub.publish_frame(frame, self)

    def get_num_connections(self) -> int:
        return len(self._pub.connections) + len(self._pub.intra)

    def subscriber_ids(self) -> frozenset[str]:
        """Caller ids of the subscribers connected now (handshake done: what is published reaches them)."""
        conns: tuple[Any, ...] = (*self._pub.connections, *self._pub.intra)
        return frozenset(c.subscriber for c in conns if not c.closed)

    def unregister(self) -> None:
        """Stop publishing; the last handle of a topic unregisters it from the master."""
        if self._closed:
            return
        self._closed = True
        self._pub.node.release_publisher(self)

    @property
    def closed(self) -> bool:
        return self._closed
