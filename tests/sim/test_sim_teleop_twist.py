"""teleop_twist_keyboard through a pseudo-terminal: the ROS package's keys, text and parameters."""

from __future__ import annotations

import os
import threading

import pexpect

from geometry_msgs.msg import Twist
from ninjemys.packages.shipped import shipped_executable
from ninjemys.sim.teleop_twist_keyboard import TeleopState
from ninjemys.testing import wait_until


def test_key_logic_matches_the_ros_package() -> None:
    s = TeleopState(0.5, 1.0, 1000, 1000)
    s.key("i")
    assert s.twist() == (0.5, 0.0, 0.0, 0.0)
    s.key("u")
    assert s.twist() == (0.5, 0.0, 0.0, 1.0)
    s.key("J")  # holonomic: strafe left
    assert s.twist() == (0.0, 0.5, 0.0, 0.0)
    s.key("m")
    assert s.twist() == (-0.5, 0.0, 0.0, -1.0)
    assert s.key("q") == [f"currently:\tspeed {0.5 * 1.1}\tturn {1.0 * 1.1} "]
    s.key("k")  # anything else stops
    assert s.twist() == (0.0, 0.0, 0.0, 0.0)
    capped = TeleopState(0.5, 1.0, 0.52, 1000)
    assert capped.key("w")[0] == "Linear speed limit reached!" and capped.speed == 0.52


def test_keys_publish_on_cmd_vel(master: str, client) -> None:  # type: ignore[no-untyped-def]
    got: list[tuple[float, float]] = []
    lock = threading.Lock()

    def on_twist(msg: Twist) -> None:
        with lock:
            got.append((msg.linear.x, msg.angular.z))

    client.subscriber("/cmd_vel", Twist, on_twist)
    cmd = shipped_executable("teleop_twist_keyboard", "teleop_twist_keyboard.py").command([])
    child = pexpect.spawn(
        cmd[0], cmd[1:], env=dict(os.environ, ROS_MASTER_URI=master), encoding="utf-8", timeout=40
    )
    try:
        child.expect_exact("Reading from the keyboard  and Publishing to Twist!")
        child.expect_exact("CTRL-C to quit")
        child.expect_exact("currently:\tspeed 0.5\tturn 1.0 ")
        wait_until(lambda: child.send("i") and got, timeout=40, what="first Twist")
        child.send("j,k")  # typed ahead: one read gets all three keys, each still gets its Twist
        wait_until(
            lambda: got[-3:] == [(0.0, 1.0), (-0.5, 0.0), (0.0, 0.0)], timeout=40, what="the keys' Twists"
        )
        child.send("z")
        child.expect_exact("currently:\tspeed 0.45\tturn 0.9 ")
        child.send("\x03")
        child.expect(pexpect.EOF)
        child.close()
        assert child.exitstatus == 0
        wait_until(lambda: got[-1] == (0.0, 0.0), timeout=40, what="the stop on exit")
    finally:
        if child.isalive():
            child.terminate(force=True)
