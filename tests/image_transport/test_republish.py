"""``rosrun image_transport republish`` in ROS 1's argument forms: raw -> compressed -> raw through two
republishers (PNG set by parameter, so the pixels come back exact), and nothing encoded unsubscribed."""

from __future__ import annotations

import os
import queue
import subprocess
import time
from typing import Any

import numpy as np
import pytest

from ninjemys.cv_bridge import CvBridge
from ninjemys.idl.loader import get_message_class
from ninjemys.node.node import Node
from ninjemys.testing import kill_tree, ninjemys_bin, run_master

Image = get_message_class("sensor_msgs/Image")
CompressedImage = get_message_class("sensor_msgs/CompressedImage")


def _start(uri: str, *args: str) -> subprocess.Popen[bytes]:
    env = dict(os.environ, ROS_MASTER_URI=uri, ROS_HOSTNAME="localhost")
    return subprocess.Popen(
        [ninjemys_bin("rosrun"), "image_transport", "republish", *args],
        env=env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        start_new_session=True,
    )


def _wait(q: queue.Queue[Any], pub: Any, msg: Any, timeout: float = 30.0) -> Any:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        pub.publish(msg)
        try:
            return q.get(timeout=0.2)
        except queue.Empty:
            pass
    raise AssertionError("no message came through the republishers")


def test_raw_to_compressed_to_raw() -> None:
    y, x = np.mgrid[0:30, 0:40]
    arr = np.dstack([x * 6, y * 8, x + y]).astype(np.uint8)
    bridge = CvBridge()
    with run_master() as uri:
        node = Node("republish_test", master_uri=uri, rosout=False, logger_services=False)
        procs = []
        try:
            node.set_param("/cam/out/compressed/format", "png")
            procs.append(_start(uri, "raw", "in:=/cam/image_raw", "compressed", "out:=/cam/out"))
            procs.append(_start(uri, "compressed", "in:=/cam/out", "raw", "out:=/cam/decompressed"))
            comp: queue.Queue[Any] = queue.Queue()
            raw: queue.Queue[Any] = queue.Queue()
            pub = node.publisher("/cam/image_raw", Image, queue_size=2)
            node.subscriber("/cam/out/compressed", CompressedImage, comp.put)
            node.subscriber("/cam/decompressed", Image, raw.put)
            img = bridge.cv2_to_imgmsg(arr, "rgb8")
            img.header.frame_id = "camera"
            back = _wait(raw, pub, img)
            assert back.encoding == "rgb8" and back.header.frame_id == "camera"
            assert np.array_equal(bridge.imgmsg_to_cv2(back), arr)
            c = comp.get(timeout=10)
            assert c.format == "rgb8; png compressed bgr8"
            assert np.array_equal(bridge.compressed_imgmsg_to_cv2(c, "rgb8"), arr)
        finally:
            for p in procs:
                kill_tree(p)
            node.shutdown("test over")
        for p in procs:
            assert b"Traceback" not in (p.stderr.read() if p.stderr else b"")


@pytest.mark.parametrize("args", [[], ["bogus", "in:=/a", "out:=/b"], ["raw", "raw", "raw"]])
def test_bad_arguments_give_usage(args: list[str]) -> None:
    res = subprocess.run(
        [ninjemys_bin("rosrun"), "image_transport", "republish", *args],
        capture_output=True,
        text=True,
        timeout=30,
    )
    assert res.returncode != 0
    assert "republish" in res.stderr and "Traceback" not in res.stderr


DEBIAN_REPUBLISH = "/usr/lib/image_transport/republish"


@pytest.mark.ros1
@pytest.mark.skipif(not os.path.exists(DEBIAN_REPUBLISH), reason="needs Debian's image-transport-tools")
def test_raw_republish_side_by_side_with_debian() -> None:
    """Debian's C++ republish (its only plugin is raw) and ours, same arguments: the same Image out.
    Debian's lists no compressed transport (no compressed_image_transport package in Debian)."""
    from ninjemys.testing import ros1_env

    arr = np.arange(20 * 10 * 3, dtype=np.uint8).reshape(10, 20, 3)
    bridge = CvBridge()
    with run_master() as uri:
        node = Node("republish_pair", master_uri=uri, rosout=False, logger_services=False)
        procs = [_start(uri, "raw", "in:=/cam/image_raw", "raw", "out:=/ours/out")]
        procs.append(
            subprocess.Popen(
                [DEBIAN_REPUBLISH, "raw", "in:=/cam/image_raw", "raw", "out:=/deb/out"],
                env=ros1_env(uri),
                stdout=subprocess.DEVNULL,
                stderr=subprocess.PIPE,
                start_new_session=True,
            )
        )
        try:
            ours: queue.Queue[Any] = queue.Queue()
            theirs: queue.Queue[Any] = queue.Queue()
            node.subscriber("/ours/out", Image, ours.put)
            node.subscriber("/deb/out", Image, theirs.put)
            pub = node.publisher("/cam/image_raw", Image, queue_size=2)
            img = bridge.cv2_to_imgmsg(arr, "bgr8")
            img.header.frame_id = "cam"
            a = _wait(ours, pub, img)
            b = _wait(theirs, pub, img)
        finally:
            for p in procs:
                kill_tree(p)
            node.shutdown("test over")
    for m in (a, b):
        assert (m.encoding, m.height, m.width, m.step, m.header.frame_id) == ("bgr8", 10, 20, 60, "cam")
        assert bytes(m.data) == arr.tobytes()
