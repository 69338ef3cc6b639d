"""queue_size on the publisher side bounds only what the kernel refused, as in ROS 1: a burst the
socket takes is never trimmed, a stalled subscriber gets the newest frames and loses the oldest."""

from __future__ import annotations

import socket
import struct

from ninjemys.testing import wait_until
from ninjemys.wire import headers
from std_msgs.msg import Int64, String

_PAD = "x" * 8000  # 2,000 of these are far more than a loopback socket's buffers hold


def test_a_tight_loop_past_queue_size_loses_nothing_the_kernel_takes(make_node) -> None:
    talker, listener = make_node("talker"), make_node("listener")
    got: list[int] = []
    listener.subscriber("n", Int64, lambda m: got.append(m.data), queue_size=None)
    pub = talker.publisher("n", Int64, queue_size=10)
    assert wait_until(lambda: pub.get_num_connections() == 1)
    for i in range(1000):  # back to back: a burst, 100x queue_size; ~12 KB, the kernel takes it all
        pub.publish(Int64(i))
    assert wait_until(lambda: len(got) == 1000, timeout=10), len(got)
    assert got == list(range(1000))
    (conn,) = pub._pub.connections
    assert conn.dropped == 0


def _read_exact(sock: socket.socket, n: int) -> bytes:
    chunks, got = [], 0
    while got < n:
        chunk = sock.recv(min(n - got, 1 << 20))
        assert chunk, f"connection closed after {got} of {n} bytes"
        chunks.append(chunk)
        got += len(chunk)
    return b"".join(chunks)


def test_a_stalled_subscriber_gets_the_newest_and_loses_the_oldest(make_node) -> None:
    talker = make_node("talker")
    pub = talker.publisher("s", String, queue_size=10)
    sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
    sock.connect(("127.0.0.1", talker.tcpros_port))
    sock.sendall(
        headers.encode_header(
            {"callerid": "/raw", "topic": "/s", "md5sum": String._md5sum, "type": String._type}
        )
    )
    total = 2000
    try:
        sock.settimeout(10)
        assert wait_until(lambda: pub.get_num_connections() == 1)
        for i in range(total):  # nobody reads: the kernel fills up, then the queue bounds the rest
            pub.publish(String(f"{i:06d}{_PAD}"))
        (conn,) = pub._pub.connections
        assert conn.dropped > 0
        (header_len,) = struct.unpack("<I", _read_exact(sock, 4))
        _read_exact(sock, header_len)
        received: list[int] = []
        while not received or received[-1] != total - 1:
            (length,) = struct.unpack("<I", _read_exact(sock, 4))
            received.append(int(String.deserialize_from(_read_exact(sock, length)).data[:6]))
        # in order, never a duplicate, and the newest queue_size last: the oldest are the ones dropped.
        # On a quiet machine the dropped run is one block (what the kernel took, then the newest
        # ten); when the writer thread is preempted mid-burst the queue also trims earlier, so the
        # test does not assert a single gap
        assert received == sorted(set(received))
        assert received[-10:] == list(range(total - 10, total))
        assert len(received) < total
        assert conn.dropped == total - len(received)
    finally:
        sock.close()
