"""Helpers shared by the web tests (a uniquely named module: every test directory has a conftest)."""

from __future__ import annotations

import time
import xmlrpc.client
from collections.abc import Callable
from pathlib import Path

CHROMIUM = Path("/usr/bin/chromium")
CHROMIUM_ARGS = [
    "--no-sandbox",
    "--disable-gpu",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--no-first-run",
]

TALKER = """
import rospy
from std_msgs.msg import String
rospy.init_node("talker")
pub = rospy.Publisher("chatter", String, queue_size=10)
rate = rospy.Rate(10)
while not rospy.is_shutdown():
    pub.publish("hello world")
    rate.sleep()
"""

#: a node in namespace /robot (its topic is /robot/odom), for namespace grouping
ROBOT_BASE = """
import os
os.environ["ROS_NAMESPACE"] = "/robot"  # rospy reads its namespace when it is imported
import rospy
from std_msgs.msg import String
rospy.init_node("base")
pub = rospy.Publisher("odom", String, queue_size=1)
rospy.Subscriber("/chatter", String, lambda msg: None)
rospy.spin()
"""

LISTENER = """
import rospy
from std_msgs.msg import String
rospy.init_node("listener")
rospy.Subscriber("chatter", String, lambda msg: None)
rospy.spin()
"""


def wait_for_master(uri: str, timeout: float = 20.0) -> None:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        try:
            xmlrpc.client.ServerProxy(uri).getPid("/test")
            return
        except OSError:
            time.sleep(0.1)
    raise RuntimeError(f"master at {uri} did not come up")


def wait_until(predicate: Callable[[], object], timeout: float = 20.0, what: str = "condition") -> object:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        value = predicate()
        if value:
            return value
        time.sleep(0.1)
    raise AssertionError(f"timed out waiting for {what}")
