"""Publishing over TCPROS: one Publication per topic per node, any number of Publisher handles.

The publish path is built for latency and throughput:

* the message is serialized once, in the caller's thread, whatever the number of subscribers (so
  the caller may modify it afterwards, as in rospy);
* for each connection whose queue is empty the frame is written straight to the (non-blocking)
  socket from the caller's thread: no hand-off, no wake-up of another thread;
* only when the kernel buffer is full does the frame wait in the connection's queue; the I/O loop
  then drains the queue in batches (many frames joined into one ``send``).
* ``queue_size=N`` bounds each connection's queue and drops the oldest frame; ``queue_size=None``
  waits until the queue has drained (synchronous, lossless, as rospy).

A slow subscriber therefore costs the publisher nothing but its own connection's queue.
Latching is per Publisher handle: a new subscriber receives the last message of every latched
handle of the topic right after the connection header (ROS 1 kept one per topic per process).
"""

from __future__ import annotations

import itertools
import logging
import select
import socket
import threading
import time
from collections import deque
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

from ninjemys.errors import SerializationError, ShutdownError
from ninjemys.node import transport
from ninjemys.wire import headers
from ninjemys.wire.tcpros import pack_len

if TYPE_CHECKING:
    from ninjemys.node.node import Node

_log = logging.getLogger(__name__)

#: Connection ids for getBusStats/getBusInfo, unique in the process.
connection_ids = itertools.count(1)

#: Most bytes joined into one send when the loop drains a queue.
_BATCH_BYTES = 1 << 20
#: Publishes closer together than this (seconds) are batched by the loop instead of sent directly.
HOT_INTERVAL = 50e-6
#: In a burst, the publishing thread itself writes once this many frames are queued.
_FLUSH_FRAMES = 32
#: queue_size=None: frames queued before publish() waits for the loop to drain them.
_SYNC_HIGH_WATER = 256
_SYNC_HIGH_WATER_BYTES = 8 << 20
#: Payloads at least this big are sent with sendmsg (prefix and payload unjoined).
_LARGE = 1 << 16
_clock = time.perf_counter


class PubConnection:
    """One subscriber of one topic: a non-blocking socket plus the frames the kernel did not take yet."""

    def __init__(self, node: Node, sock: socket.socket, topic: str, subscriber: str, uri: str = "") -> None:
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
        self._cond = threading.Condition(self._lock)
        self._partial: memoryview | None = None  # the head frame, partly written
        self._queue: deque[bytes] = deque()
        self._armed = False  # the loop watches the socket for writability
        self._last = 0.0  # time of the previous send (detects bursts)
        self._queued_bytes = 0

    def send(self, data: bytes, queue_size: int | None) -> None:
        """Queue ``data`` (one or more frames) for this subscriber; never blocks unless queue_size is None.

        An idle connection is written to directly (lowest latency). While publishes come faster than
        one per :data:`HOT_INTERVAL`, frames are queued instead and the loop sends them in batches:
        one system call and one wake-up of the subscriber per batch instead of per message.
        """
        with self._lock:
            if self.closed:
                return
            now = _clock()
            hot = now - self._last < HOT_INTERVAL
            self._last = now
            if self._partial is None and not self._queue and not hot:
                try:
                    n = self.sock.send(data)
                except (BlockingIOError, InterruptedError):
                    n = 0
                except OSError as exc:
                    self._fail(f"write failed: {exc}")
                    return
                self.bytes_sent += n
                if n == len(data):
                    self.num_sent += 1
                    return
                self._partial = memoryview(data)[n:]
            else:
                queue = self._queue
                queue.append(data)
                self._queued_bytes += len(data)
                if queue_size and len(queue) > queue_size:
                    self._queued_bytes -= len(queue.popleft())
                    self.dropped += 1
                if self._partial is None and len(queue) >= _FLUSH_FRAMES and self._write_locked():
                    return  # a burst: this thread wrote a whole batch in one call
            if not self._armed:
                self._armed = True
                self.node.runtime.call_soon(self._arm)
            if queue_size is None and (
                len(self._queue) >= _SYNC_HIGH_WATER or self._queued_bytes >= _SYNC_HIGH_WATER_BYTES
            ):
                # synchronous publishing: wait for the loop to drain (lossless, bounded memory)
                while not self.closed and not (self._partial is None and not self._queue):
                    self._cond.wait()

    def send_large(self, prefix: bytes, payload: bytes, queue_size: int | None) -> None:
        """Like :meth:`send` for a big message: the length prefix and the payload leave in one
        ``sendmsg`` without being joined (a 6 MB image is not copied once more just to frame it)."""
        with self._lock:
            idle = self._partial is None and not self._queue and not self.closed
            if idle:
                self._last = _clock()
                try:
                    n = self.sock.sendmsg([prefix, payload])
                except (BlockingIOError, InterruptedError):
                    n = 0
                except OSError as exc:
                    self._fail(f"write failed: {exc}")
                    return
                self.bytes_sent += n
                if n == len(prefix) + len(payload):
                    self.num_sent += 1
                    return
                if n >= len(prefix):
                    self._partial = memoryview(payload)[n - len(prefix) :]
                else:
                    self._partial = memoryview(prefix[n:] + payload)
                self.num_sent += 1
                if queue_size is not None and not self._armed:
                    self._armed = True
                    self.node.runtime.call_soon(self._arm)
        if not idle:
            self.send(prefix + payload, queue_size)
        elif queue_size is None:
            self._finish_in_caller()

    def _finish_in_caller(self) -> None:
        """Synchronous publishing of a big message: write the rest from the caller's thread as the
        kernel takes it (the subscriber's pace), like a blocking send, without involving the loop."""
        while True:
            with self._lock:
                partial = self._partial
                if self.closed or partial is None:
                    return
                try:
                    n = self.sock.send(partial)
                except (BlockingIOError, InterruptedError):
                    n = 0
                except OSError as exc:
                    self._fail(f"write failed: {exc}")
                    return
                self.bytes_sent += n
                if n == len(partial):
                    self._partial = None
                    if self._queue and not self._armed:
                        self._armed = True
                        self.node.runtime.call_soon(self._arm)
                    return
                self._partial = partial[n:]
            try:
                select.select([], [self.sock], [], 1.0)
            except (OSError, ValueError):
                pass  # closed under us: the next round sees it

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
            with self._cond:
                if not self.closed:
                    _log.debug("topic %s: %s (%s)", self.topic, why, self.subscriber)
                self._close_locked()

    def _arm(self) -> None:
        if self.closed:
            return
        try:
            self.node.runtime.loop.add_writer(self.fd, self._drain)
        except (ValueError, OSError) as exc:
            with self._cond:
                self._fail(f"cannot watch socket: {exc}")

    def _drain(self) -> None:
        """Writable: push the partial frame, then batches of queued frames (on the loop)."""
        with self._lock:
            if self.closed or not self._write_locked():
                return
            self._armed = False
            self.node.runtime.loop.remove_writer(self.fd)
            self._cond.notify_all()

    def _write_locked(self) -> bool:
        """Write what the kernel takes (lock held); True once nothing is left queued."""
        try:
            while True:
                if self._partial is None:
                    if not self._queue:
                        return True
                    self._partial = memoryview(self._take_batch())
                n = self.sock.send(self._partial)
                self.bytes_sent += n
                if n < len(self._partial):
                    self._partial = self._partial[n:]
                    return False
                self._partial = None
        except (BlockingIOError, InterruptedError):
            return False
        except OSError as exc:
            self._fail(f"write failed: {exc}")
            return False

    def _take_batch(self) -> bytes:
        queue = self._queue
        if len(queue) == 1:
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
        """Called with the lock held: log once, close, wake blocked publishers."""
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
        self._cond.notify_all()
        self.node.runtime.call_soon(self._release_socket)
        self.node.runtime.call_soon(self.node._topic_connection_closed, self)

    def _release_socket(self) -> None:
        loop = self.node.runtime.loop
        try:
            loop.remove_writer(self.fd)
            loop.remove_reader(self.fd)
        except (ValueError, OSError):
            pass
        transport.close_quietly(self.sock)

    def close(self) -> None:
        with self._cond:
            self._close_locked()


class Publication:
    """A topic this node publishes: type, connections, and the Publisher handles sharing them."""

    def __init__(self, node: Node, topic: str, msg_class: Any) -> None:
        self.node = node
        self.topic = topic
        self.msg_class = msg_class
        self.type_name: str = msg_class._type
        self.md5sum: str = msg_class._md5sum
        self.definition: str = getattr(msg_class, "_full_text", "")
        self.connections: tuple[PubConnection, ...] = ()
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
        nodelay = header.get("tcp_nodelay", "0") == "1"
        sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1 if nodelay else 0)
        conn = PubConnection(self.node, sock, self.topic, who)
        with self.lock:
            reply = headers.encode_header(self.reply_header({}))
            latched = b"".join(h.latched for h in self.handles if h.latch and h.latched is not None)
            conn.send(reply + latched, queue_size=0)
            conn.num_sent = 1 if latched else 0
            self.connections = (*self.connections, conn)
        conn.watch()

    def publish_frame(self, data: bytes, handle: Publisher) -> None:
        with self.lock:
            if handle.latch:
                handle.latched = data
            conns = self.connections
        queue_size = handle.queue_size
        for conn in conns:
            conn.send(data, queue_size)

    def publish_large(self, payload: bytes, handle: Publisher) -> None:
        prefix = pack_len(len(payload))
        with self.lock:
            if handle.latch:
                handle.latched = prefix + payload
            conns = self.connections
        queue_size = handle.queue_size
        for conn in conns:
            conn.send_large(prefix, payload, queue_size)

    def remove_connection(self, conn: PubConnection) -> None:
        with self.lock:
            if conn in self.connections:
                self.connections = tuple(c for c in self.connections if c is not conn)
                self.bytes_sent_closed += conn.bytes_sent

    def close(self) -> None:
        with self.lock:
            conns, self.connections = self.connections, ()
        for conn in conns:
            conn.close()


class Publisher:
    """A handle to publish on a topic; see :meth:`ninjemys.node.Node.publisher`."""

    def __init__(
        self,
        publication: Publication,
        queue_size: int | None,
        latch: bool,
        headers: Mapping[str, str] | None,
    ) -> None:
        self._pub = publication
        self.name = publication.topic
        self.resolved_name = publication.topic
        self.data_class = publication.msg_class
        self.type = publication.type_name
        self.md5sum = publication.md5sum
        self.queue_size = queue_size
        self.latch = latch
        self.headers = dict(headers or {})
        self.latched: bytes | None = None
        self._has_header = bool(getattr(publication.msg_class, "_has_header", False))
        self._seq = 0
        self._closed = False

    def publish(self, msg: Any) -> None:
        """Serialize ``msg`` once and send it to every subscriber (see the module docstring)."""
        if self._closed:
            raise ShutdownError(f"publisher of {self.name} is unregistered")
        if self._has_header:
            self._seq += 1  # rospy counts from 1
            msg.header.seq = self._seq
        try:
            payload = msg.serialize_to_bytes()
        except AttributeError:
            if not hasattr(msg, "serialize_to_bytes"):
                raise SerializationError(
                    f"topic {self.name}: expected a {self.type} message, got {type(msg).__name__}"
                ) from None
            raise
        if len(payload) >= _LARGE:
            self._pub.publish_large(payload, self)
        else:
            self._pub.publish_frame(pack_len(len(payload)) + payload, self)

    def publish_raw(self, payload: bytes | bytearray | memoryview) -> None:
        """Send already-serialized bytes (relays, bag play, AnyMsg)."""
        if self._closed:
            raise ShutdownError(f"publisher of {self.name} is unregistered")
        self._pub.publish_frame(pack_len(len(payload)) + bytes(payload), self)

    def get_num_connections(self) -> int:
        return len(self._pub.connections)

    def unregister(self) -> None:
        """Stop publishing; the last handle of a topic unregisters it from the master."""
        if self._closed:
            return
        self._closed = True
        self._pub.node._drop_publisher(self)

    @property
    def closed(self) -> bool:
        return self._closed
