"""The small-message paths of issue 25: which publish is a burst (batched) and which goes out at once,
SHMROS inline frames tagged once by the publication and cut untagged by the reader."""

from __future__ import annotations

import socket
from typing import Any

import pytest

from ninjemys.node import shm_link, topics
from ninjemys.wire.tcpros import FrameReader, TaggedFrame, pack_len


class _Loop:
    def __init__(self) -> None:
        self.calls: list[Any] = []

    def call_soon(self, fn: Any, *args: Any) -> None:
        self.calls.append(fn)

    def defer(self, fn: Any, *args: Any) -> None:
        self.calls.append(fn)

    def call_later(self, delay: float, fn: Any, *args: Any) -> None:
        self.calls.append(fn)

    def add_writer(self, fd: int, fn: Any) -> None:
        self.calls.append(fn)


class _Node:
    name = "/pub"

    def __init__(self) -> None:
        self.runtime = _Loop()
        self.runtime.loop = self.runtime  # type: ignore[attr-defined]


class _Clock:
    def __init__(self) -> None:
        self.now = 100.0

    def __call__(self) -> float:
        return self.now


@pytest.fixture
def clock(monkeypatch: pytest.MonkeyPatch) -> _Clock:
    fake = _Clock()
    monkeypatch.setattr(topics, "_clock", fake)
    return fake


def _pair(family: int = socket.AF_UNIX) -> tuple[socket.socket, socket.socket]:
    if family == socket.AF_UNIX:
        a, b = socket.socketpair()
    else:
        server = socket.create_server(("127.0.0.1", 0))
        a = socket.create_connection(server.getsockname())
        b, _ = server.accept()
        server.close()
    a.setblocking(False)
    return a, b


def _drain(sock: socket.socket, expect: int = 0) -> bytes:
    """What has arrived; with ``expect``, waits (up to 5 s) until that many bytes have (loopback TCP)."""
    got = b""
    while True:
        if len(got) >= expect:
            sock.setblocking(False)
        else:
            sock.settimeout(5.0)
        try:
            chunk = sock.recv(1 << 20)
        except (BlockingIOError, TimeoutError):
            return got
        if not chunk:
            return got
        got += chunk
        if expect and len(got) >= expect:
            return got


FRAME = pack_len(4) + b"abcd"


@pytest.mark.parametrize("family", [socket.AF_UNIX, socket.AF_INET])
def test_a_publish_after_a_round_trip_goes_out_at_once(clock: _Clock, family: int) -> None:
    a, b = _pair(family)
    conn = topics.PubConnection(_Node(), a, "/t", "/sub")  # type: ignore[arg-type]
    for _ in range(20):
        clock.now += 30e-6  # a ping-pong: the previous write ended a whole round trip ago
        conn.send(FRAME, 10)
        assert not conn._queue and conn._partial is None
    assert len(_drain(b, 20 * len(FRAME))) == 20 * len(FRAME)
    assert conn.node.runtime.calls == []  # the I/O loop never had to write a reply


class _PreemptedWrites:
    """A clock under which every write takes ``took`` seconds: the publishing thread lost the CPU
    inside ``send`` (each publish reads the clock before and after its write)."""

    def __init__(self, took: float) -> None:
        self.now = 100.0
        self.took = took
        self._end = False

    def __call__(self) -> float:
        self._end = not self._end
        return self.now if self._end else self.now + self.took


@pytest.mark.parametrize("queue_size", [10, None])
@pytest.mark.parametrize("family", [socket.AF_UNIX, socket.AF_INET])
def test_a_publish_right_after_a_preempted_write_goes_out_at_once(
    monkeypatch: pytest.MonkeyPatch, family: int, queue_size: int | None
) -> None:
    """On one CPU the subscriber runs while the publisher is inside ``send``, and a ping-pong's reply
    can be back before ``send`` returns: the next ping comes microseconds after the write ended, yet
    the subscriber waits for it. A write that took a burst's whole gap counts from its start, so it is
    no burst: written at once, never left to the I/O loop (it was, for 3 % of a one-CPU ping-pong's
    publishes: a wake-up of another thread each, the round trip's p99)."""
    clock = _PreemptedWrites(took=35e-6)
    monkeypatch.setattr(topics, "_clock", clock)
    a, b = _pair(family)
    conn = topics.PubConnection(_Node(), a, "/t", "/sub")  # type: ignore[arg-type]
    for _ in range(20):
        conn.send(FRAME, queue_size)
        assert not conn._queue and conn._partial is None
        clock.now += 37e-6  # the reply came during the write; the next ping 2 us after it ended
    assert len(_drain(b, 20 * len(FRAME))) == 20 * len(FRAME)
    assert conn.node.runtime.calls == []


@pytest.mark.parametrize("family", [socket.AF_UNIX, socket.AF_INET])
def test_a_flat_out_loop_is_batched(clock: _Clock, family: int) -> None:
    a, b = _pair(family)
    conn = topics.PubConnection(_Node(), a, "/t", "/sub")  # type: ignore[arg-type]
    for _ in range(topics._FLUSH_FRAMES):
        clock.now += 2e-6
        conn.send(FRAME, 10000)
    # the first went out alone; the rest waited to go out together in one send
    assert len(conn._queue) == topics._FLUSH_FRAMES - 1
    clock.now += 2e-6
    conn.send(FRAME, 10000)
    assert not conn._queue
    assert len(_drain(b, (topics._FLUSH_FRAMES + 1) * len(FRAME))) == (topics._FLUSH_FRAMES + 1) * len(FRAME)


@pytest.mark.parametrize("queue_size", [10, None])
def test_a_flood_into_a_lagging_subscriber_keeps_the_bound_or_loses_nothing(
    clock: _Clock, queue_size: int | None, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The burst path queues most frames without a call (issue 25); bounds still hold: queue_size=10
    keeps the newest 10 of what the kernel refused and drops the oldest; queue_size=None loses nothing
    (the publisher writes its backlog itself at the high-water mark)."""
    a, b = _pair()
    a.setsockopt(socket.SOL_SOCKET, socket.SO_SNDBUF, 4096)
    conn = topics.PubConnection(_Node(), a, "/t", "/sub")  # type: ignore[arg-type]
    if queue_size is None:  # the reader takes a little whenever the publisher must wait for it
        real_select = topics.select.select

        def reading_select(r: Any, w: Any, x: Any, t: float) -> Any:
            received.append(_drain(b))
            return real_select(r, w, x, t)

        monkeypatch.setattr(topics.select, "select", reading_select)
    received: list[bytes] = []
    count = 3000
    for i in range(count):
        clock.now += 1e-6
        conn.send(pack_len(4) + i.to_bytes(4, "little"), queue_size)
        if queue_size is not None:  # what waits because the kernel refused it is bounded
            assert len(conn._queue) <= (queue_size if conn._partial is not None else topics._FLUSH_FRAMES)
        else:  # synchronous: the backlog never passes the high-water mark (the publisher waits)
            assert len(conn._queue) <= topics._SYNC_HIGH_WATER
    while conn._queue or conn._partial is not None:
        received.append(_drain(b))
        conn._write_locked()
    received.append(_drain(b))
    stream = b"".join(received)
    seqs = [int.from_bytes(stream[k + 4 : k + 8], "little") for k in range(0, len(stream), 8)]
    assert seqs == sorted(seqs) and seqs[-1] == count - 1  # in order, the newest never dropped
    if queue_size is None:
        assert seqs == list(range(count)) and conn.dropped == 0
    else:
        assert conn.dropped > 0 and len(seqs) + conn.dropped == count


def test_between_the_marks_a_unix_socket_asks_whether_the_subscriber_waits(clock: _Clock) -> None:
    a, b = _pair()
    conn = topics.PubConnection(_Node(), a, "/t", "/sub")  # type: ignore[arg-type]
    assert conn._unread is not None
    conn.send(FRAME, 10)
    clock.now += 10e-6
    conn.send(FRAME, 10)  # the subscriber has not read the first frame: it is busy, batch
    assert len(conn._queue) == 1
    assert _drain(b) == FRAME
    conn._queue.clear()
    clock.now += 10e-6
    conn.send(FRAME, 10)  # everything read: the subscriber waits for this one
    assert not conn._queue and _drain(b) == FRAME


def test_tcp_has_no_unread_probe() -> None:
    a, _b = _pair(socket.AF_INET)
    assert topics.transport.unread_probe(a) is None


def _shm_and_plain(msg_class: type) -> tuple[topics.Publication, socket.socket, socket.socket]:
    """A publication of /t with one SHMROS and one plain connection, and the two far ends."""
    node = _Node()
    pub = topics.Publication(node, "/t", msg_class)  # type: ignore[arg-type]
    a, b = _pair()
    c, d = _pair()
    pub.connections = (
        shm_link.ShmPubConnection(node, a, "/t", "/shm"),  # type: ignore[arg-type]
        topics.PubConnection(node, c, "/t", "/plain"),  # type: ignore[arg-type]
    )
    return pub, b, d


def test_shmros_small_frames_are_tagged_once_by_the_publication(clock: _Clock) -> None:
    assert topics._LARGE - 5 < shm_link.THRESHOLD  # every frame publish_small takes is inline for SHMROS
    from std_msgs.msg import String

    pub, b, d = _shm_and_plain(String)
    handle = topics.Publisher(pub, 10, False, None)
    handle.publish(String(data="hi"))
    body = pack_len(2) + b"hi"
    assert _drain(b) == pack_len(len(body) + 1) + b"\0" + body
    assert _drain(d) == pack_len(len(body)) + body


def test_a_small_generated_message_is_framed_in_one_piece_latched_untagged(
    clock: _Clock, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The fused path (issue 25): no frame_parts at all for a small generated type; a latched handle
    keeps the untagged frame, whichever connections it was sent to."""
    from ninjemys.idl.message import Message
    from std_msgs.msg import String

    pub, b, d = _shm_and_plain(String)
    handle = topics.Publisher(pub, None, True, None)

    def no_parts(self: Message) -> None:
        raise AssertionError("the generic frame was built")

    monkeypatch.setattr(String, "frame_parts", no_parts)
    handle.publish(String(data="latched"))
    body = pack_len(7) + b"latched"
    assert handle.latched == pack_len(len(body)) + body
    assert _drain(b) == pack_len(len(body) + 1) + b"\0" + body
    assert _drain(d) == pack_len(len(body)) + body


def test_a_long_string_leaves_the_fused_path_before_anything_is_sent(clock: _Clock) -> None:
    """A small type's message can still be big (a long string): it goes the general way, which never
    copies a big payload, and arrives once, whole."""
    from std_msgs.msg import String

    node = _Node()
    pub = topics.Publication(node, "/t", String)  # type: ignore[arg-type]
    c, d = _pair()
    pub.connections = (topics.PubConnection(node, c, "/t", "/plain"),)  # type: ignore[arg-type]
    handle = topics.Publisher(pub, None, False, None)
    text = "y" * (topics._LARGE + 10)
    assert not pub.publish_wire(String(data=text), String._wire_frame, handle)
    assert _drain(d) == b""
    handle.publish(String(data=text))
    body = pack_len(len(text)) + text.encode()
    assert _drain(d, len(body) + 4) == pack_len(len(body)) + body


def test_a_tagged_reader_cuts_inline_frames_untagged_and_keeps_the_others() -> None:
    reader = FrameReader(size=64, tagged=True)
    stream = (
        pack_len(3) + b"\0ab"  # inline
        + pack_len(2) + b"\x01n"  # a notice-like frame: kept whole, tagged
        + pack_len(0)  # no tag at all: kept, for the caller to refuse
        + pack_len(40) + b"\0" + b"x" * 39  # a large frame (>= half the buffer): received in place
    )  # fmt: skip
    frames: list[Any] = []
    for i in range(0, len(stream), 7):
        chunk = stream[i : i + 7]
        buf = reader.buffer()
        while len(chunk) > len(buf):  # a large frame's buffer is exactly its size
            buf[:] = chunk[: len(buf)]
            frames += reader.commit(len(buf))
            chunk = chunk[len(buf) :]
            buf = reader.buffer()
        buf[: len(chunk)] = chunk
        frames += reader.commit(len(chunk))
    assert frames[0] == b"ab" and frames[0].__class__ is bytes
    assert frames[1] == b"\x01n" and isinstance(frames[1], TaggedFrame)
    assert frames[2] == b"" and isinstance(frames[2], TaggedFrame)
    assert isinstance(frames[3], bytearray) and frames[3][0] == 0 and len(frames[3]) == 40
    assert reader.special == 3
    plain = FrameReader(size=64)
    buf = plain.buffer()
    buf[: len(FRAME)] = FRAME
    assert plain.commit(len(FRAME)) == [b"abcd"] and plain.special == 0


def test_a_tagged_reader_given_one_whole_frame_per_read_cuts_it_the_same_way() -> None:
    """The one-frame-per-read shortcut (the usual wake-up) keeps the tagged stream's rules."""
    reader = FrameReader(size=64, tagged=True)
    got: list[Any] = []
    for frame in (pack_len(3) + b"\0ab", pack_len(2) + b"\x01n", pack_len(3) + b"\0cd"):
        buf = reader.buffer()
        buf[: len(frame)] = frame
        got += reader.commit(len(frame))
    assert got == [b"ab", b"\x01n", b"cd"]
    assert got[0].__class__ is bytes and isinstance(got[1], TaggedFrame) and got[2].__class__ is bytes
    assert reader.special == 1
