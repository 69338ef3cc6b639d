"""Subscribing over TCPROS: the loop sets connections up, each Subscriber's worker thread does the rest.

After the header exchange (on the I/O loop) a publisher's socket is handed to the worker thread of
the topic's first Subscriber handle (the *reader*). That thread waits in its own selector on its
sockets and a wake-up pipe, reads with ``recv_into`` into a preallocated buffer, cuts frames,
queues them (bounded by ``queue_size``, oldest dropped first), deserializes and calls back. So:

* a message costs one thread wake-up between the kernel and the callback (no hop through the loop);
* a dropped message is never deserialized;
* callbacks never run on the I/O thread, and a slow callback delays only its own subscription;
* the socket is read only when the queue is empty, and then in rounds of what the kernel held when
  the round began, so ``queue_size=1`` really means "the latest message" whatever ``buff_size`` is
  (rospy's ros_comm#536 does not apply), and a publisher as fast as the reader cannot keep the
  worker reading instead of delivering (a sustained stream never starves the callback).

Further Subscriber handles of the same topic in the same node get the reader's frames through their
own queue and pipe.

A handle made with ``share=other`` has no thread of its own: ``other``'s worker (the *host*) polls its
sockets too and delivers its messages, so messages of several topics that arrive together cost one
wake-up instead of one per topic (on a VM a wake-up costs more CPU than decoding a small message).
The host's thread runs until every handle it serves is closed; a closed handle's connections go on
to the next handle of its topic, as a reader's do.

A handle made with ``lazy=period`` (a tf listener's ``/tf``: its data is needed only when a lookup
asks) does not wake per message: its worker reads what the kernel holds once ``period`` seconds
have passed since the sockets were last read, or as soon as one holds a quarter of its receive
buffer (``SO_RCVLOWAT``: the kernel wakes it then, so a publisher never finds the buffer full), and
a reader that needs the data now calls :meth:`Subscriber.pull`, which reads and delivers on the
caller's thread. :meth:`Subscriber.set_eager` makes the worker wake per message again while
someone waits for data. Where ``SO_RCVLOWAT`` cannot be set, a lazy handle wakes per message.
"""

from __future__ import annotations

import logging
import select
import selectors
import socket
import struct
import threading
import time
from collections import deque
from collections.abc import Callable, Mapping

from ninjemys.errors import NinjemysError, ProtocolError
from ninjemys.net import auth, xmlrpc_client
from ninjemys.node import intraprocess, slices, transport
from ninjemys.node.intraprocess import Handoff
from ninjemys.node.log import ERROR
from ninjemys.node.topics import connection_ids
from ninjemys.records import SlotRecord
from ninjemys.wire import headers
from ninjemys.wire.tcpros import FrameReader

TYPE_CHECKING = False  # importing typing costs ~7 ms of every node's start-up; checkers set it

if TYPE_CHECKING:
    from typing import Any

    from ninjemys.node.context import NodeContext

_log = logging.getLogger(__name__)

#: Bytes an unbounded subscription reads from one connection before delivering what it has.
_READ_BUDGET = 256 * 1024
#: An in-process publisher with queue_size=None waits while this many messages wait for an unbounded
#: handle, until no more than the low mark are left, looking every _LOCAL_WAIT seconds (TCPROS's
#: synchronous publishing, where the kernel's buffer is the bound).
_LOCAL_HIGH_WATER = 256
_LOCAL_LOW_WATER = 128
_LOCAL_WAIT = 100e-6
#: A worker with one stream waits for it in a blocking ``recv`` (see Subscriber._solo_rounds) once two
#: messages come less than half this many seconds apart, and at most this long (``SO_RCVTIMEO``): the
#: delay a connection add or release waits for, while that stream flows, before the worker sees it.
#: Half: a stream near 1/_BLOCKING_WAIT Hz would otherwise enter and time out by turns (a wake-up more).
_BLOCKING_WAIT = 0.1


def _kernel_pending(sock: socket.socket) -> int:
    """Bytes the kernel holds for ``sock`` (the FIONREAD ioctl); 0 where it cannot tell (Windows), which
    ends a read round early rather than late. Imported on first use: most nodes never get here."""
    global _ioctl
    if _ioctl is None:
        try:
            import fcntl
            import termios

            request = termios.FIONREAD
            _ioctl = lambda fd: fcntl.ioctl(fd, request, b"\0\0\0\0")  # noqa: E731
        except (ImportError, AttributeError):
            _ioctl = False
    if not _ioctl:
        return 0
    try:
        return _unpack_int(_ioctl(sock.fileno()))[0]
    except (OSError, ValueError):
        return 0


_ioctl: Any = None
_unpack_int = struct.Struct("i").unpack
_U32 = struct.Struct("<I")  # a frame's length prefix


def _low_water(sock: socket.socket, lazy: bool) -> bool:
    """Set ``sock``'s ``SO_RCVLOWAT`` to a quarter of its receive buffer (``lazy``) or back to one byte;
    False where the platform cannot. A quarter: the kernel counts its bookkeeping in that buffer and
    offers the sender as little as half of it, so a quarter of it in data is reached, never the end."""
    option = getattr(socket, "SO_RCVLOWAT", None)
    if option is None:
        return False
    try:
        mark = max(1, sock.getsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF) // 4) if lazy else 1
        sock.setsockopt(socket.SOL_SOCKET, option, mark)
    except OSError:
        return False
    return True


class RawMessage(SlotRecord):
    """What a ``raw=True`` subscriber receives: the serialized bytes and the publisher's header."""

    __slots__ = ("data", "connection_header")

    def __init__(self, data: bytes | bytearray, connection_header: Mapping[str, str] | None = None) -> None:
        self.data = data
        self.connection_header = {} if connection_header is None else connection_header


class _Poller:
    """Readiness of a worker's sockets: ``select.epoll`` where it exists (half the cost of ``selectors``
    per wait, which is on every message's path), else the portable ``selectors`` default."""

    def __init__(self) -> None:
        #: what each watched fd is reported as (a worker's solo rounds read it directly)
        self.objs: dict[int, SubConnection | None] = {}
        #: at most this many events per wait (epoll otherwise sizes its buffer for 1023 on every call)
        self.max_events = 1
        self.epoll = select.epoll() if hasattr(select, "epoll") else None
        self._selector = None if self.epoll is not None else selectors.DefaultSelector()

    def register(self, fd: int, obj: SubConnection | None) -> None:
        """Watch ``fd``; :meth:`wait` reports it as ``obj`` (None is the worker's wake-up socket)."""
        self.objs[fd] = obj
        self.max_events = len(self.objs)
        if self.epoll is not None:
            self.epoll.register(fd, select.EPOLLIN)
        else:
            assert self._selector is not None
            self._selector.register(fd, selectors.EVENT_READ, obj)

    def unregister(self, fd: int) -> None:
        if fd not in self.objs:
            return
        del self.objs[fd]
        self.max_events = max(1, len(self.objs))
        try:
            if self.epoll is not None:
                self.epoll.unregister(fd)
            else:
                assert self._selector is not None
                self._selector.unregister(fd)
        except (KeyError, ValueError, OSError):
            pass

    def wait(self, timeout: float | None = None) -> list[SubConnection | None]:
        """What is readable, waiting at most ``timeout`` seconds (None: until something is)."""
        if self.epoll is not None:
            objs = self.objs
            events = self.epoll.poll(-1 if timeout is None else timeout, self.max_events)
            if len(events) == 1:  # the usual wake-up: one socket (a comprehension is one more call)
                fd = events[0][0]
                return [objs[fd]] if fd in objs else []
            return [objs[fd] for fd, _ in events if fd in objs]
        assert self._selector is not None
        return [key.data for key, _ in self._selector.select(timeout)]

    def close(self) -> None:
        if self.epoll is not None:
            self.epoll.close()
        elif self._selector is not None:
            self._selector.close()


class SubConnection:
    """One publisher's stream for one topic, read on the loop."""

    intra = False
    #: frames start with a tag byte (SHMROS): the reader's and the fused decoder's framing
    tagged = False
    #: the flags of every read that must not wait: ``MSG_DONTWAIT`` once :meth:`make_blocking` made the
    #: socket blocking (so that a solo worker can wait in ``recv`` itself), 0 while it is non-blocking
    flags = 0
    #: a drop ended the stream under a blocked reader (:meth:`interrupt`): its end is not news
    _interrupted = False

    def __init__(self, sub: Subscription, sock: socket.socket, uri: str, header: Mapping[str, str]) -> None:
        self.sub = sub
        self.sock = sock
        self.fd = sock.fileno()
        self.uri = uri
        self.header = dict(header)
        self.publisher = header.get("callerid", uri)
        self.latching = header.get("latching", "0") == "1"
        self.last: bytes | bytearray | None = None
        self.id = next(connection_ids)
        #: the handle whose callbacks this stream feeds (set when handed to a worker)
        self.reader: Subscriber | None = None
        self.bytes_recv = 0
        self.num_recv = 0
        self.closed = False
        self._reader = FrameReader()

    @property
    def transport(self) -> str:
        """The transport name getBusInfo reports (TCPROS or UNIXROS)."""
        return transport.transport_of(self.sock)

    def read(self, budget: int | None = None, first: int | None = None) -> list[bytes | bytearray] | None:
        """Read frames from the kernel (worker thread): about ``budget`` bytes at most when given, else
        what the kernel held when the read began, not what arrives meanwhile (a publisher as fast as
        this reader would keep it reading, and its callbacks waiting, for as long as the stream
        lasts). ``first``: the byte count of a :meth:`wait` that began this read. None when the
        stream has ended."""
        reader, sock = self._reader, self.sock
        frames: list[bytes | bytearray] = []
        got = 0
        while True:
            buf = reader.buffer()
            if first is not None:
                n, first = first, None
            else:
                received = self._recv_into(buf)
                if received is None:
                    return None
                if received < 0:
                    break
                n = received
            self.bytes_recv += n
            got += n
            try:
                frames.extend(reader.commit(n))
            except ProtocolError as exc:
                self._drop_broken_stream(exc)
                return None
            if n < len(buf):
                break  # the kernel had no more: skip the EAGAIN round trip
            if budget is None:
                budget = got + _kernel_pending(sock)  # the first full read: this round ends there
            if got >= budget:
                break
        if frames:
            self.num_recv += len(frames)
            if self.latching:
                self.last = frames[-1]
        return frames

    def read_decoded(
        self, budget: int | None, decode: Any, cap: int | None, min_frame: int, first: int | None = None
    ) -> tuple[list[Any], list[bytes | bytearray], list[tuple[int, Exception]]] | None:
        """:meth:`read` fused with decoding (the worker's fast path for a plain, unlatched stream):
        ``(messages, frames, failures)``: the messages decoded as they were cut, then the frames left
        to decode one by one (a large frame received in place, or, once ``cap`` messages could be
        exceeded, everything after: a bounded queue drops those unread rather than decoded), and
        ``(length, error)`` for each frame that did not decode. ``first``: the byte count of a
        :meth:`wait` that began this read. None when the stream has ended."""
        reader, sock = self._reader, self.sock
        msgs: list[Any] = []
        frames: list[bytes | bytearray] = []
        bad: list[tuple[int, Exception]] = []
        got = 0
        fused = True
        buf = reader.buffer()
        if buf is reader.whole:
            # the usual wake-up: no frame pending, and the few small frames the kernel holds fit the
            # buffer: one recv and one decode, without the general loop's calls and checks (about a
            # microsecond of every small message's hop, measured in a ping-pong's CPU time)
            if first is not None:
                n, first = first, None
            else:
                try:
                    n = sock.recv_into(buf, 0, self.flags)
                except (BlockingIOError, InterruptedError):
                    return msgs, frames, bad
                except OSError as exc:
                    self._lost(f"read failed: {exc}")
                    return None
            if 0 < n < len(buf) and (cap is None or n // min_frame <= cap):
                self.bytes_recv += n
                # commit_decoded's work, with the reader untouched when every frame was whole
                start = decode(buf[:n].tobytes(), 0, n, msgs, bad)
                if start != n:
                    return self.decoded_rest(msgs, bad, start, n)
                self.num_recv += len(msgs) + len(bad)
                return msgs, frames, bad
            first = self._received(n)
            if first is None:
                return None
        while True:
            if first is not None:
                n, first = first, None
            else:
                buf = reader.buffer()
                received = self._recv_into(buf)
                if received is None:
                    return None
                if received < 0:
                    break
                n = received
            self.bytes_recv += n
            got += n
            if fused and cap is not None and len(msgs) + (reader.pending + n) // min_frame > cap:
                fused = False
            try:
                if fused and not frames:
                    frames = reader.commit_decoded(n, decode, msgs, bad)
                    if frames:  # a large frame (or a tagged one): decoded here, so that order is kept
                        untagged = self.untag(frames)
                        if untagged:
                            _decode_into(self.sub.msg_class, untagged, msgs, bad)
                        frames = []
                        if self.closed:
                            break  # a malformed stream, closed: deliver what came before
                else:
                    frames.extend(reader.commit(n))
            except ProtocolError as exc:
                self._drop_broken_stream(exc)
                return None
            if n < len(buf):
                break  # the kernel had no more: skip the EAGAIN round trip
            if budget is None:
                budget = got + _kernel_pending(sock)  # the first full read: this round ends there
            if got >= budget:
                break
        if frames:
            frames = self.untag(frames) or []
        self.num_recv += len(msgs) + len(frames) + len(bad)
        return msgs, frames, bad

    def decoded_rest(
        self, msgs: list[Any], bad: list[tuple[int, Exception]], start: int, n: int
    ) -> tuple[list[Any], list[bytes | bytearray], list[tuple[int, Exception]]] | None:
        """:meth:`read_decoded`'s result when ``n`` bytes were received into the reader's whole buffer
        and the fused decoder stopped at ``start`` (a large frame begun, a frame cut short, a tagged
        frame): the rest kept in the reader, what it completes decoded one by one."""
        try:
            frames = self._reader.commit_rest(start, n)
        except ProtocolError as exc:
            self._drop_broken_stream(exc)
            return None
        if frames:  # a large frame begun, or tagged frames: the general path's way
            frames = self.untag(frames) or []
            if frames:
                _decode_into(self.sub.msg_class, frames, msgs, bad)
                frames = []
        self.num_recv += len(msgs) + len(bad)
        return msgs, frames, bad

    def untag(self, frames: list[Any]) -> list[Any] | None:
        """The messages' bytes in frames cut from this stream (a tagged stream overrides this); None
        when the stream turned out malformed (then it is closed)."""
        return frames

    def _recv_into(self, buf: Any) -> int | None:
        """One ``recv_into`` for both read paths: the byte count, -1 when the kernel has nothing
        now, None when the stream has ended (reported and closed)."""
        try:
            n = self.sock.recv_into(buf, 0, self.flags)
        except (BlockingIOError, InterruptedError):
            return -1
        except OSError as exc:
            self._lost(f"read failed: {exc}")
            return None
        return self._received(n)

    def make_blocking(self, timeout: float) -> bool:
        """Make the socket blocking, each wait in it ending after ``timeout`` seconds at most, so that
        :meth:`wait` can sleep in ``recv`` itself (one system call per message instead of a poll and
        a ``recv``); every other read then passes ``MSG_DONTWAIT``. False, and the socket left as it
        was, where the platform has neither flag nor timeout option (not Linux)."""
        dontwait = getattr(socket, "MSG_DONTWAIT", 0)
        option = getattr(socket, "SO_RCVTIMEO", None)
        if not dontwait or option is None or self.closed:
            return False
        seconds = int(timeout)
        try:
            self.sock.setsockopt(
                socket.SOL_SOCKET, option, struct.pack("@ll", seconds, int((timeout - seconds) * 1e6))
            )
            self.sock.settimeout(None)
        except (OSError, struct.error):
            return False
        self.flags = dontwait
        return True

    def wait(self) -> int | None:
        """Sleep in ``recv`` until bytes come (after :meth:`make_blocking`; worker thread): how many
        came (the caller passes that as ``first`` to :meth:`read` or :meth:`read_decoded`), -1
        when the wait timed out, None when the stream has ended (reported and closed)."""
        try:
            n = self.sock.recv_into(self._reader.buffer())
        except (BlockingIOError, InterruptedError):
            return -1
        except OSError as exc:
            self._lost(f"read failed: {exc}")
            return None
        return self._received(n)

    def interrupt(self) -> None:
        """End the stream under a reader blocked in :meth:`wait` (a drop: the reader closes it without
        a word); any thread."""
        self._interrupted = True
        try:
            self.sock.shutdown(socket.SHUT_RDWR)
        except OSError:
            pass

    def _received(self, n: int) -> int | None:
        """``n`` bytes came from ``recv_into``: ``n``, or None when 0 said the stream has ended
        (reported and closed)."""
        if n == 0:
            if self.closed or self._interrupted:  # closed or dropped by another thread under a wait
                self.close()
                return None
            pending = self._reader.pending
            if pending:
                self._lost(
                    f"publisher disconnected mid-message ({pending} bytes of a frame received)",
                    logging.WARNING,
                )
            else:
                self._lost("publisher closed the connection")
            return None
        return n

    def _drop_broken_stream(self, exc: ProtocolError) -> None:
        """Drop a publisher whose stream broke the framing (no reconnection: it would send the same)."""
        _log.warning("topic %s: dropped publisher %s: %s", self.sub.topic, self.publisher, exc)
        self.close()
        self.sub.node.runtime.call_soon(self.sub.connection_lost, self, False)

    def _lost(self, why: str, level: int = logging.INFO) -> None:
        if self.closed or self._interrupted:  # closed or dropped by another thread: not news
            self.close()
            return
        _log.log(level, "topic %s: %s (%s)", self.sub.topic, why, self.publisher)
        self.close()
        self.sub.node.runtime.call_soon(self.sub.connection_lost, self, True)

    def close(self) -> None:
        """Close the socket (any thread; idempotent)."""
        if self.closed:
            return
        self.closed = True
        if self.flags:  # a reader may sleep in recv on it: a close alone would not wake it
            try:
                self.sock.shutdown(socket.SHUT_RDWR)
            except OSError:
                pass
        transport.close_quietly(self.sock)


def _decode_into(
    cls: Any, frames: list[bytes | bytearray], out: list[Any], bad: list[tuple[int, Exception]]
) -> None:
    """Decode ``frames`` one by one onto ``out`` (failures onto ``bad``, as the fused decoder does)."""
    decode = cls.deserialize_from
    for frame in frames:
        try:
            out.append(decode(frame))
        except Exception as exc:  # generated code raises DeserializationError, struct.error, ...
            bad.append((len(frame), exc))


def shm_offer() -> list[str] | None:
    """The SHMROS offer, or None (imported on first use: shm_link builds on this module)."""
    from ninjemys.node import shm_link

    return shm_link.offer()


def _connection(sub: Subscription, sock: socket.socket, uri: str, header: Mapping[str, str]) -> SubConnection:
    """SHMROS when the publisher's reply names a ring, else TCPROS/UNIXROS. A ring that cannot be
    mapped marks the publisher TCPROS-only and raises (the caller retries)."""
    if "ninjemys_shm" not in header:
        return SubConnection(sub, sock, uri, header)
    from ninjemys.node import shm_link

    try:
        return shm_link.subscriber_connection(sub, sock, uri, header)
    except NinjemysError:
        sub.shm_refused.add(uri)
        raise


class Subscription:
    """A topic this node subscribes to: the publisher connections and the handles fed by them."""

    def __init__(self, node: NodeContext, topic: str, msg_class: Any, tcp_nodelay: bool) -> None:
        self.node = node
        self.topic = topic
        self.msg_class = msg_class
        self.type_name: str = getattr(msg_class, "_type", "*") if msg_class is not None else "*"
        self.md5sum: str = getattr(msg_class, "_md5sum", "*") if msg_class is not None else "*"
        self.definition: str = getattr(msg_class, "_full_text", "") if msg_class is not None else ""
        self.tcp_nodelay = tcp_nodelay
        self.handles: list[Subscriber] = []
        self.connections: dict[str, SubConnection | intraprocess.IntraLink] = {}
        self.publishers: list[str] = []
        #: publisher lists applied so far (see :meth:`registered`)
        self.updates = 0
        self._connecting: set[str] = set()
        #: publishers whose shared memory failed here: TCPROS only from then on
        self.shm_refused: set[str] = set()
        self.closed = False

    # -- publisher set (on the loop) -------------------------------------------------------------

    def update_publishers(self, uris: list[str], keep_live: bool = False) -> None:
        """publisherUpdate semantics: connect to new URIs, drop connections to missing ones
        (``keep_live``: keep open connections the list omits, as a master still filling in may)."""
        if self.closed:
            return
        self.updates += 1
        if keep_live:
            uris = list(uris) + [
                uri for uri, conn in self.connections.items() if uri not in uris and not conn.closed
            ]
        self.publishers = list(uris)
        wanted = set(uris)
        for uri, conn in list(self.connections.items()):
            if uri not in wanted:
                del self.connections[uri]
                self._drop(conn)
        loop = self.node.runtime.loop
        for uri in uris:
            if uri not in self.connections and uri not in self._connecting:
                self._connecting.add(uri)
                loop.create_task(self._connect(uri))

    def registered(self, uris: list[str], updates: int, keep_live: bool = False) -> None:
        """The master's answer to this subscription's registerSubscriber (on the loop), sent when
        ``self.updates`` was ``updates``. A publisherUpdate that arrived since is newer than this
        answer (the master notifies a subscriber only once it is registered), so the answer is then
        stale and ignored: applied after it, it would drop a publisher that appeared meanwhile
        (a fresh subscriber racing a publisher's start got nothing, ever)."""
        if updates == self.updates:
            self.update_publishers(uris, keep_live)

    def _drop(self, conn: SubConnection | intraprocess.IntraLink) -> None:
        if conn.intra:
            conn.close()
        else:
            self._hand(("drop", conn))  # type: ignore[arg-type]

    def _connect_intra(self, uri: str) -> bool:
        """Join a publisher of this very process without a socket, when a handle opted in (on the
        loop); True when ``uri`` was such a publisher (joined, or refused with one line)."""
        if not any(h.intraprocess for h in self.handles):
            return False
        pub = intraprocess.local_publication(uri, self.topic)
        if pub is None:
            return False
        link = intraprocess.attach(pub, self, uri)
        if link is not None:
            if self.closed or uri not in self.publishers:
                link.close()
                return True
            old = self.connections.pop(uri, None)
            if old is not None:
                self._drop(old)
            self.connections[uri] = link
        return True

    async def _connect(self, uri: str, attempt: int = 0) -> None:
        sock: socket.socket | None = None
        try:
            if self._connect_intra(uri):
                return
            offer: list[list[str]] = [["TCPROS"]]
            # a lazy handle waits on SO_RCVLOWAT, which Linux honours for TCP only, and reads plain
            # frames: it keeps TCPROS (neither a Unix socket nor shared memory)
            lazy = any(h._host._lazy for h in self.handles)
            if transport.local_transport_enabled() and transport.host_identity() and not lazy:
                offer.insert(0, [transport.UNIXROS, transport.host_identity()])
            shm = None if lazy or uri in self.shm_refused else shm_offer()
            if shm is not None:
                offer.insert(0, shm)
            reply = await xmlrpc_client.call(
                uri, "requestTopic", (self.node.name, self.topic, offer), timeout=5.0
            )
            code, status, proto = reply
            if code != 1 or not proto or proto[0] not in ("TCPROS", transport.UNIXROS, "SHMROS"):
                _log.info("topic %s: publisher %s declined: %s", self.topic, uri, status)
                self._retry_later(uri, attempt)
                return
            if proto[0] == transport.UNIXROS or (proto[0] == "SHMROS" and len(proto) == 2):  # a Unix socket
                sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
                address: Any = transport.unix_sockaddr(str(proto[1]))
            else:
                sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
                address = (proto[1], int(proto[2]))
            transport.tune(sock, self.tcp_nodelay)
            await transport.connect(sock, address, timeout=5.0)
            shm_field = {"ninjemys_shm": transport.host_identity()} if proto[0] == "SHMROS" else None
            fields = self._header(shm_field)
            await transport.write_all(sock, headers.encode_header(fields))
            header = await transport.read_header(sock)
            refused = auth.check_fields(header)
            error = (
                f"authentication failed: {refused}"
                if refused is not None
                else headers.check_publisher_header(header, self.type_name, self.md5sum)
            )
            if error is not None:
                _log.warning("topic %s: cannot subscribe to %s: %s", self.topic, uri, error)
                transport.close_quietly(sock)
                return
            if self.closed or uri not in self.publishers:
                transport.close_quietly(sock)
                return
            conn = _connection(self, sock, uri, header)
            old = self.connections.pop(uri, None)
            if old is not None:
                self._drop(old)
            self.connections[uri] = conn
            self._hand(("add", conn))
        except (OSError, TimeoutError, NinjemysError, ValueError, TypeError) as exc:
            why = "timed out" if isinstance(exc, TimeoutError) else str(exc) or type(exc).__name__
            _log.info("topic %s: could not connect to publisher %s: %s", self.topic, uri, why)
            if sock is not None:
                transport.close_quietly(sock)
            self._retry_later(uri, attempt)
        except Exception as exc:  # an unexpected reply shape from a foreign peer
            _log.warning("topic %s: bad answer from publisher %s: %s", self.topic, uri, exc)
            if sock is not None:
                transport.close_quietly(sock)
        finally:
            self._connecting.discard(uri)

    def _header(self, extra: dict[str, str] | None = None) -> dict[str, str]:
        """The connection header, signed last: every field, ``extra`` ones too, is under the signature."""
        fields = {
            "callerid": self.node.name,
            "topic": self.topic,
            "md5sum": self.md5sum,
            "type": self.type_name,
            "message_definition": self.definition,
            "tcp_nodelay": "1" if self.tcp_nodelay else "0",
        }
        if extra:
            fields.update(extra)
        return auth.sign_fields(fields)

    def _hand(self, op: tuple[str, SubConnection]) -> None:
        """Give a connection to (or take it from) the reader's worker thread."""
        reader = self.handles[0] if self.handles else None
        if reader is None or reader.closed:
            op[1].close()
            return
        reader.post(op)

    def connection_lost(self, conn: SubConnection | intraprocess.IntraLink, retry: bool) -> None:
        """A stream ended (on the loop): forget it; if the publisher is still listed, try once more."""
        if self.connections.get(conn.uri) is conn:
            del self.connections[conn.uri]
        if retry and not self.closed and conn.uri in self.publishers:
            self.node.runtime.loop.call_later(0.5, self._retry, conn.uri)

    def _retry(self, uri: str, attempt: int = 0) -> None:
        if self.closed or uri not in self.publishers or uri in self.connections or uri in self._connecting:
            return
        self._connecting.add(uri)
        self.node.runtime.loop.create_task(self._connect(uri, attempt))

    def _retry_later(self, uri: str, attempt: int) -> None:
        """Try a failed publisher again while the master still lists it, as rospy does: after 0.5 s,
        doubling up to 30 s (a publisher too busy to answer, or asked a moment before its node knew
        the topic, is not left unconnected for good)."""
        if not self.closed and uri in self.publishers:
            delay = min(0.5 * 2**attempt, 30.0)
            self.node.runtime.loop.call_later(delay, self._retry, uri, attempt + 1)

    def latched_frames(self) -> list[tuple[Any, Mapping[str, str]]]:
        return [(c.last, c.header) for c in self.connections.values() if c.last is not None]

    def close(self) -> None:
        """On the loop: close every stream (the workers stop selecting closed sockets)."""
        self.closed = True
        for conn in list(self.connections.values()):  # an in-process link forgets itself as it closes
            conn.close()
        self.connections.clear()


class Subscriber:
    """A callback subscription; see :meth:`ninjemys.node.Node.subscriber`."""

    # declared here because a handle made with ``share`` reads them on its host before its own are set
    #: the handle whose worker thread reads and delivers for this one (itself unless made with ``share``)
    _host: Subscriber
    #: the handles a worker delivers for (itself first); replaced, never mutated
    _served: tuple[Subscriber, ...]
    #: the worker decided to end: no handle may join it any more
    _retired: bool
    _thread: threading.Thread
    _ops_lock: threading.Lock
    #: seconds a lazy worker lets data wait (0: it wakes per message); see :meth:`set_eager`
    _lazy: float
    _eager: bool

    def __init__(
        self,
        subscription: Subscription,
        callback: Callable[..., Any] | None,
        callback_args: Any = None,
        queue_size: int | None = None,
        raw: bool = False,
        coalesce: float = 0.0,
        share: Subscriber | None = None,
        lazy: float = 0.0,
        batch: bool = False,
        intraprocess: bool = False,
        direct: bool = False,
    ) -> None:
        self._sub = subscription
        #: an in-process publisher that opted in too hands this handle its message objects, shared
        self.intraprocess = intraprocess
        #: an idle handle is called back on an in-process publisher's thread (see push_local)
        self._direct = direct
        #: direct handles: held while a callback of this handle runs, by its worker or by an in-process
        #: publisher's thread that delivers itself (other handles call back only on their worker)
        self._busy = threading.Lock()
        self._busy_owner = 0  # the thread delivering directly now (unregister waits for any other)
        #: seconds a message may wait so that one wake-up of the worker takes several (see Node.subscriber)
        self._coalesce = max(0.0, coalesce)
        self.name = subscription.topic
        self.resolved_name = subscription.topic
        self.data_class = subscription.msg_class
        self.type = subscription.type_name
        self.md5sum = subscription.md5sum
        self.queue_size = queue_size
        self.raw = raw
        #: the callbacks get a list: every message read in one go (see Node.subscriber)
        self.batch = batch
        self.dropped = 0
        # a tuple, replaced (never mutated) by add_callback: the worker iterates it without a copy
        self._callbacks: tuple[tuple[Callable[..., Any], Any], ...] = ()
        if callback is not None:
            self._callbacks = ((callback, callback_args),)
        msg_class = subscription.msg_class
        self._decode: Callable[[Any], Any] | None = (
            None if raw or msg_class is None else msg_class.deserialize_from
        )
        self._queue: deque[tuple[bytes | bytearray, Mapping[str, str]]] = deque(
            maxlen=queue_size if queue_size and queue_size > 0 else None
        )
        self._closed = False
        #: the fused decoders of this type for plain and tagged streams (None: not made yet; False:
        #: none), see _read_fused
        self._fused: list[Any] = [None, None]
        if share is not None:
            host = share._host
            with host._ops_lock:
                if not host._retired:  # its thread still runs: serve this handle too
                    self._host = host
                    self._thread = host._thread
                    host._served = (*host._served, self)
                    return
        self._host = self
        self._served = (self,)
        self._retired = False
        self._ops: list[tuple[str, Any]] = []
        self._ops_lock = threading.Lock()
        # held while the sockets are read and their frames delivered: by the worker, and by a thread
        # that pulls (lazy handles); a callback's own pull returns at once, so it is never taken twice
        self._read_lock = threading.Lock()
        self._lazy = max(0.0, lazy)
        self._eager = False
        self._last_read = 0.0  # monotonic time of the last read of every socket (a round or a pull)
        self._lowat = False  # the sockets wake the worker only when well filled (lazy, not eager)
        self._puller = 0  # the thread that is pulling now (its callbacks must not pull again)
        # a socket pair, not a pipe: selectable on every OS (Windows cannot select on pipes)
        self._wake_r, self._wake_w = socket.socketpair()
        self._wake_r.setblocking(False)
        self._wake_w.setblocking(False)
        self._woken = False
        self._poller = _Poller()
        self._poller.register(self._wake_r.fileno(), None)
        self._conns: dict[int, SubConnection] = {}
        self._thread = subscription.node.runtime.start_thread(self._work, f"sub:{subscription.topic}")

    # -- hand-offs from other threads ------------------------------------------------------------

    def _wakeup(self) -> None:
        host = self._host
        if host._woken:
            return
        host._woken = True
        try:
            host._wake_w.send(b"\0")
        except (BlockingIOError, OSError):
            pass

    def post(self, op: tuple[str, SubConnection]) -> None:
        """Queue a connection add/drop for the worker that reads for this (reader) handle."""
        if op[0] == "add":
            op[1].reader = self
        host = self._host
        with host._ops_lock:
            host._ops.append(op)
        self._wakeup()
        if op[0] == "drop" and op[1].flags:
            op[1].interrupt()  # its worker may sleep in its recv, where the wake-up does not reach

    def enqueue(self, frames: list[bytes | bytearray], header: Mapping[str, str]) -> None:
        """Frames read by another thread (the reader handle, or a latched replay)."""
        self._push(frames, header)
        self._wakeup()

    def push_local(
        self, item: Handoff, header: Mapping[str, str], pub_queue_size: int | None, direct: bool = False
    ) -> int:
        """A message from a publisher of this process (its thread); returns how many it dropped.

        ``direct`` (a publish, not a latched replay on the loop): a handle made with ``direct=True``
        that is idle (nothing queued, no callback of it running) is called back right here, on the
        publisher's thread, with no wake-up; the lock it holds meanwhile keeps its callbacks one at a
        time and in order (the worker pops its queue under the same lock).

        This handle's own ``queue_size`` drops the oldest, as for a socket. An unbounded handle gets
        the publisher's ``queue_size`` semantics instead, as over TCPROS: a bounded publisher drops
        the oldest messages waiting for this lagging subscriber beyond its bound, and
        ``queue_size=None`` makes the publisher wait (lossless, synchronous) while more than
        :data:`_LOCAL_HIGH_WATER` wait, unless it publishes from this handle's own thread.
        """
        queue = self._queue
        busy = self._busy
        if direct and self._direct and not queue and not self._closed and busy.acquire(False):
            try:
                if not queue and not self._closed:
                    self._busy_owner = threading.get_ident()
                    self._deliver_handoff(item, header)
                    return 0
            finally:
                self._busy_owner = 0
                busy.release()
        dropped = 0
        if queue.maxlen is None and pub_queue_size != 0:
            if pub_queue_size is not None:
                while len(queue) >= pub_queue_size:
                    try:
                        queue.popleft()
                    except IndexError:
                        break
                    dropped += 1
            elif len(queue) >= _LOCAL_HIGH_WATER and threading.current_thread() is not self._host._thread:
                while len(queue) > _LOCAL_LOW_WATER and not self._closed:
                    time.sleep(_LOCAL_WAIT)
        self.enqueue([item], header)  # type: ignore[list-item]
        return dropped

    def _keep_newest(self, frames: list[bytes | bytearray], queued: int) -> list[bytes | bytearray]:
        """``queue_size`` semantics for ``frames`` arriving behind ``queued`` waiting ones: count what
        the bounded queue drops (oldest first) and return the frames that can still be delivered."""
        maxlen = self._queue.maxlen
        if maxlen is not None:
            overflow = queued + len(frames) - maxlen
            if overflow > 0:
                self.dropped += overflow
                if len(frames) > maxlen:
                    frames = frames[-maxlen:]
        return frames

    def _push(self, frames: list[bytes | bytearray], header: Mapping[str, str]) -> None:
        queue = self._queue
        frames = self._keep_newest(frames, len(queue))
        if len(frames) == 1:
            queue.append((frames[0], header))
        else:
            queue.extend([(f, header) for f in frames])

    # -- the worker thread -----------------------------------------------------------------------

    def _work(self) -> None:
        slices.shorten()  # a callback that wakes a thread keeps the CPU until it sleeps (see slices)
        try:
            while not (self._closed and self._retire()):
                busy = False
                for handle in self._served:
                    queue = handle._queue
                    if queue:
                        if handle._direct:
                            # popped under the lock: a direct delivery sees the queue empty only
                            # once everything before it has been called back (order kept)
                            with handle._busy:
                                if queue:
                                    frame, header = queue.popleft()
                                    handle._deliver(frame, header)
                        else:
                            frame, header = queue.popleft()
                            handle._deliver(frame, header)
                        busy = True
                if busy:
                    continue
                if self._lazy:  # reads may also come from pulls: under the read lock
                    self._lazy_round()
                    continue
                if not self._coalesce and len(self._served) == 1 and self._poller.epoll is not None:
                    self._solo_rounds()
                    continue
                for conn in self._poller.wait():
                    if conn is None:
                        self._on_wake()
                    else:
                        self._read(conn)
                if self._coalesce and not any(h._queue for h in self._served):
                    time.sleep(self._coalesce)  # let messages gather: the next poll takes them all
        finally:
            with self._read_lock:
                self._finish()

    def _solo_rounds(self) -> None:
        """The general loop's rounds for a worker that serves only its own handle, eager (the usual
        case), with the poller's wait inlined and none of the checks that concern other handles; it
        returns to the general loop when that has work (a queued message, a handle joining, the
        handle closed). Why: at tens of hertz (a state publisher's joint states) every wake-up runs
        this code cold, and each call and attribute on the way costs cache misses, measured at
        several microseconds per message.

        With one stream whose messages come less than :data:`_BLOCKING_WAIT` / 2 apart, the worker
        sleeps in that socket's ``recv`` instead of the poller (:meth:`SubConnection.wait`): one
        system call per message, and the first bytes already read when it wakes. The wake-up
        socket is then looked at after each wait, which ends on data, on the timeout, or on the
        stream's end (a close or drop shuts the socket down under it); so a connection add or a
        handle release waits at most that timeout while the stream flows, and an idle worker is
        back in the poller, which sees everything at once."""
        poller = self._poller
        poll = poller.epoll.poll  # type: ignore[union-attr]
        objs = poller.objs
        conns = self._conns
        queue = self._queue
        served = self._served
        read = self._read
        handles = self._sub.handles
        fused_of = self._fused
        maxlen = queue.maxlen
        budget = None if maxlen is not None else _READ_BUDGET
        monotonic = time.monotonic
        # the stream the next wait sleeps in (None: the poller), and when the poller last woke for it
        waiter: SubConnection | None = None
        last = 0.0
        first: int | None = None
        # what a round delivered, dropped before the next wait: a message kept alive by this frame's
        # locals while the worker sleeps would hold its shared-memory slot (and its memory) until the
        # next message, for ever after the last one
        got: tuple[list[Any], list[bytes | bytearray], list[tuple[int, Exception]]] | None = None
        msgs: list[Any] | None = None
        frames: list[bytes | bytearray] | None = None
        bad: list[tuple[int, Exception]] | None = None
        msg: Any = None
        # a raw handle's one callback, called without arguments (else None), while the callbacks are
        # these (add_callback replaces the tuple) and the handle is alone on its topic
        callbacks = raw_callbacks = self._callbacks
        raw_solo = (
            callbacks[0][0]
            if self._decode is None
            and not self.batch
            and not self._direct
            and len(callbacks) == 1
            and callbacks[0][1] is None
            else None
        )
        while not queue and not self._closed and self._served is served:
            got = msgs = frames = bad = msg = None
            if waiter is not None:
                first = self._wait_rounds(waiter, fused_of[waiter.tagged], raw_solo, raw_callbacks, served)
                if first is None or first <= 0 or self._woken or len(conns) != 1:
                    if first is None:
                        self._forget(waiter)
                    elif first > 0:
                        read(waiter, first)  # the general way: the handles or connections changed
                    waiter = None  # the poller next: it sees the wake-up socket too
                    continue
                events: Any = ((waiter.fd, 0),)
            else:
                first = None
                events = poll(-1, poller.max_events)
            for fd, _ in events:
                if fd in objs:
                    conn = objs[fd]
                    if conn is None:
                        self._on_wake()
                        continue
                    if first is None and conn.flags and len(conns) == 1:
                        # messages coming fast: wait for the next one in recv (see the docstring)
                        now = monotonic()
                        if now - last < _BLOCKING_WAIT / 2:
                            waiter = conn
                        last = now
                    fused = fused_of[conn.tagged]
                    if (
                        not fused
                        or conn.latching
                        or conn.closed
                        or self._direct
                        or self._closed
                        or conn.reader is not self
                        or len(handles) != 1
                    ):
                        if (
                            fused is False
                            and raw_solo
                            and not conn.latching
                            and not conn.closed
                            and not self._closed
                            and conn.reader is self
                            and len(handles) == 1
                            and self._callbacks is callbacks
                        ):
                            # a raw handle (robot_state_publisher's joint states): _read and
                            # _deliver_batch inlined, as the fused path below is for decoded ones
                            frames = conn.read(budget, first)
                            if frames is None:
                                self._forget(conn)
                                waiter = None
                                continue
                            if maxlen is not None and len(frames) > maxlen:
                                frames = self._keep_newest(frames, 0)
                            header = conn.header
                            for msg in frames:
                                if self._closed:
                                    break
                                try:
                                    raw_solo(RawMessage(msg, header))
                                except Exception:
                                    self._callback_raised(raw_solo)
                            continue
                        read(conn, first)
                        if conn.closed:
                            waiter = None
                        continue
                    # _read and _read_fused inlined for an unlatched stream and one handle, and
                    # _deliver_msgs for a single callback: each call is cache misses on a cold path
                    got = conn.read_decoded(budget, fused[0], maxlen, fused[1], first)
                    if got is None:
                        self._forget(conn)
                        waiter = None
                        continue
                    msgs, frames, bad = got
                    if frames or bad or (maxlen is not None and len(msgs) > maxlen):
                        self._fused_rest(conn, msgs, frames, bad, maxlen)
                        continue
                    callbacks = self._callbacks
                    if len(callbacks) == 1 and callbacks[0][1] is None:
                        callback = callbacks[0][0]
                        for msg in msgs:
                            if self._closed:
                                break
                            try:
                                callback(msg)
                            except Exception:
                                self._callback_raised(callback)
                    else:
                        self._deliver_msgs(msgs)

    def _wait_rounds(
        self,
        conn: SubConnection,
        fused: Any,
        raw_solo: Callable[[Any], Any] | None,
        raw_callbacks: tuple[tuple[Callable[..., Any], Any], ...],
        served: tuple[Subscriber, ...],
    ) -> int | None:
        """:meth:`_solo_rounds` while it waits in ``conn``'s ``recv``: as long as nothing changes and
        each read is whole small frames, a round is that ``recv``, one decode (or one RawMessage)
        and the callbacks, with no other call on the way (a message at tens of hertz runs this with
        cold caches, where each call costs). Returns when that ends: the byte count of a read it
        did not deliver (in the reader's whole buffer: the caller reads it the general way, as the
        first read of ``first``), 0 when something changed before a wait, -1 when a wait timed
        out, None when the stream ended (reported and closed)."""
        reader = conn._reader
        whole = reader.whole
        if reader.buffer() is not whole:  # a frame begun: the general way
            return conn.wait()
        if fused and not conn.latching and not self._direct:
            decode, min_frame = fused
            raw = None
        elif fused is False and raw_solo is not None and not conn.latching:
            decode = min_frame = None
            raw = raw_solo
        else:
            return conn.wait()
        skip = 5 if conn.tagged else 4  # a tagged stream's small inline frame: tag 0, then the body
        recv_into = conn.sock.recv_into
        size = len(whole)
        queue = self._queue
        maxlen = queue.maxlen
        handles = self._sub.handles
        header = conn.header
        unpack_from = _U32.unpack_from
        # a round's messages, dropped before the next wait (see _solo_rounds)
        msgs: list[Any] | None = None
        msg: Any = None
        while True:
            msgs = msg = None
            if (
                queue
                or self._closed
                or self._woken
                or self._served is not served
                or len(handles) != 1
                or conn.reader is not self
                or (raw is not None and self._callbacks is not raw_callbacks)
            ):
                return 0
            try:
                n = recv_into(whole)
            except (BlockingIOError, InterruptedError):
                return -1
            except OSError as exc:
                conn._lost(f"read failed: {exc}")
                return None
            if not n:
                return conn._received(0)
            if self._closed or self._woken or len(handles) != 1 or n >= size:
                return n  # changed while it slept (or a large read): the general way delivers it
            if raw is not None:
                if n > skip and unpack_from(whole, 0)[0] == n - 4 and (skip == 4 or not whole[4]):
                    conn.bytes_recv += n
                    conn.num_recv += 1
                    try:
                        raw(RawMessage(whole[skip:n].tobytes(), header))
                    except Exception:
                        self._callback_raised(raw)
                    continue
                return n
            if maxlen is not None and n // min_frame > maxlen:
                return n  # a bounded queue drops some: decoded only if kept (the general way)
            msgs = []
            bad: list[tuple[int, Exception]] = []
            start = decode(whole[:n].tobytes(), 0, n, msgs, bad)
            conn.bytes_recv += n
            if start != n:  # a large frame begun, a frame cut short, a tagged frame
                got = conn.decoded_rest(msgs, bad, start, n)
                if got is None:
                    return None
                self._fused_rest(conn, *got, maxlen)
                if reader.buffer() is not whole:
                    return 0
                continue
            conn.num_recv += len(msgs) + len(bad)
            if bad or (maxlen is not None and len(msgs) > maxlen):
                self._fused_rest(conn, msgs, [], bad, maxlen)
                continue
            callbacks = self._callbacks
            if len(callbacks) == 1 and callbacks[0][1] is None:
                callback = callbacks[0][0]
                for msg in msgs:
                    if self._closed:
                        break
                    try:
                        callback(msg)
                    except Exception:
                        self._callback_raised(callback)
            else:
                self._deliver_msgs(msgs)

    def _callback_raised(self, callback: Callable[..., Any]) -> None:
        """A user callback raised: logged as rospy logs it, ``bad callback: <callback>`` and the
        traceback at ERROR on the console and /rosout (where rqt_console shows it), and the worker
        goes on with the next message. After shutdown only the Python logger hears of it, as in rospy."""
        if self._sub.node.is_shutdown:
            _log.warning("topic %s: callback %r raised during shutdown", self.name, callback, exc_info=True)
            return
        self._sub.node.log.log(ERROR, "bad callback: %s", callback, exc_info=True)

    def _lazy_round(self) -> None:
        """One wait of a lazy handle's worker: on the low-water marks (:meth:`_lazy_wait`), or per
        message while eager."""
        lazy = not self._eager
        if lazy != self._lowat:
            self._set_lowat(lazy)
        if self._lowat:
            self._lazy_wait()
            return
        ready = self._poller.wait()
        with self._read_lock:
            for conn in ready:
                if conn is None:
                    self._on_wake()
                else:
                    self._read(conn)

    def _lazy_wait(self) -> None:
        """One wait of a lazy worker: until ``lazy`` seconds have passed since the sockets were last
        read (by a round or a pull), or one of them holds its low-water mark; then read them all."""
        wait = self._last_read + self._lazy - time.monotonic()
        ready = self._poller.wait(wait) if wait > 0.0 else []
        with self._read_lock:
            full = False
            for conn in ready:
                if conn is None:
                    self._on_wake()
                else:
                    full = True
            if full or time.monotonic() >= self._last_read + self._lazy:
                for conn in list(self._conns.values()):
                    self._read(conn)
                self._last_read = time.monotonic()

    def _set_lowat(self, lazy: bool) -> None:
        """Make the sockets report readable only at a quarter of their receive buffer (at most half
        of the data it holds) while lazy, at any byte otherwise (read lock not needed: the
        worker's own sockets). Without ``SO_RCVLOWAT`` the worker stays one wake-up per message."""
        ok = True
        for conn in list(self._conns.values()):
            ok = _low_water(conn.sock, lazy) and ok
        self._lowat = lazy and ok

    def _retire(self) -> bool:
        """True (and no handle may join any more) when every handle this worker serves is closed."""
        with self._ops_lock:
            if any(not h._closed for h in self._served):
                return False
            self._retired = True
            return True

    def _on_wake(self) -> None:
        try:
            while self._wake_r.recv(4096):
                pass
        except (BlockingIOError, OSError):
            pass
        # cleared only after draining: a wake-up written during the drain would otherwise be consumed
        # while the flag stays set, and every later enqueue would skip its wake-up (a lost wake-up)
        self._woken = False
        self._apply_ops()

    def _apply_ops(self) -> None:
        """Connections to add, drop or pass on (read lock held)."""
        with self._ops_lock:
            ops, self._ops = self._ops, []
        for op, obj in ops:
            if op == "add" and not obj.closed:
                if self._lowat and not _low_water(obj.sock, True):
                    self._set_lowat(False)
                if not self._lazy and not self._coalesce and self._poller.epoll is not None:
                    obj.make_blocking(_BLOCKING_WAIT)  # solo rounds may wait in its recv
                self._conns[obj.fd] = obj
                self._poller.register(obj.fd, obj)
                self._read(obj)  # latched data may already be waiting
            elif op == "drop":
                self._forget(obj)
                obj.close()
            elif op == "release":  # a served handle closed while others still use this thread
                for conn in [c for c in self._conns.values() if c.reader is obj]:
                    self._forget(conn)
                    self._pass_on(conn, obj)

    @staticmethod
    def _pass_on(conn: SubConnection, old: Subscriber) -> None:
        """Give the stream of closed handle ``old`` to the next open handle of its topic, or close it."""
        successor = next((h for h in conn.sub.handles if h is not old and not h.closed), None)
        if successor is not None and not conn.closed:
            successor.post(("add", conn))
        else:
            conn.close()

    def _forget(self, conn: SubConnection) -> None:
        if self._conns.pop(conn.fd, None) is not None:
            self._poller.unregister(conn.fd)

    def _read(self, conn: SubConnection, first: int | None = None) -> None:
        """Read ``conn`` and deliver (``first``: the byte count of the :meth:`SubConnection.wait` that
        began this read)."""
        if conn.closed:
            self._forget(conn)
            return
        owner = conn.reader or self
        # a bounded queue keeps the newest: read what the kernel holds and drop; an unbounded one
        # delivers as it goes (reading megabytes of backlog first would stall every callback meanwhile)
        maxlen = owner._queue.maxlen
        tagged = conn.tagged
        fused = owner._fused[tagged]
        if fused is None:
            fused = owner._fused[tagged] = owner._frames_decoder(tagged)
        if fused and not conn.latching and not owner._closed and len(owner._sub.handles) == 1:
            self._read_fused(owner, conn, fused, maxlen, first)
            return
        frames = conn.read(None if maxlen is not None else _READ_BUDGET, first)
        if frames is None:
            self._forget(conn)
            return
        if frames:
            # every other handle of the topic, the next reader too when this one has just closed (its
            # worker reads until it sees that, and the stream then goes on to the next reader)
            for other in owner._sub.handles:
                if other is not owner:
                    other.enqueue(frames, conn.header)
            # the queues are empty whenever the worker reads (it delivers them first), so this
            # batch can go straight to the callbacks: no per-message queue entry
            maxlen = owner._queue.maxlen
            if maxlen is not None and len(frames) > maxlen:
                frames = owner._keep_newest(frames, 0)
            if owner._direct:
                with owner._busy:
                    owner._deliver_batch(frames, conn.header)
            else:
                owner._deliver_batch(frames, conn.header)

    def _frames_decoder(self, tagged: bool) -> Any:
        """The fused decoder of this handle's type (see :mod:`ninjemys.idl.framedecode`), or False when
        its messages go the per-frame way (raw, batch, a class not generated here)."""
        if self._decode is None or self.batch or self.data_class is None:
            return False
        from ninjemys.idl.framedecode import frames_decoder

        try:
            return frames_decoder(self.data_class, tagged) or False
        except Exception as exc:  # a class whose generated code we cannot regenerate: keep the old path
            _log.info("topic %s: per-frame decoding (%s)", self.name, exc)
            return False

    def _read_fused(
        self, owner: Subscriber, conn: SubConnection, fused: Any, maxlen: int | None, first: int | None = None
    ) -> None:
        """The fast path of :meth:`_read`: one handle, a plain stream; frames are decoded as they are
        cut and the callback is called in a tight loop."""
        budget = None if maxlen is not None else _READ_BUDGET
        got = conn.read_decoded(budget, fused[0], maxlen, fused[1], first)
        if got is None:
            self._forget(conn)
            return
        self._fused_rest(conn, *got, maxlen, owner)

    def _fused_rest(
        self,
        conn: SubConnection,
        msgs: list[Any],
        frames: list[bytes | bytearray],
        bad: list[tuple[int, Exception]],
        maxlen: int | None,
        owner: Subscriber | None = None,
    ) -> None:
        """Deliver what :meth:`SubConnection.read_decoded` returned for ``owner`` (this handle by
        default): failures reported, ``maxlen`` kept, then the messages and the frames left."""
        if owner is None:
            owner = self
        for length, exc in bad:
            owner._undecodable_length(length, conn.header, exc)
        if maxlen is not None and len(msgs) + len(frames) > maxlen:  # drop the oldest, as the queue would
            over = len(msgs) + len(frames) - maxlen
            owner.dropped += over
            if over >= len(msgs):
                frames = frames[over - len(msgs) :]
                msgs = []
            else:
                msgs = msgs[over:]
        if owner._direct:
            with owner._busy:
                owner._deliver_msgs(msgs)
                if frames:
                    owner._deliver_batch(frames, conn.header)
        else:
            owner._deliver_msgs(msgs)
            if frames:
                owner._deliver_batch(frames, conn.header)

    def _deliver_msgs(self, msgs: list[Any]) -> None:
        """Call back with decoded messages, in order; the usual case (one callback without args) in a
        tight loop, as this runs once per received message."""
        callbacks = self._callbacks
        if len(callbacks) == 1 and callbacks[0][1] is None:
            callback = callbacks[0][0]
            for msg in msgs:
                if self._closed:
                    return
                try:
                    callback(msg)
                except Exception:
                    self._callback_raised(callback)
            return
        for msg in msgs:
            if self._closed:
                return
            self._call(msg)

    def _finish(self) -> None:
        """Worker exit: pass our connections to the next handle of their topic, or close them."""
        conns = list(self._conns.values())
        for conn in conns:
            self._forget(conn)
        with self._ops_lock:
            self._retired = True
            pending = [c for op, c in self._ops if op == "add"]
            self._ops = []
        for conn in conns + pending:
            self._pass_on(conn, conn.reader or self)
        self._poller.close()
        self._wake_r.close()
        self._wake_w.close()

    def _call(self, msg: Any) -> None:
        for callback, args in self._callbacks:
            try:
                if args is None:
                    callback(msg)
                else:
                    callback(msg, args)
            except Exception:
                self._callback_raised(callback)

    def _deliver_batch(self, frames: list[bytes | bytearray], header: Mapping[str, str]) -> None:
        """Deliver frames in order; the common case (decode, one callback without args) is inlined,
        as this loop runs once per received message."""
        decode, callbacks = self._decode, self._callbacks
        if self.batch:
            if decode is None:
                msgs: list[Any] = [RawMessage(frame, header) for frame in frames]
            else:
                msgs = [m for m in (self._decoded(f, header) for f in frames) if m is not None]
            if msgs and not self._closed:
                self._call(msgs)
            return
        if len(callbacks) != 1 or callbacks[0][1] is not None:
            for frame in frames:
                if self._closed:
                    return
                self._deliver(frame, header)
            return
        callback = callbacks[0][0]
        if decode is None:  # raw: the bytes and the publisher's header
            for frame in frames:
                if self._closed:
                    return
                try:
                    callback(RawMessage(frame, header))
                except Exception:
                    self._callback_raised(callback)
            return
        for frame in frames:
            if self._closed:
                return
            try:
                msg = decode(frame)
            except Exception as exc:  # generated code raises DeserializationError, struct.error, ...
                self._undecodable(frame, header, exc)
                continue
            try:
                callback(msg)
            except Exception:
                self._callback_raised(callback)

    def _undecodable(self, frame: bytes | bytearray, header: Mapping[str, str], exc: Exception) -> None:
        self._undecodable_length(len(frame), header, exc)

    def _undecodable_length(self, length: int, header: Mapping[str, str], exc: Exception) -> None:
        _log.warning(
            "topic %s: cannot deserialize a %d-byte %s from %s: %s",
            self.name,
            length,
            self.type,
            header.get("callerid", "?"),
            exc,
        )

    def _decoded(self, frame: bytes | bytearray, header: Mapping[str, str]) -> Any:
        """The message in ``frame`` (None, after one line saying why, when it does not decode)."""
        try:
            return self._decode(frame)  # type: ignore[misc]
        except Exception as exc:  # generated code raises DeserializationError, struct.error, ...
            self._undecodable(frame, header, exc)
            return None

    def _deliver(self, frame: bytes | bytearray, header: Mapping[str, str]) -> None:
        if frame.__class__ is Handoff:
            self._deliver_handoff(frame, header)
            return
        if self._decode is None:
            msg: Any = RawMessage(frame, header)
        else:
            msg = self._decoded(frame, header)
            if msg is None:
                return
        self._call([msg] if self.batch else msg)

    def _deliver_handoff(self, item: Handoff, header: Mapping[str, str]) -> None:
        """A message from a publisher of this process: the object itself, a copy, or raw bytes."""
        if self._decode is None:
            msg: Any = RawMessage(bytes(item.body()), header)
        else:
            try:
                msg = item.message_for(self.intraprocess, self.data_class)
            except (
                Exception
            ) as exc:  # a publisher's object that does not serialize, or bytes that do not decode
                _log.warning("topic %s: cannot take a message from %s in-process: %s",
                             self.name, header.get("callerid", "?"), exc)  # fmt: skip
                return
        self._call([msg] if self.batch else msg)

    # -- API -------------------------------------------------------------------------------------

    def pull(self) -> None:
        """Read what the kernel holds now for this handle's worker and deliver it on the calling thread
        (a lazy handle's reader calls this before it uses its data). A no-op while the worker wakes
        per message (not lazy, or :meth:`set_eager`), and on the worker's own thread."""
        host = self._host
        if not host._lazy or host._eager or threading.current_thread() is host._thread:
            return
        me = threading.get_ident()
        if host._puller == me:  # a callback of this pull pulls again: its frames come in order anyway
            return
        with host._read_lock:
            if host._retired:
                return
            host._puller = me
            try:
                host._apply_ops()  # a connection handed over a moment ago may hold data already
                for conn in list(host._conns.values()):
                    host._read(conn)
                host._last_read = time.monotonic()
            finally:
                host._puller = 0

    def set_eager(self, eager: bool) -> None:
        """For a lazy handle: while ``eager``, its worker wakes per message (someone waits for data);
        then lazy again. Applies to every handle its worker serves."""
        host = self._host
        if not host._lazy or host._eager == eager:
            return
        host._eager = eager
        self._wakeup()  # the worker switches to the other kind of wait

    def add_callback(self, callback: Callable[..., Any], callback_args: Any = None) -> None:
        self._callbacks = (*self._callbacks, (callback, callback_args))

    def get_num_connections(self) -> int:
        return len(self._sub.connections)

    def publisher_ids(self) -> frozenset[str]:
        """Caller ids of the publishers connected now (handshake done: what they publish reaches us)."""
        return frozenset(c.publisher for c in list(self._sub.connections.values()) if not c.closed)

    def unregister(self) -> None:
        """Stop receiving; the worker thread ends (joined unless called from a callback)."""
        if self._closed:
            return
        self._sub.node.release_subscriber(self)
        host = self._host
        with host._ops_lock:
            self._closed = True
            shared = any(not h._closed for h in host._served)
            if shared:  # the thread goes on for the others: it hands this handle's streams on
                host._ops.append(("release", self))
        self._wakeup()
        me = threading.get_ident()
        # not from a callback: on the worker's thread, in a pull, which holds what the worker needs, or
        # in a direct callback on a publisher's thread, which holds the lock the worker may wait for
        if (
            threading.current_thread() is self._thread
            or host._puller == me
            or (self._direct and self._busy_owner == me)
        ):
            return
        if not shared:
            self._thread.join(2.0)
        if self._direct:
            # a publisher's thread may be calling back directly: once unregister returns, no callback runs
            if self._busy.acquire(timeout=2.0):
                self._busy.release()

    @property
    def closed(self) -> bool:
        return self._closed
