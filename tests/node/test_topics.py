"""Topics between ninjemys nodes in one process (each node has its own sockets, as across processes)."""

from __future__ import annotations

import threading
import time

from node_msgs import Image, Int64, String

from ninjemys.testing import wait_until


def _connected(pub, n: int = 1) -> bool:
    return wait_until(lambda: pub.get_num_connections() >= n)


def test_publish_reaches_subscriber_in_order(make_node) -> None:
    talker, listener = make_node("talker"), make_node("listener")
    got: list[str] = []
    done = threading.Event()

    def cb(msg: String) -> None:
        got.append(msg.data)
        if len(got) == 100:
            done.set()

    listener.subscriber("chatter", String, cb)
    pub = talker.publisher("chatter", String, queue_size=None)
    assert _connected(pub)
    for i in range(100):
        pub.publish(String(f"hello {i}"))
    assert done.wait(5)
    assert got == [f"hello {i}" for i in range(100)]


def test_callback_args_and_raw_subscription(make_node) -> None:
    talker, listener = make_node("talker"), make_node("listener")
    got: list[object] = []
    raw: list[object] = []
    listener.subscriber("chatter", String, lambda m, a: got.append((m.data, a)), callback_args="extra")
    listener.subscriber("chatter", String, raw.append, raw=True)
    pub = talker.publisher("chatter", String)
    assert _connected(pub)
    pub.publish(String("x"))
    assert wait_until(lambda: got and raw)
    assert got == [("x", "extra")]
    assert bytes(raw[0].data) == b"\x01\x00\x00\x00x"
    assert raw[0].connection_header["callerid"] == "/talker"
    assert raw[0].connection_header["type"] == "std_msgs/String"


def test_publish_framed_sends_a_frame_the_caller_built(make_node) -> None:
    """publish_framed: the caller packs the length with the message (robot_state_publisher's plans);
    socket and in-process subscribers get the message, a latched one reaches a late subscriber."""
    talker, listener = make_node("talker"), make_node("listener")
    got: list[str] = []
    listener.subscriber("framed", String, lambda m: got.append(m.data))
    local: list[str] = []
    talker.subscriber("framed", String, lambda m: local.append(m.data), intraprocess=True)
    pub = talker.publisher("framed", String, latch=True)
    assert _connected(pub, 2)
    pub.publish_framed(b"\x09\x00\x00\x00\x05\x00\x00\x00hello")
    assert wait_until(lambda: got == ["hello"] and local == ["hello"])
    late: list[str] = []
    make_node("late").subscriber("framed", String, lambda m: late.append(m.data))
    assert wait_until(lambda: late == ["hello"])


def test_latched_message_reaches_late_subscribers_per_publisher(make_node) -> None:
    talker, listener = make_node("talker"), make_node("listener")
    a = talker.publisher("static", String, latch=True)
    b = talker.publisher("static", String, latch=True)
    a.publish(String("from a"))
    b.publish(String("from b"))
    first: list[str] = []
    listener.subscriber("static", String, lambda m: first.append(m.data))
    assert wait_until(lambda: len(first) == 2)
    # both latched publishers of the process are kept (ROS 1 kept only the last one, ros_comm#146)
    assert sorted(first) == ["from a", "from b"]
    second: list[str] = []
    listener.subscriber("static", String, lambda m: second.append(m.data))
    # a later callback on the same topic gets the last latched message received, as in rospy
    assert wait_until(lambda: second == ["from b"])


def test_header_seq_is_set_per_publisher(make_node) -> None:
    talker, listener = make_node("talker"), make_node("listener")
    seqs: list[int] = []
    listener.subscriber("img", Image, lambda m: seqs.append(m.header.seq))
    pub = talker.publisher("img", Image, queue_size=None)
    assert _connected(pub)
    for _ in range(3):
        pub.publish(Image(2, 2, "mono8", 2, b"abcd"))
    assert wait_until(lambda: len(seqs) == 3)
    assert seqs == [1, 2, 3]  # as rospy: a per-publisher counter from 1


def test_large_image_arrives_intact(make_node) -> None:
    talker, listener = make_node("talker"), make_node("listener")
    payload = bytes(range(256)) * (1920 * 1080 * 3 // 256)
    got: list[Image] = []
    listener.subscriber("image", Image, got.append)
    pub = talker.publisher("image", Image)
    assert _connected(pub)
    pub.publish(Image(1080, 1920, "rgb8", 1920 * 3, payload))
    pub.publish(Image(1, 1, "rgb8", 3, b"xyz"))
    assert wait_until(lambda: len(got) == 2, timeout=10)
    assert got[0].data == payload and got[0].width == 1920
    assert got[1].data == b"xyz"


def test_md5_mismatch_is_refused_and_other_connections_keep_working(make_node, caplog) -> None:
    talker, good, bad = make_node("talker"), make_node("good"), make_node("bad")
    got: list[str] = []
    wrong: list[object] = []
    bad.subscriber("chatter", Int64, wrong.append)
    good.subscriber("chatter", String, lambda m: got.append(m.data))
    pub = talker.publisher("chatter", String)
    assert _connected(pub)
    time.sleep(0.3)
    assert pub.get_num_connections() == 1
    pub.publish(String("still fine"))
    assert wait_until(lambda: got == ["still fine"])
    assert wrong == []
    assert any("topic types do not match" in r.getMessage() for r in caplog.records)


def test_slow_subscriber_does_not_slow_publisher_or_other_subscribers(make_node) -> None:
    talker, slow_node, fast_node = make_node("talker"), make_node("slow"), make_node("fast")
    release = threading.Event()
    slow_got: list[int] = []
    fast_got: list[int] = []

    def slow_cb(msg: Int64) -> None:
        release.wait(10)
        slow_got.append(msg.data)

    slow_node.subscriber("n", Int64, slow_cb, queue_size=5)
    fast_node.subscriber("n", Int64, lambda m: fast_got.append(m.data))
    pub = talker.publisher("n", Int64, queue_size=100)
    assert _connected(pub, 2)
    start = time.monotonic()
    for i in range(2000):
        pub.publish(Int64(i))
    elapsed = time.monotonic() - start
    assert wait_until(lambda: len(fast_got) == 2000)
    assert fast_got == list(range(2000))
    assert elapsed < 5  # generous: the point is it did not wait for the blocked callback
    release.set()
    assert wait_until(lambda: slow_got and slow_got[-1] == 1999)
    # the slow subscriber's bounded queue kept the newest messages and dropped the oldest
    assert len(slow_got) < 100
    assert slow_got[-5:] == list(range(1995, 2000))
    assert slow_got == sorted(slow_got)


def test_unregister_and_connection_counts(make_node) -> None:
    talker, listener = make_node("talker"), make_node("listener")
    sub = listener.subscriber("chatter", String, lambda m: None)
    pub = talker.publisher("chatter", String)
    assert _connected(pub)
    assert wait_until(lambda: sub.get_num_connections() == 1)
    sub.unregister()
    assert wait_until(lambda: pub.get_num_connections() == 0)
    assert listener.get_subscriptions() == []
    pub.unregister()
    assert talker.get_publications() == [["/rosout", "rosgraph_msgs/Log"]]  # every node logs to /rosout


def test_publish_after_modification_sends_the_original(make_node) -> None:
    talker, listener = make_node("talker"), make_node("listener")
    got: list[str] = []
    listener.subscriber("chatter", String, lambda m: got.append(m.data))
    pub = talker.publisher("chatter", String, queue_size=None)
    assert _connected(pub)
    msg = String("before")
    pub.publish(msg)
    msg.data = "after"
    assert wait_until(lambda: got)
    assert got == ["before"]


def test_shutdown_leaves_no_thread_behind(master) -> None:
    from ninjemys.node import Node

    def ours() -> list[str]:
        prefixes = ("ninjemys-io", "sub:", "srv:", "reg:", "param-update", "shutdown")
        return [t.name for t in threading.enumerate() if t.name.startswith(prefixes)]

    talker = Node("talker", master_uri=master.uri)
    listener = Node("listener", master_uri=master.uri)
    listener.subscriber("chatter", String, lambda m: None)
    pub = talker.publisher("chatter", String)
    assert _connected(pub)
    assert ours()
    started = time.monotonic()
    talker.shutdown("done")
    listener.shutdown("done")
    assert time.monotonic() - started < 2
    assert ours() == []


def test_publisher_never_blocks_on_a_subscriber_that_stops_reading(make_node) -> None:
    import socket

    from ninjemys.wire import headers

    talker = make_node("talker")
    pub = talker.publisher("flood", String, queue_size=10)
    sock = socket.create_connection(("127.0.0.1", talker.tcpros_port))
    try:
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
        sock.sendall(
            headers.encode_header({"callerid": "/stuck", "topic": "/flood", "md5sum": "*", "type": "*"})
        )
        assert _connected(pub)
        payload = String("x" * 1024)
        started = time.monotonic()
        for _ in range(20000):  # 20 MB: far more than any socket buffer
            pub.publish(payload)
        assert time.monotonic() - started < 10
        conn = pub._pub.connections[0]
        assert len(conn._queue) <= 10
        assert conn.dropped > 0
    finally:
        sock.close()


def test_queue_size_none_is_lossless(make_node) -> None:
    talker, listener = make_node("talker"), make_node("listener")
    got: list[int] = []
    listener.subscriber("n", Int64, lambda m: got.append(m.data))
    pub = talker.publisher("n", Int64, queue_size=None)
    assert _connected(pub)
    for i in range(20000):
        pub.publish(Int64(i))
    assert wait_until(lambda: len(got) == 20000, timeout=20)
    assert got == list(range(20000))


def test_a_raising_callback_is_logged_as_rospys_bad_callback_on_rosout(make_node) -> None:
    """rospy logs a callback's exception as ``bad callback: <cb>`` plus the traceback at ERROR, so it
    reaches /rosout and rqt_console; the subscriber goes on with the next message."""
    from rosgraph_msgs.msg import Log

    listener, talker, watcher = make_node("listener"), make_node("talker"), make_node("watcher")
    logged: list = []
    watcher.subscriber("/rosout", Log, logged.append)
    got: list[str] = []

    def crashy(msg: String) -> None:
        if msg.data == "boom":
            raise ZeroDivisionError("the callback's own fault")
        got.append(msg.data)

    listener.subscriber("chatter", String, crashy)
    pub = talker.publisher("chatter", String, queue_size=10)
    assert _connected(pub)

    def heard_listener() -> bool:  # /rosout keeps nothing for late subscribers: connect first
        listener.log.info("are you there")
        return any(m.name == listener.name for m in logged)

    assert wait_until(heard_listener)
    pub.publish(String("boom"))
    pub.publish(String("after"))
    assert wait_until(lambda: got == ["after"])
    assert wait_until(lambda: any(m.msg.startswith("bad callback: ") for m in logged))
    entry = next(m for m in logged if m.msg.startswith("bad callback: "))
    assert entry.level == Log.ERROR
    assert entry.name == listener.name
    assert "crashy" in entry.msg.splitlines()[0]
    assert "ZeroDivisionError: the callback's own fault" in entry.msg
