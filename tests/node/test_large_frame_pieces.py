"""A frame far larger than the subscriber's read buffer (a 6 MB image-sized std_msgs/String), arriving
in uneven small pieces with pauses, in one piece before the handle has the stream, latched or not,
between small messages: every message arrives once, intact and in order, on every worker path (the
lone handle's solo rounds, fused or per-frame, and a bounded queue).

Why: tests/interop/test_topics_ros1.py::test_roscpp_6mb_message_to_us_intact once timed out (1 run in
~15). These feed the subscriber's worker directly through a socket pair, so each shape of arrival is
reproduced exactly, whatever the machine's load."""

from __future__ import annotations

import random
import socket
import threading
import time

import pytest

from ninjemys.idl.loader import get_message_class
from ninjemys.node.subscriber import SubConnection
from ninjemys.testing import wait_until

String = get_message_class("std_msgs/String")

BIG = "".join(chr(ord("a") + i % 26) for i in range(6_220_800))


def _frames(texts: list[str]) -> bytes:
    return b"".join(String(text).serialize_framed() for text in texts)


def _pieces(data: bytes, seed: int) -> list[bytes]:
    """``data`` cut in uneven pieces: a split length prefix first, then 1 byte to 200 kB each."""
    rng = random.Random(seed)
    out = [data[:2], data[2:3]]
    pos = 3
    while pos < len(data):
        n = rng.choice((1, 3, 4, 5, 1000, 4096, 65_535, 65_536, 65_537, 131_072, 200_000))
        out.append(data[pos : pos + n])
        pos += n
    return out


def _feed(sock: socket.socket, pieces: list[bytes], pause: float) -> threading.Thread:
    def run() -> None:
        for i, piece in enumerate(pieces):
            sock.sendall(piece)
            if pause and i % 7 == 0:
                time.sleep(pause)

    thread = threading.Thread(target=run, daemon=True)
    thread.start()
    return thread


def _attach(handle, sock: socket.socket, latching: bool) -> SubConnection:  # type: ignore[no-untyped-def]
    """Give ``handle``'s worker a stream from a fake publisher, as the loop does after a handshake (not
    listed in the subscription's connections: no publisher list drops it)."""
    sock.setblocking(False)
    header = {"callerid": "/fake_talker", "topic": handle.name, "type": "std_msgs/String",
              "md5sum": String._md5sum, "latching": "1" if latching else "0"}  # fmt: skip
    # after the master's first answer, which would drop a connection to a publisher it does not list
    assert wait_until(lambda: handle._sub.updates >= 1)
    conn = SubConnection(handle._sub, sock, "http://fake:1/", header)
    handle.post(("add", conn))
    return conn


@pytest.mark.parametrize("latching", [False, True], ids=["plain", "latched"])
@pytest.mark.parametrize("queue_size", [None, 1, 10], ids=["q=None", "q=1", "q=10"])
@pytest.mark.parametrize("arrival", ["pieces", "slow-pieces", "one-write-before-attach"])
def test_a_6mb_frame_arrives_intact_however_it_is_cut(
    make_node, latching: bool, queue_size: int | None, arrival: str
) -> None:
    node = make_node("big_listener")
    got: list[str] = []
    handle = node.subscriber("big", String, lambda m: got.append(m.data), queue_size=queue_size)
    ours, theirs = socket.socketpair(socket.AF_UNIX, socket.SOCK_STREAM)
    texts = ["before", BIG, "after"] if not latching else [BIG]
    data = _frames(texts)
    try:
        if arrival == "one-write-before-attach":  # the whole frame is on its way before the handle reads
            feeder = _feed(theirs, [data], 0.0)
            time.sleep(0.05)
            _attach(handle, ours, latching)
        else:
            _attach(handle, ours, latching)
            feeder = _feed(
                theirs, _pieces(data, seed=len(arrival)), 0.002 if arrival == "slow-pieces" else 0.0
            )
        feeder.join(30)
        assert not feeder.is_alive()
        assert wait_until(lambda: got[-1:] == texts[-1:], timeout=20), [len(t) for t in got]
        time.sleep(0.05)
        if queue_size is None:
            assert [len(t) for t in got] == [len(t) for t in texts]
            assert got == texts
        else:  # a bounded queue may drop the oldest of what arrived together: never the newest
            assert all(t in texts for t in got)  # each delivered message intact
            assert [texts.index(t) for t in got] == sorted({texts.index(t) for t in got})  # once, in order
            assert len(got) + handle.dropped == len(texts)
    finally:
        theirs.close()


def test_a_6mb_frame_then_a_stream_of_small_ones_through_the_fused_loop(make_node) -> None:
    """The lone handle's fused rounds: a large frame received in place between small frames that
    share its reads (prefix of the next frame in the same recv as the end of the big one)."""
    node = make_node("big_listener")
    got: list[str] = []
    handle = node.subscriber("big", String, lambda m: got.append(m.data), queue_size=None)
    ours, theirs = socket.socketpair(socket.AF_UNIX, socket.SOCK_STREAM)
    texts = [f"m{i}" for i in range(300)] + [BIG] + [f"n{i}" for i in range(300)] + [BIG, "end"]
    try:
        _attach(handle, ours, latching=False)
        _feed(theirs, _pieces(_frames(texts), seed=7), 0.001).join(30)
        assert wait_until(lambda: len(got) >= len(texts), timeout=20), len(got)
        assert got == texts
    finally:
        theirs.close()
