"""joint_state_publisher: the same JointState as Debian's for one URDF and one set of parameters
(joint order, zeros, limits and safety limits, mimic chains, dependent_joints, source_list), and
the cycle logic on its own (delta sweep, velocities and efforts, a mimic loop refused)."""

from __future__ import annotations

import os
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from ninjemys import testing
from ninjemys.idl.loader import get_message_class
from ninjemys.node import Node
from ninjemys.robot.joint_state_publisher import JointStatePublisher
from ninjemys.robot.kinematics import URDFError

DEBIAN_JSP = Path("/usr/lib/joint_state_publisher/joint_state_publisher")

URDF = """<?xml version="1.0"?>
<robot name="gripper_arm">
  <link name="base"/><link name="a"/><link name="b"/><link name="c"/><link name="d"/><link name="e"/>
  <link name="f"/><link name="g"/>
  <joint name="spin" type="continuous"><parent link="base"/><child link="a"/><axis xyz="0 0 1"/></joint>
  <joint name="lift" type="prismatic"><parent link="a"/><child link="b"/>
    <limit lower="0.1" upper="0.5" effort="1" velocity="1"/></joint>
  <joint name="fixed_cam" type="fixed"><parent link="b"/><child link="c"/></joint>
  <joint name="elbow" type="revolute"><parent link="b"/><child link="d"/>
    <limit lower="-2" upper="2" effort="1" velocity="1"/>
    <safety_controller soft_lower_limit="-1" soft_upper_limit="1.5" k_position="1" k_velocity="1"/></joint>
  <joint name="finger" type="prismatic"><parent link="d"/><child link="e"/>
    <limit lower="0" upper="0.04" effort="1" velocity="1"/></joint>
  <joint name="finger_mimic" type="prismatic"><parent link="d"/><child link="f"/>
    <limit lower="-0.04" upper="0" effort="1" velocity="1"/><mimic joint="finger" multiplier="-1" offset="0.002"/></joint>
  <joint name="finger_mimic2" type="prismatic"><parent link="d"/><child link="g"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/><mimic joint="finger_mimic" multiplier="2"/></joint>
</robot>
"""


class _Last:
    def __init__(self) -> None:
        self.msg = None
        self.event = threading.Event()

    def __call__(self, msg) -> None:  # noqa: ANN001
        self.msg = msg
        self.event.set()


def _ours(*args: str) -> list[str]:
    return [
        sys.executable,
        "-m",
        "ninjemys.packages.run_shipped",
        "joint_state_publisher",
        "joint_state_publisher",
        *args,
    ]


def _first(node: Node, topic: str, after: float = 0.0):  # noqa: ANN202
    last = _Last()
    sub = node.subscriber(topic, get_message_class("sensor_msgs/JointState"), last, queue_size=1)
    try:
        assert last.event.wait(30), f"nothing on {topic}"
        time.sleep(after)
        return last.msg
    finally:
        sub.unregister()


@pytest.fixture
def master(tmp_path: Path):
    env = dict(os.environ, ROS_HOME=str(tmp_path), ROS_LOG_DIR=str(tmp_path / "log"))
    with testing.run_master(env=env) as uri:
        node = Node("jsp_check", master_uri=uri)
        try:
            yield node, dict(env, ROS_MASTER_URI=uri, ROS_HOSTNAME="localhost")
        finally:
            node.shutdown("test done")


def _run(argv: list[str], env: dict[str, str]) -> subprocess.Popen[bytes]:
    return subprocess.Popen(argv, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)


def _stop(*procs: subprocess.Popen[bytes]) -> None:
    for proc in procs:
        proc.terminate()
    for proc in procs:
        try:
            proc.wait(10)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()


def _setup(node: Node) -> None:
    for ns in ("/ours", "/debian"):
        node.set_param(f"{ns}/robot_description", URDF)
        node.set_param(f"{ns}/jsp/zeros", {"elbow": 0.7})
        node.set_param(f"{ns}/jsp/dependent_joints", {})
        node.set_param(f"{ns}/jsp/source_list", [f"{ns}/source"])
        node.set_param(f"{ns}/jsp/publish_default_velocities", True)


def test_ours_publishes_the_urdfs_joints_in_order(master) -> None:
    node, env = master
    _setup(node)
    proc = _run(_ours("__ns:=/ours", "__name:=jsp"), env)
    try:
        msg = _first(node, "/ours/joint_states")
    finally:
        _stop(proc)
    assert list(msg.name) == ["spin", "lift", "elbow", "finger", "finger_mimic", "finger_mimic2"]
    assert list(msg.position) == pytest.approx([0.0, 0.3, 0.7, 0.0, 0.002, 0.004])
    assert list(msg.velocity) == [0.0] * 6 and list(msg.effort) == []


@pytest.mark.ros1
@pytest.mark.skipif(not DEBIAN_JSP.exists(), reason="Debian's joint-state-publisher is not installed")
def test_same_joint_states_as_debians_with_a_source(master) -> None:
    node, env = master
    _setup(node)
    JointState = get_message_class("sensor_msgs/JointState")
    sources = {
        ns: node.publisher(f"{ns}/source", JointState, queue_size=10, latch=True)
        for ns in ("/ours", "/debian")
    }
    ros1 = testing.ros1_env(env["ROS_MASTER_URI"], ROS_HOME=env["ROS_HOME"], ROS_HOSTNAME="localhost")
    procs = [
        _run(_ours("__ns:=/ours", "__name:=jsp"), env),
        _run(["/usr/bin/python3", str(DEBIAN_JSP), "__ns:=/debian", "__name:=jsp"], ros1),
    ]
    try:
        for pub in sources.values():
            msg = JointState(
                name=["finger", "spin", "nope"], position=[0.03, 1.25, 5.0], velocity=[0.5, 0.1, 0.0]
            )
            pub.publish(msg)
        messages = {ns: _first(node, f"{ns}/joint_states", after=0.5) for ns in ("/ours", "/debian")}
        deadline = time.monotonic() + 20
        while (
            any(m.position[3] != pytest.approx(0.03) for m in messages.values())
            and time.monotonic() < deadline
        ):
            messages = {ns: _first(node, f"{ns}/joint_states") for ns in ("/ours", "/debian")}
    finally:
        _stop(*procs)
    ours, theirs = messages["/ours"], messages["/debian"]
    assert list(ours.name) == list(theirs.name)
    assert list(ours.position) == pytest.approx(list(theirs.position), abs=1e-12)
    assert list(ours.velocity) == pytest.approx(list(theirs.velocity), abs=1e-12)
    assert list(ours.effort) == list(theirs.effort)
    assert ours.position[3] == pytest.approx(0.03)


def _params(values: dict) -> object:
    return lambda name, default=None: values.get(name, default)


def test_cycle_logic_delta_efforts_and_loops() -> None:
    warnings: list[str] = []
    jsp = JointStatePublisher(URDF, _params({"publish_default_efforts": True}), warnings.append)
    msg = get_message_class("sensor_msgs/JointState")()
    assert jsp.fill(msg) and list(msg.effort) == [0.0] * 6
    for _ in range(7):  # 0.3 + 7 * 0.03 passes the upper limit 0.5 on the 7th step
        jsp.sweep(0.03)
    lift = jsp.free["lift"]
    assert lift.values["position"] == pytest.approx(0.5) and not lift.forward  # held at the limit, turning
    assert jsp.free["elbow"].values["position"] == pytest.approx(0.21)
    jsp.sweep(0.03)
    assert lift.values["position"] == pytest.approx(0.47)
    looped = URDF.replace(
        '<limit lower="0" upper="0.04" effort="1" velocity="1"/></joint>',
        '<limit lower="0" upper="0.04" effort="1" velocity="1"/><mimic joint="finger_mimic2"/></joint>',
    )
    with pytest.raises(URDFError, match="infinite recursive mimic chain"):
        JointStatePublisher(looped, _params({}), warnings.append)
    no_limit = URDF.replace('<limit lower="0.1" upper="0.5" effort="1" velocity="1"/>', "")
    jsp = JointStatePublisher(no_limit, _params({}), warnings.append)
    assert "lift" not in jsp.order and any("limits are not specified" in w for w in warnings)
