"""The publisher's write paths with generated message classes: bursts written a batch at a time and
finished by the loop once they stop, big frames sent in pieces with ``sendmsg``, and the copy that
keeps a publisher free to change its buffers once ``publish`` has returned."""

from __future__ import annotations

import socket
import struct
import threading
import time

from ninjemys.node import topics
from ninjemys.testing import wait_until
from ninjemys.wire import headers
from sensor_msgs.msg import Image
from std_msgs.msg import Int64

_BIG = 1920 * 1080 * 3


def _connected(pub, n: int = 1) -> bool:
    return wait_until(lambda: pub.get_num_connections() >= n)


def _image(data: bytes | bytearray, seq_tag: str = "cam") -> Image:
    img = Image(height=1080, width=1920, encoding="rgb8", step=1920 * 3, data=data)
    img.header.frame_id = seq_tag
    return img


def _raw_subscriber(port: int, topic: str, msg_class: type, rcvbuf: int | None = None) -> socket.socket:
    sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    if rcvbuf is not None:
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, rcvbuf)
    sock.connect(("127.0.0.1", port))
    sock.sendall(
        headers.encode_header(
            {"callerid": "/raw", "topic": topic, "md5sum": msg_class._md5sum, "type": msg_class._type}
        )
    )
    return sock


def _read_exact(sock: socket.socket, n: int) -> bytes:
    chunks, got = [], 0
    while got < n:
        chunk = sock.recv(min(n - got, 1 << 20))
        assert chunk, f"connection closed after {got} of {n} bytes"
        chunks.append(chunk)
        got += len(chunk)
    return b"".join(chunks)


def _read_frame(sock: socket.socket) -> bytes:
    (length,) = struct.unpack("<I", _read_exact(sock, 4))
    return _read_exact(sock, length)


def test_a_burst_arrives_whole_and_in_order_after_the_publisher_stops(make_node) -> None:
    talker, listener = make_node("talker"), make_node("listener")
    got: list[int] = []
    listener.subscriber("n", Int64, lambda m: got.append(m.data))
    pub = talker.publisher("n", Int64, queue_size=100000)
    assert _connected(pub)
    # 1000 back-to-back publishes: mostly queued and written in batches; the last few (fewer than a
    # batch) are only written by the loop's check once publishing stops
    for i in range(1000):
        pub.publish(Int64(i))
    assert wait_until(lambda: len(got) == 1000, timeout=10)
    assert got == list(range(1000))
    # a burst of two after a pause: the second frame is held back, then flushed
    time.sleep(0.05)
    pub.publish(Int64(-1))
    pub.publish(Int64(-2))
    assert wait_until(lambda: len(got) == 1002)
    assert got[-2:] == [-1, -2]


def test_big_frames_go_out_in_pieces_and_arrive_intact(make_node, monkeypatch) -> None:
    monkeypatch.setenv("NINJEMYS_SHM", "0")  # the TCPROS path (SHMROS: tests/node/test_shm.py)
    sent_with_sendmsg: list[int] = []
    original = topics.PubConnection.send_parts

    def spy(self, parts, total, queue_size):
        sent_with_sendmsg.append(total)
        return original(self, parts, total, queue_size)

    monkeypatch.setattr(topics.PubConnection, "send_parts", spy)
    talker, listener = make_node("talker"), make_node("listener")
    got: list[Image] = []
    listener.subscriber("image", Image, got.append)
    pub = talker.publisher("image", Image, queue_size=None)
    assert _connected(pub)
    frames = [bytes([i]) * _BIG for i in range(3)]
    pub.publish(_image(frames[0], "a"))
    pub.publish(_image(frames[1], "b"))
    pub.publish(_image(frames[2], "c"))
    assert wait_until(lambda: len(got) == 3, timeout=20)
    assert [m.header.frame_id for m in got] == ["a", "b", "c"]
    assert all(bytes(m.data) == frames[i] for i, m in enumerate(got))
    assert sent_with_sendmsg and all(total > _BIG for total in sent_with_sendmsg)


def test_changing_the_buffer_after_publish_does_not_change_what_is_sent(make_node) -> None:
    talker = make_node("talker")
    pub = talker.publisher("image", Image, queue_size=5)
    # a subscriber that reads nothing yet, with a small buffer: the kernel takes only part of the
    # frame, the rest stays with the publisher after publish() returns
    sock = _raw_subscriber(talker.tcpros_port, "/image", Image, rcvbuf=4096)
    try:
        sock.settimeout(10)
        assert _connected(pub)
        data = bytearray(b"\x01" * _BIG)
        pub.publish(_image(data))
        data[:] = b"\x02" * _BIG  # the caller reuses its buffer
        header_len = struct.unpack("<I", _read_exact(sock, 4))[0]
        _read_exact(sock, header_len)  # the publisher's connection header
        frame = _read_frame(sock)
        assert len(frame) > _BIG
        assert frame[-_BIG:] == b"\x01" * _BIG
    finally:
        sock.close()


def test_small_and_big_frames_keep_their_order(make_node) -> None:
    talker = make_node("talker")
    pub = talker.publisher("image", Image, queue_size=None)
    sock = _raw_subscriber(talker.tcpros_port, "/image", Image)
    sizes = [3, 3, 3, _BIG, 3, _BIG, 3]
    received: list[bytes] = []

    def read() -> None:  # queue_size=None blocks the publisher until the subscriber reads
        header_len = struct.unpack("<I", _read_exact(sock, 4))[0]
        _read_exact(sock, header_len)
        for _ in sizes:
            received.append(_read_frame(sock))

    reader = threading.Thread(target=read, daemon=True)
    try:
        sock.settimeout(10)
        assert _connected(pub)
        reader.start()
        for i, size in enumerate(sizes):  # back to back: the small ones are queued as a burst
            pub.publish(_image(bytes([i]) * size, str(i)))
        reader.join(20)
        assert len(received) == len(sizes)
        for i, (size, frame) in enumerate(zip(sizes, received, strict=True)):
            msg = Image.deserialize_from(frame)
            assert msg.header.frame_id == str(i)
            assert bytes(msg.data) == bytes([i]) * size
    finally:
        sock.close()
