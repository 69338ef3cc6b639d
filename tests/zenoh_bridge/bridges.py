"""Helpers for the zenoh-bridge-ros1 tests: bridges in child processes, real rospy programs."""

from __future__ import annotations

import textwrap

from ninjemys.master.client import MasterClient
from ninjemys.testing import ROS1_PYTHON, NodeProcess, ninjemys_bin, ros1_env, wait_until

BRIDGE_NODE = "/ros1_to_zenoh_bridge"

RUN_TIMEOUT = 30.0


def start_bridge(master_uri: str, *args: str) -> NodeProcess:
    """``zenoh-bridge-ros1`` on ``master_uri``, waited for until it runs (no multicast scouting)."""
    env = ros1_env(master_uri)
    env["PATH"] = ""  # nothing found by name: the command is run by its full path
    proc = NodeProcess(
        [ninjemys_bin("zenoh-bridge-ros1"), "--ros_master_uri", master_uri, "--no-multicast-scouting", *args],
        env=env,
    )
    try:
        proc.wait_for("running:", timeout=RUN_TIMEOUT)
    except BaseException:
        proc.stop()
        raise
    return proc


def rospy(master_uri: str, source: str, *argv: str) -> NodeProcess:
    """A real rospy program (Debian's /usr/bin/python3) running ``source``."""
    return NodeProcess([ROS1_PYTHON, "-c", textwrap.dedent(source), *argv], env=ros1_env(master_uri))


TALKER = """
    import sys, rospy
    from std_msgs.msg import String
    rospy.init_node("talker")
    pub = rospy.Publisher(sys.argv[1], String, queue_size=10)
    rate, i = rospy.Rate(20), 0
    while not rospy.is_shutdown():
        pub.publish(String("%s %d" % (sys.argv[2], i)))
        i += 1
        rate.sleep()
"""

SET_BOOL_SERVER = """
    import rospy
    from std_srvs.srv import SetBool, SetBoolResponse
    rospy.init_node("arm_server")
    def handle(req):
        return SetBoolResponse(success=req.data, message="armed" if req.data else "disarmed")
    rospy.Service("/arm", SetBool, handle)
    def jammed(req):
        raise rospy.ServiceException("arm jammed")
    rospy.Service("/brake", SetBool, jammed)
    print("ready", flush=True)
    rospy.spin()
"""


def bridged(master_uri: str, topic: str, kind: str = "pub", timeout: float = 30.0) -> None:
    """Wait until the bridge node publishes (``pub``), subscribes (``sub``) or serves (``srv``) ``name``."""
    index = {"pub": 0, "sub": 1, "srv": 2}[kind]

    def present() -> bool:
        with MasterClient(master_uri, "/test_probe") as m:
            entries = m.get_system_state()[index]
        return any(name == topic and BRIDGE_NODE in nodes for name, nodes in entries)

    wait_until(present, timeout=timeout, what=f"the bridge on {master_uri} to {kind} {topic}")
