"""Course-style OpenCV code, unchanged: a package of our own whose node subscribes camera/image_raw,
converts with cv_bridge, runs cv2.cvtColor + cv2.inRange and publishes the mask. Run with ``rosrun``
on ninjemys and with Debian's rospy/cv_bridge/python3-opencv side by side: the same mask."""

from __future__ import annotations

import os
import queue
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from ninjemys.cv_bridge import CvBridge
from ninjemys.idl.loader import get_message_class
from ninjemys.node.node import Node
from ninjemys.testing import have_ros1, kill_tree, ninjemys_bin, ros1_env, run_master

Image = get_message_class("sensor_msgs/Image")

NODE = '''#!/usr/bin/env python3
"""Red-object mask, as the course texts write it."""
import cv2
import numpy as np
import rospy
from cv_bridge import CvBridge
from sensor_msgs.msg import Image


class ColorFilter:
    def __init__(self):
        self.bridge = CvBridge()
        self.pub = rospy.Publisher("mask", Image, queue_size=1)
        rospy.Subscriber("camera/image_raw", Image, self.callback, queue_size=1)

    def callback(self, msg):
        frame = self.bridge.imgmsg_to_cv2(msg, desired_encoding="bgr8")
        hsv = cv2.cvtColor(frame, cv2.COLOR_BGR2HSV)
        mask = cv2.inRange(hsv, np.array([0, 120, 70]), np.array([10, 255, 255]))
        mask = cv2.morphologyEx(mask, cv2.MORPH_OPEN, np.ones((3, 3), np.uint8))
        out = self.bridge.cv2_to_imgmsg(mask, encoding="mono8")
        out.header = msg.header
        self.pub.publish(out)


if __name__ == "__main__":
    rospy.init_node("color_filter")
    ColorFilter()
    rospy.spin()
'''

PACKAGE_XML = """<?xml version="1.0"?>
<package format="2">
  <name>color_filter</name>
  <version>0.1.0</version>
  <description>red mask with cv2</description>
  <maintainer email="me@example.org">me</maintainer>
  <license>BSD</license>
  <buildtool_depend>catkin</buildtool_depend>
  <depend>rospy</depend>
  <depend>cv_bridge</depend>
  <depend>sensor_msgs</depend>
</package>
"""


def _package(root: Path) -> Path:
    pkg = root / "src" / "color_filter"
    (pkg / "scripts").mkdir(parents=True)
    (pkg / "package.xml").write_text(PACKAGE_XML)
    script = pkg / "scripts" / "color_filter.py"
    script.write_text(NODE)
    script.chmod(0o755)
    return script


def _scene() -> np.ndarray:
    """A gray 60x80 rgb8 frame with a red square and a blue one (only the red one is masked)."""
    y, x = np.mgrid[0:60, 0:80]
    arr = np.dstack([x + 60, y + 60, x + y]).astype(np.uint8) // 2
    arr[10:30, 10:30] = (220, 30, 20)
    arr[35:55, 45:70] = (20, 30, 220)
    return arr


@pytest.mark.ros1
def test_cv2_color_filter_node_same_mask_as_ros1(tmp_path: Path) -> None:
    script = _package(tmp_path)
    bridge = CvBridge()
    with run_master() as uri:
        env = dict(
            os.environ, ROS_MASTER_URI=uri, ROS_HOSTNAME="localhost", ROS_PACKAGE_PATH=str(tmp_path / "src")
        )
        env["PATH"] = f"{Path(sys.executable).parent}:{env['PATH']}"  # what `source .venv/bin/activate` does
        procs = [
            subprocess.Popen(
                [
                    ninjemys_bin("rosrun"),
                    "color_filter",
                    "color_filter.py",
                    "mask:=/ours/mask",
                    "__name:=ours",
                ],
                env=env,
                stderr=subprocess.PIPE,
                start_new_session=True,
            )
        ]
        if have_ros1():
            procs.append(
                subprocess.Popen(
                    ["/usr/bin/python3", str(script), "mask:=/ros1/mask", "__name:=ros1"],
                    env=ros1_env(uri),
                    stderr=subprocess.PIPE,
                    start_new_session=True,
                )
            )
        node = Node("camera", master_uri=uri, rosout=False, logger_services=False)
        try:
            got: dict[str, queue.Queue[Any]] = {}
            for who in ("ours", "ros1")[: len(procs)]:
                got[who] = queue.Queue()
                node.subscriber(f"/{who}/mask", Image, got[who].put)
            pub = node.publisher("/camera/image_raw", Image, queue_size=1)
            frame = bridge.cv2_to_imgmsg(_scene(), "rgb8")
            frame.header.frame_id = "camera"
            masks: dict[str, Any] = {}
            deadline = time.monotonic() + 60
            while len(masks) < len(got) and time.monotonic() < deadline:
                for p in procs:
                    assert p.poll() is None, p.stderr.read().decode() if p.stderr else ""
                pub.publish(frame)
                for who, q in got.items():
                    try:
                        masks[who] = q.get(timeout=0.2)
                    except queue.Empty:
                        pass
            assert set(masks) == set(got), f"masks from {sorted(masks)} only"
        finally:
            for p in procs:
                kill_tree(p)
            node.shutdown("test over")
    ours = bridge.imgmsg_to_cv2(masks["ours"])
    assert masks["ours"].encoding == "mono8" and masks["ours"].header.frame_id == "camera"
    assert ours[10:30, 10:30].min() == 255 and ours[35:55, 45:70].max() == 0
    assert int(ours.astype(bool).sum()) == 400  # the red square only
    if "ros1" in masks:
        assert bytes(masks["ros1"].data) == bytes(masks["ours"].data)
        assert masks["ros1"].step == masks["ours"].step == 80
