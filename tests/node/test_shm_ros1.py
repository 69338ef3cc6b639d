"""SHMROS next to real ROS 1 peers: with shared memory on, rospy and roscpp nodes still talk to
ninjemys over TCPROS both ways, and one publication serves an SHMROS and a TCPROS subscriber at once."""

from __future__ import annotations

import hashlib
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parents[1] / "interop"))

from ros1_peers import ROSPY_IMAGE_PUB, ROSPY_IMAGE_SUB, roscpp, rospy  # noqa: E402

from ninjemys.idl.loader import get_message_class  # noqa: E402
from ninjemys.node import shm_ring  # noqa: E402
from ninjemys.testing import NodeProcess, wait_until  # noqa: E402

pytestmark = [
    pytest.mark.ros1,
    pytest.mark.skipif(not shm_ring.available(), reason="SHMROS needs Linux and /dev/shm"),
]

Image = get_message_class("sensor_msgs/Image")
String = get_message_class("std_msgs/String")


@pytest.fixture(autouse=True)
def shm_on(monkeypatch) -> None:  # noqa: ANN001
    monkeypatch.setenv("NINJEMYS_SHM", "1")


@pytest.fixture
def peers() -> Iterator[list[NodeProcess]]:
    started: list[NodeProcess] = []
    try:
        yield started
    finally:
        for child in started:
            child.kill()


def _start(peers: list[NodeProcess], child: NodeProcess) -> NodeProcess:
    peers.append(child)
    assert child.wait_for(lambda line: line == "ready", timeout=30), child.describe()
    return child


def _transports(node, topic: str) -> list[str]:  # noqa: ANN001
    return sorted(entry[3] for entry in node.bus_info() if entry[4] == topic)


def test_our_image_reaches_rospy_over_tcpros_and_ours_over_shm(make_node, master, peers) -> None:  # noqa: ANN001
    data = bytes(range(255, -1, -1)) * (1920 * 1080 * 3 // 256)
    camera = make_node("camera")
    pub = camera.publisher("image", Image, latch=True)
    pub.publish(Image(height=1080, width=1920, encoding="rgb8", step=5760, data=data))
    ours: list[Image] = []
    make_node("viewer").subscriber("image", Image, ours.append)
    child = _start(peers, rospy(ROSPY_IMAGE_SUB, master.uri))
    expected = f"image 1920x1080 rgb8 {len(data)} {hashlib.md5(data).hexdigest()}"
    assert child.wait_for(lambda line: line == expected, timeout=20), child.describe()
    assert wait_until(lambda: ours, timeout=10)
    assert ours[0].data == data
    assert _transports(camera, "/image") == ["SHMROS", "TCPROS"]
    # live (not latched) frames now: the ring for ours, TCPROS for rospy
    live = bytes(range(256)) * (1920 * 1080 * 3 // 256)
    pub.publish(Image(height=1080, width=1920, encoding="rgb8", step=5760, data=live))
    expected = f"image 1920x1080 rgb8 {len(live)} {hashlib.md5(live).hexdigest()}"
    assert child.wait_for(lambda line: line == expected, timeout=20), child.describe()
    assert wait_until(lambda: len(ours) == 2, timeout=10)
    assert ours[1].data == live and type(ours[1].data.obj).__name__ == "Lease"


def test_a_rospy_publisher_gets_tcpros_from_our_shm_offer(make_node, master, peers) -> None:  # noqa: ANN001
    got: list[Image] = []
    viewer = make_node("viewer")
    viewer.subscriber("image", Image, got.append)
    _start(peers, rospy(ROSPY_IMAGE_PUB, master.uri))
    assert wait_until(lambda: got, timeout=20), peers[0].describe()
    assert got[0].data == bytes(range(256)) * (1920 * 1080 * 3 // 256)
    assert _transports(viewer, "/image") == ["TCPROS"]


def test_a_roscpp_publisher_gets_tcpros_from_our_shm_offer(make_node, master, peers) -> None:  # noqa: ANN001
    listener = make_node("big_listener")
    got: list[String] = []
    listener.subscriber("big", String, got.append)
    _start(peers, roscpp(master.uri, "bigtalker"))
    assert wait_until(lambda: got, timeout=40), (listener.bus_info(), peers[0].describe())
    assert len(got[0].data) == 6220800 and got[0].data.startswith("abcdefghijklmnopqrstuvwxyz")
    assert _transports(listener, "/big") == ["TCPROS"]


def test_our_6mb_reaches_roscpp_over_tcpros_and_ours_over_shm(make_node, master, peers) -> None:  # noqa: ANN001
    text = "".join(chr(ord("A") + (i * 7) % 26) for i in range(256)) * (6220800 // 256)
    talker = make_node("big_talker")
    pub = talker.publisher("big", String, latch=True)
    pub.publish(String(text))
    ours: list[String] = []
    make_node("our_listener").subscriber("big", String, ours.append)
    child = _start(peers, roscpp(master.uri, "biglistener"))
    assert wait_until(lambda: ours, timeout=10) and ours[0].data == text
    assert child.wait_for(lambda line: line.startswith(f"big {len(text)} "), timeout=20), child.describe()
    assert _transports(talker, "/big") == ["SHMROS", "TCPROS"]


def test_a_loaned_image_reaches_rospy_over_tcpros_identical_to_ours_over_shm(
    make_node, master, peers
) -> None:  # noqa: ANN001
    camera = make_node("camera")
    pub = camera.publisher("image", Image, queue_size=None)
    ours: list[Image] = []
    make_node("viewer").subscriber("image", Image, ours.append)
    child = _start(peers, rospy(ROSPY_IMAGE_SUB, master.uri))
    assert wait_until(lambda: pub.get_num_connections() == 2, timeout=20)
    assert _transports(camera, "/image") == ["SHMROS", "TCPROS"]
    frame = bytes((k + 7) % 256 for k in range(256)) * (1920 * 1080 * 3 // 256)
    with pub.loan(len(frame), height=1080, width=1920, encoding="rgb8", step=5760) as msg:
        assert pub.loan(10).shared is False  # (a small loan never takes a slot)
        msg.data[:] = memoryview(frame)
        pub.publish(msg)
    expected = f"image 1920x1080 rgb8 {len(frame)} {hashlib.md5(frame).hexdigest()}"
    assert child.wait_for(lambda line: line == expected, timeout=20), child.describe()
    assert wait_until(lambda: ours, timeout=10)
    assert ours[0].data == frame and type(ours[0].data.obj).__name__ == "Lease"
