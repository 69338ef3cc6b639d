"""Debian's real ``rosnode info /turtlesim`` against our turtlesim_node lists the seed's interface."""

from __future__ import annotations

import subprocess

import pytest

from ninjemys.testing import ROS1_PYTHON, ros1_env, wait_until

pytestmark = pytest.mark.ros1

# the seed's printout (000_*.txt), minus the connection details that depend on the machine
SEED_PUBLICATIONS = [
    "/rosout [rosgraph_msgs/Log]",
    "/turtle1/color_sensor [turtlesim/Color]",
    "/turtle1/pose [turtlesim/Pose]",
]
SEED_SERVICES = [
    "/clear",
    "/kill",
    "/reset",
    "/spawn",
    "/turtle1/set_pen",
    "/turtle1/teleport_absolute",
    "/turtle1/teleport_relative",
    "/turtlesim/get_loggers",
    "/turtlesim/set_logger_level",
]


def _section(text: str, title: str) -> list[str]:
    lines = text.split(title, 1)[1].splitlines()[1:]
    items = []
    for line in lines:
        if not line.startswith(" * "):
            break
        items.append(line[3:].strip())
    return items


def test_rosnode_info_matches_seed(turtlesim, master, client) -> None:  # type: ignore[no-untyped-def]
    from geometry_msgs.msg import Twist

    turtlesim()
    # the seed ran teleop alongside: a publisher on cmd_vel is what makes rosnode show its type
    client.publisher("/turtle1/cmd_vel", Twist, queue_size=1)
    client.wait_for_service("/turtle1/teleport_relative", timeout=10)

    def info() -> str:
        done = subprocess.run(
            [ROS1_PYTHON, "/usr/bin/rosnode", "info", "/turtlesim"],
            env=ros1_env(master),
            capture_output=True,
            text=True,
            timeout=30,
        )
        return done.stdout if "Services:" in done.stdout and "cmd_vel [geometry" in done.stdout else ""

    out = wait_until(info, timeout=20, what="rosnode info")
    assert "Node [/turtlesim]" in out
    assert _section(out, "Publications:") == SEED_PUBLICATIONS
    assert _section(out, "Subscriptions:") == ["/turtle1/cmd_vel [geometry_msgs/Twist]"]
    assert _section(out, "Services:") == SEED_SERVICES
    assert "Pid:" in out


def test_seed_rostopic_pub_moves_the_turtle(turtlesim, master, client) -> None:  # type: ignore[no-untyped-def]
    """The seed's command, run by Debian's real rostopic, drives our turtle (0.2 units in the 1 s hold)."""
    from turtlesim.msg import Pose

    turtlesim()
    poses: list[Pose] = []
    client.subscriber("/turtle1/pose", Pose, poses.append)
    wait_until(lambda: poses, what="poses")
    subprocess.run(
        [
            ROS1_PYTHON,
            "/usr/bin/rostopic",
            "pub",
            "-1",
            "/turtle1/cmd_vel",
            "geometry_msgs/Twist",
            "{linear: {x: 0.2, y: 0, z: 0}, angular: {x: 0, y: 0, z: 0}}",
        ],
        env=ros1_env(master),
        capture_output=True,
        timeout=30,
        check=True,
    )
    wait_until(lambda: poses[-1].linear_velocity == 0.0 and poses[-1].x > 5.6, what="the move to end")
    assert poses[-1].x - 5.544445 == pytest.approx(0.2, rel=0.02)
