"""In-process delivery (INTRAPROCESS): a publisher and a subscriber of one process, made with
``intraprocess=True``, hand over the message object without a socket or serialization; the topic
behaves as over TCPROS (latching, queue_size, mixed subscribers, unregister) and getBusInfo names it."""

from __future__ import annotations

import os
import subprocess
import sys
import threading
import time

import pytest
from node_msgs import String

from ninjemys.idl.loader import get_message_class
from ninjemys.testing import have_ros1, ninjemys_bin, ros1_env, wait_until

Image = get_message_class("sensor_msgs/Image")
Header = get_message_class("std_msgs/Header")


def _transports(node, topic: str) -> list[str]:  # noqa: ANN001
    return sorted(entry[3] for entry in node.bus_info() if entry[4] == topic)


def test_both_ends_opted_in_share_the_object_and_the_bus_info_says_intraprocess(make_node) -> None:  # noqa: ANN001
    talker = make_node("talker")
    listener = make_node("listener")
    pub = talker.publisher("chatter", String, intraprocess=True)
    got: list[object] = []
    threads: list[str] = []

    def on_msg(msg: object) -> None:
        got.append(msg)
        threads.append(threading.current_thread().name)

    listener.subscriber("chatter", String, on_msg, intraprocess=True)
    assert wait_until(lambda: pub.get_num_connections() == 1)
    msgs = [String(data=f"m{i}") for i in range(5)]
    for msg in msgs:
        pub.publish(msg)
    assert wait_until(lambda: len(got) == 5)
    assert all(a is b for a, b in zip(got, msgs, strict=True))
    # the callback runs on the subscriber's own thread, as over a socket
    assert set(threads) == {"sub:/chatter"}
    assert _transports(talker, "/chatter") == ["INTRAPROCESS"]
    assert _transports(listener, "/chatter") == ["INTRAPROCESS"]
    (entry,) = [e for e in listener.bus_info() if e[4] == "/chatter"]
    assert (
        entry[1] == talker.uri
        and entry[2] == "i"
        and entry[6] == f"INTRAPROCESS connection from [{talker.name}]"
    )
    stats = {t: conns for t, _, conns in talker.bus_stats()[0]}
    assert stats["/chatter"][0][2] == 5  # messages handed over


def test_a_node_subscribing_to_its_own_topic(make_node) -> None:  # noqa: ANN001
    node = make_node("loopback")
    pub = node.publisher("self", Image, intraprocess=True)
    got: list[object] = []
    node.subscriber("self", Image, got.append, intraprocess=True)
    assert wait_until(lambda: pub.get_num_connections() == 1)
    msg = Image(encoding="mono8")
    pub.publish(msg)
    assert wait_until(lambda: len(got) == 1)
    assert got[0] is msg and msg.header.seq == 1  # the publisher numbers headers as over TCPROS
    assert _transports(node, "/self") == ["INTRAPROCESS", "INTRAPROCESS"]


def test_one_end_not_opted_in_means_a_copy(make_node) -> None:  # noqa: ANN001
    talker = make_node("talker")
    pub = talker.publisher("chatter", Header)  # did not promise to leave its messages alone
    copies: list[object] = []
    make_node("copying").subscriber("chatter", Header, copies.append, intraprocess=True)
    over_socket: list[object] = []
    shy = talker.publisher("other", Header, intraprocess=True)
    make_node("shy").subscriber("other", Header, over_socket.append)  # not opted in: a socket
    assert wait_until(lambda: pub.get_num_connections() == 1 and shy.get_num_connections() == 1)
    assert _transports(talker, "/chatter") == ["INTRAPROCESS"]
    assert _transports(talker, "/other") in (["TCPROS"], ["UNIXROS"], ["SHMROS"])
    msg = Header(frame_id="a")
    pub.publish(msg)
    shy.publish(msg)
    msg.frame_id = "changed after publish"
    assert wait_until(lambda: len(copies) == 1 and len(over_socket) == 1)
    for got in (copies[0], over_socket[0]):
        assert got is not msg and got.frame_id == "a"


def test_latching_reaches_late_in_process_and_socket_subscribers(make_node) -> None:  # noqa: ANN001
    talker = make_node("talker")
    pub = talker.publisher("map", Header, latch=True, intraprocess=True)
    latched = Header(frame_id="map")
    pub.publish(latched)  # nobody listens yet
    late: list[object] = []
    make_node("late").subscriber("map", Header, late.append, intraprocess=True)
    assert wait_until(lambda: len(late) == 1)
    assert late[0] is latched
    # a socket subscriber comes later still: it gets the latched message serialized on demand
    remote: list[object] = []
    make_node("remote").subscriber("map", Header, remote.append)
    assert wait_until(lambda: len(remote) == 1)
    assert remote[0].frame_id == "map" and remote[0] is not latched
    # the latest message is what the next late subscriber gets
    newer = Header(frame_id="newer")
    pub.publish(newer)
    later: list[object] = []
    make_node("later").subscriber("map", Header, later.append, intraprocess=True)
    assert wait_until(lambda: len(later) == 1)
    assert later[0] is newer


def test_queue_size_keeps_the_newest_while_the_callback_is_busy(make_node) -> None:  # noqa: ANN001
    talker = make_node("talker")
    pub = talker.publisher("burst", Header, intraprocess=True, queue_size=100)
    release = threading.Event()
    got: list[str] = []

    def slow(msg) -> None:  # noqa: ANN001
        got.append(msg.frame_id)
        release.wait(10)

    sub = make_node("slow").subscriber("burst", Header, slow, queue_size=2, intraprocess=True)
    assert wait_until(lambda: pub.get_num_connections() == 1)
    pub.publish(Header(frame_id="first"))
    assert wait_until(lambda: got == ["first"])  # the callback now blocks
    for i in range(10):
        pub.publish(Header(frame_id=str(i)))
    release.set()
    assert wait_until(lambda: len(got) == 3)
    time.sleep(0.2)
    assert got == ["first", "8", "9"]
    assert sub.dropped == 8


def test_an_unbounded_subscriber_gets_the_publishers_queue_size(make_node) -> None:  # noqa: ANN001
    """As over TCPROS: a bounded publisher drops the oldest messages waiting for a lagging subscriber,
    a queue_size=None publisher waits for it and loses nothing."""
    talker = make_node("talker")
    bounded = talker.publisher("bounded", Header, intraprocess=True, queue_size=3)
    lossless = talker.publisher("lossless", Header, intraprocess=True, queue_size=None)
    release = threading.Event()
    got: dict[str, list[str]] = {"bounded": [], "lossless": []}

    def slow(msg, topic) -> None:  # noqa: ANN001
        got[topic].append(msg.frame_id)
        release.wait(20)

    listener = make_node("slow")
    for topic in got:
        listener.subscriber(topic, Header, slow, callback_args=topic, intraprocess=True)  # queue_size=None
    assert wait_until(lambda: bounded.get_num_connections() == 1 and lossless.get_num_connections() == 1)
    bounded.publish(Header(frame_id="first"))
    lossless.publish(Header(frame_id="first"))
    assert wait_until(lambda: got["bounded"] == ["first"] and got["lossless"] == ["first"])
    for i in range(10):
        bounded.publish(Header(frame_id=str(i)))
    done = threading.Event()

    def flood() -> None:
        for i in range(400):
            lossless.publish(Header(frame_id=str(i)))
        done.set()

    threading.Thread(target=flood, daemon=True).start()
    assert not done.wait(0.5)  # the publisher waits for its lagging subscriber
    release.set()
    assert done.wait(20)
    assert wait_until(lambda: len(got["lossless"]) == 401 and len(got["bounded"]) == 4)
    assert got["lossless"] == ["first", *map(str, range(400))]
    assert got["bounded"] == ["first", "7", "8", "9"]
    stats = {t: conns for t, _, conns in talker.bus_stats()[0]}
    assert stats["/bounded"][0][2] == 11 and stats["/lossless"][0][2] == 401


def test_several_subscribers_mixed_in_process_and_remote(make_node, master) -> None:  # noqa: ANN001
    talker = make_node("talker")
    pub = talker.publisher("chatter", String, intraprocess=True)
    shared: list[object] = []
    copied: list[object] = []
    two = make_node("two")
    two.subscriber("chatter", String, shared.append, intraprocess=True)
    two.subscriber("chatter", String, copied.append)  # a second handle, not opted in: a copy
    code = (
        "import sys, time\n"
        "from ninjemys.node import Node\n"
        "from std_msgs.msg import String\n"
        "n = Node('remote', master_uri=sys.argv[1])\n"
        "got = []\n"
        "n.subscriber('/chatter', String, lambda m: got.append(m.data))\n"
        "print('ready', flush=True)\n"
        "t = time.monotonic()\n"
        "while len(got) < 3 and time.monotonic() - t < 20: time.sleep(0.01)\n"
        "print(' '.join(got), flush=True)\n"
        "n.shutdown()\n"
    )
    child = subprocess.Popen([sys.executable, "-c", code, master.uri], stdout=subprocess.PIPE, text=True)
    try:
        assert child.stdout is not None and child.stdout.readline().strip() == "ready"
        assert wait_until(lambda: pub.get_num_connections() == 2, timeout=20)
        assert _transports(talker, "/chatter") in (
            ["INTRAPROCESS", "TCPROS"],
            ["INTRAPROCESS", "UNIXROS"],
            ["INTRAPROCESS", "SHMROS"],
        )
        msgs = [String(data=f"m{i}") for i in range(3)]
        for msg in msgs:
            pub.publish(msg)
        out, _ = child.communicate(timeout=30)
    finally:
        if child.poll() is None:
            child.kill()
            child.wait()
    assert out.strip() == "m0 m1 m2"
    assert wait_until(lambda: len(shared) == 3 and len(copied) == 3)
    assert all(a is b for a, b in zip(shared, msgs, strict=True))
    assert [m.data for m in copied] == ["m0", "m1", "m2"] and not any(
        a is b for a, b in zip(copied, msgs, strict=True)
    )


def test_unregister_either_end(make_node) -> None:  # noqa: ANN001
    talker = make_node("talker")
    listener = make_node("listener")
    pub = talker.publisher("chatter", String, intraprocess=True)
    got: list[object] = []
    sub = listener.subscriber("chatter", String, got.append, intraprocess=True)
    assert wait_until(lambda: pub.get_num_connections() == 1)
    sub.unregister()
    pub.publish(String(data="after"))  # the handle is closed: nothing reaches its callback
    assert wait_until(lambda: pub.get_num_connections() == 0)
    time.sleep(0.2)
    assert got == [] and _transports(talker, "/chatter") == []
    # and the publisher's side: the subscriber's connection goes, a new publisher is found again
    sub = listener.subscriber("chatter", String, got.append, intraprocess=True)
    assert wait_until(lambda: pub.get_num_connections() == 1)
    pub.unregister()
    assert wait_until(lambda: sub.get_num_connections() == 0)
    pub2 = talker.publisher("chatter", String, intraprocess=True)
    assert wait_until(lambda: pub2.get_num_connections() == 1)
    pub2.publish(String(data="again"))
    assert wait_until(lambda: [m.data for m in got] == ["again"])


def test_a_type_mismatch_is_refused_with_one_line(make_node, caplog) -> None:  # noqa: ANN001
    talker = make_node("talker")
    pub = talker.publisher("mixed", String, intraprocess=True)
    make_node("wrong").subscriber("mixed", Header, lambda m: None, intraprocess=True)
    assert wait_until(lambda: "cannot subscribe to" in caplog.text)
    assert pub.get_num_connections() == 0
    lines = [r for r in caplog.records if "in-process" in r.getMessage()]
    assert len(lines) == 1 and "/mixed" in lines[0].getMessage()


def test_raw_subscribers_get_the_bytes(make_node) -> None:  # noqa: ANN001
    talker = make_node("talker")
    pub = talker.publisher("img", Image, intraprocess=True)
    raw: list[bytes] = []
    make_node("raw").subscriber(
        "img", Image, lambda m: raw.append(bytes(m.data)), raw=True, intraprocess=True
    )
    assert wait_until(lambda: pub.get_num_connections() == 1)
    img = Image(height=1, width=3, encoding="mono8", step=3, data=b"abc")
    pub.publish(img)
    assert wait_until(lambda: len(raw) == 1)
    assert raw[0] == img.serialize_to_bytes()


@pytest.mark.parametrize("rosnode", ["ninjemys", pytest.param("ros1", marks=pytest.mark.ros1)])
def test_rosnode_info_names_the_in_process_transport(make_node, master, rosnode) -> None:  # noqa: ANN001
    """ROS 1 prints a connection's transport in ``rosnode info`` (from getBusInfo), and only there:
    ``rostopic info`` lists nodes, not connections, in ROS 1 and here alike."""
    if rosnode == "ros1" and not have_ros1():
        pytest.skip("Debian's ROS 1 is not installed")
    talker = make_node("talker")
    pub = talker.publisher("chatter", String, intraprocess=True)
    make_node("listener").subscriber("chatter", String, lambda m: None, intraprocess=True)
    assert wait_until(lambda: pub.get_num_connections() == 1)
    if rosnode == "ros1":
        cmd, env = ["/usr/bin/rosnode", "info", "/talker"], ros1_env(master.uri)
    else:
        cmd, env = [ninjemys_bin("rosnode"), "info", "/talker"], dict(os.environ, ROS_MASTER_URI=master.uri)
    out = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=60).stdout
    block = out[out.index(" * topic: /chatter") :]
    assert " * topic: /chatter\n    * to: /listener" in block
    assert "    * direction: outbound" in block and "    * transport: INTRAPROCESS" in block
