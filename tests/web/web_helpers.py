"""Helpers shared by the web tests (a uniquely named module: every test directory has a conftest)."""

from __future__ import annotations

import contextlib
from collections.abc import Iterator
from pathlib import Path
from typing import Any

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


@contextlib.contextmanager
def graph_app(master_uri: str, update_period: float = 0.2) -> Iterator[Any]:
    """The web tools as rqt_graph runs them: a WebApp with a gateway (own node, counted as debug)."""
    from ninjemys.bridge.server import Gateway, GatewayOptions
    from ninjemys.node import Node
    from ninjemys.web.app import WebApp

    node = Node("test_rqt_graph", anonymous=True, master_uri=master_uri)
    gateway = Gateway(
        GatewayOptions(node_name=node.name, hide_own_node=True, update_period=update_period), node=node
    )
    gateway.start()
    app = WebApp(master_uri, caller_id=node.name)
    app.add_gateway(gateway)
    app.start()
    try:
        yield app
    finally:
        app.stop()
        gateway.shutdown()
        node.shutdown("test over")
