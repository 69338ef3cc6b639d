"""Two roscores bridged by two ``zenoh-bridge-ros1`` processes over TCP on localhost, no multicast.

One bridge listens, the other connects (mode peer). Real rospy programs on one graph, ninjemys nodes
on the other, in both directions; a service call across; a latched topic seen by a late subscriber
across; a bridge killed and restarted; bad endpoints. Ten robots with identical names: test_fleet.py.
"""

from __future__ import annotations

import queue
import subprocess
import time

import pytest

pytest.importorskip("zenoh", reason="eclipse-zenoh (the zenoh extra) is not installed")

from ninjemys.errors import ServiceError  # noqa: E402
from ninjemys.node import Node  # noqa: E402
from ninjemys.testing import (  # noqa: E402
    NodeProcess,
    free_port,
    have_ros1,
    ninjemys_bin,
    ros1_env,
    run_master,
    run_real_roscore,
    wait_until,
)
from ninjemys.zenoh_bridge.discovery import LOST_AFTER  # noqa: E402

from .bridges import SET_BOOL_SERVER, TALKER, bridged, rospy, start_bridge  # noqa: E402

needs_ros1 = pytest.mark.skipif(not have_ros1(), reason="Debian's ROS 1 (rospy) is not installed")


@pytest.fixture
def two_graphs(tmp_path, monkeypatch):
    """(uri_a, uri_b, zenoh port): two masters; bridges are started by each test."""
    monkeypatch.setenv("ROS_HOME", str(tmp_path))
    monkeypatch.setenv("ROS_HOSTNAME", "localhost")
    with run_master() as uri_a, run_master() as uri_b:
        yield uri_a, uri_b, free_port()


@pytest.fixture
def bridges(two_graphs):
    uri_a, uri_b, port = two_graphs
    with (
        start_bridge(uri_a, "-l", f"tcp/127.0.0.1:{port}") as a,
        start_bridge(uri_b, "-e", f"tcp/127.0.0.1:{port}", "--client_bridging_mode", "auto") as b,
    ):
        yield uri_a, uri_b, a, b


def listen(uri: str, topic: str) -> tuple[Node, queue.Queue[str]]:
    from std_msgs.msg import String

    got: queue.Queue[str] = queue.Queue()
    node = Node("listener", master_uri=uri, anonymous=True, rosout=False)
    node.subscriber(topic, String, lambda m: got.put(m.data))
    return node, got


def first(got: queue.Queue[str], timeout: float = 30.0) -> str:
    try:
        return got.get(timeout=timeout)
    except queue.Empty:
        raise AssertionError(f"nothing arrived across the bridge within {timeout} s") from None


@pytest.mark.ros1
@needs_ros1
@pytest.mark.parametrize("direction", ["a_to_b", "b_to_a"])
def test_rospy_talker_to_ninjemys_listener_across(bridges, direction):
    uri_a, uri_b, _, _ = bridges
    talk_uri, listen_uri = (uri_a, uri_b) if direction == "a_to_b" else (uri_b, uri_a)
    with rospy(talk_uri, TALKER, "/chatter", direction):
        node, got = listen(listen_uri, "/chatter")
        try:
            text = first(got)
            assert text.startswith(f"{direction} ")
            # a stream, not one message: the numbers keep rising
            later = [first(got) for _ in range(5)]
            numbers = [int(t.split()[1]) for t in [text, *later]]
            assert numbers == sorted(numbers) and numbers[-1] > numbers[0]
        finally:
            node.shutdown()


@pytest.mark.ros1
@needs_ros1
def test_service_call_across(bridges):
    from std_srvs.srv import SetBool

    uri_a, uri_b, _, _ = bridges
    with rospy(uri_a, SET_BOOL_SERVER) as server:
        server.wait_for("ready", timeout=30)
        node = Node("caller", master_uri=uri_b, rosout=False)
        try:
            node.wait_for_service("/arm", timeout=30)
            proxy = node.service_proxy("/arm", SetBool)
            assert (proxy(True).success, proxy(True).message) == (True, "armed")
            assert proxy(False).message == "disarmed"
            # the server's refusal comes back across as the caller's error, with its text
            node.wait_for_service("/brake", timeout=30)
            with pytest.raises(ServiceError, match="arm jammed"):
                node.service_proxy("/brake", SetBool)(True)
        finally:
            node.shutdown()


def test_latched_topic_reaches_a_late_subscriber_across(bridges):
    from std_msgs.msg import String

    uri_a, uri_b, _, _ = bridges
    talker = Node("mapper", master_uri=uri_a, rosout=False)
    try:
        pub = talker.publisher("/map_version", String, latch=True)
        pub.publish(String("map v1"))
        bridged(uri_b, "/map_version", "pub")  # the far side knows the topic ...
        node, got = listen(uri_b, "/map_version")  # ... and a subscriber comes after the only message
        try:
            assert first(got) == "map v1"
        finally:
            node.shutdown()
    finally:
        talker.shutdown()


def test_bridge_killed_and_restarted_graph_recovers(two_graphs):
    from std_msgs.msg import String

    uri_a, uri_b, port = two_graphs
    talker = Node("talker", master_uri=uri_a, rosout=False)
    pub = talker.publisher("/chatter", String)
    node, got = listen(uri_b, "/chatter")
    try:
        with start_bridge(uri_b, "-l", f"tcp/127.0.0.1:{port}"):
            for round_ in ("first", "second"):
                with start_bridge(uri_a, "-e", f"tcp/127.0.0.1:{port}") as a:
                    wait_until(lambda r=round_: pub.publish(String(r)) or _drain_has(got, r), timeout=30,
                               what=f"{round_} bridge to relay", step=0.1)  # fmt: skip
                    a.kill()  # SIGKILL: no goodbye; its registration on master A stays behind, stale
                # past the beacon timeout: the far side has forgotten everything the dead bridge announced,
                # so the second round is a rediscovery, by a bridge that takes over the stale registration
                time.sleep(LOST_AFTER + 0.5)
                _drain_has(got, "")
    finally:
        node.shutdown()
        talker.shutdown()


def _drain_has(got: queue.Queue[str], text: str) -> bool:
    found = False
    while not got.empty():
        found |= got.get_nowait() == text
    return found


@pytest.mark.parametrize(
    ("argv", "named"),
    [
        (["-e", "127.0.0.1:7447"], "--connect: bad endpoint '127.0.0.1:7447'"),
        (["-l", "tcp/127.0.0.1"], "--listen: bad endpoint 'tcp/127.0.0.1'"),
    ],
)
def test_bad_endpoint_one_clear_error(argv, named):
    r = subprocess.run([ninjemys_bin("zenoh-bridge-ros1"), *argv], capture_output=True, text=True, timeout=60)
    assert r.returncode == 2
    assert r.stderr.splitlines() == [r.stderr.strip()], r.stderr  # one line, no traceback
    assert named in r.stderr


def test_unreachable_endpoint_one_clear_error():
    port = free_port()
    r = subprocess.run(
        [ninjemys_bin("zenoh-bridge-ros1"), "-m", "client", "-e", f"tcp/127.0.0.1:{port}"],
        capture_output=True, text=True, timeout=60,
    )  # fmt: skip
    assert r.returncode == 1
    assert len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert f"cannot open the Zenoh session (connect tcp/127.0.0.1:{port})" in r.stderr


def test_unknown_type_relayed_raw_with_its_definition(bridges):
    """A type no definition on this machine describes: bytes, md5 and definition still cross."""
    from ninjemys.bag.play import stand_in_class

    uri_a, uri_b, _, _ = bridges
    battery = stand_in_class("fleet_msgs/Battery", "0123456789abcdef0123456789abcdef", "float32 voltage\n")
    talker = Node("battery", master_uri=uri_a, rosout=False)
    node = Node("monitor", master_uri=uri_b, rosout=False)
    got: queue.Queue = queue.Queue()
    try:
        pub = talker.publisher("/battery", battery)
        bridged(uri_b, "/battery", "pub")
        node.subscriber("/battery", None, got.put, raw=True)
        wait_until(
            lambda: pub.publish_raw(b"\x00\x00\x40\x41") or not got.empty(), timeout=30, what="a message"
        )
        raw = got.get_nowait()
        assert bytes(raw.data) == b"\x00\x00\x40\x41"
        header = raw.connection_header
        assert (header["type"], header["md5sum"]) == (
            "fleet_msgs/Battery",
            "0123456789abcdef0123456789abcdef",
        )
        assert header["message_definition"] == "float32 voltage\n"
    finally:
        node.shutdown()
        talker.shutdown()


@pytest.mark.ros1
@needs_ros1
def test_real_roscores_and_real_tools_on_both_sides(tmp_path):
    """Nothing of ours but the bridges: Debian's roscore twice, rostopic pub on one, rostopic echo on the other."""
    port = free_port()
    with (
        run_real_roscore(tmp_path / "a") as uri_a,
        run_real_roscore(tmp_path / "b") as uri_b,
        start_bridge(uri_a, "-l", f"tcp/127.0.0.1:{port}"),
        start_bridge(uri_b, "-e", f"tcp/127.0.0.1:{port}"),
        NodeProcess(["/usr/bin/rostopic", "pub", "-r", "10", "/chatter", "std_msgs/String", "data: real"],
                    env=ros1_env(uri_a)),
    ):  # fmt: skip
        echo = subprocess.run(
            ["/usr/bin/rostopic", "echo", "-n", "1", "/chatter"],
            env=ros1_env(uri_b), capture_output=True, text=True, timeout=60,
        )  # fmt: skip
        assert echo.returncode == 0, echo.stderr
        assert 'data: "real"' in echo.stdout
