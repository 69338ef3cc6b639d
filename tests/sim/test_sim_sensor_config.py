"""Item 5 of the Gazebo issue: the sensors, topics and frames are configurable, as node parameters
and from the RobotModel a description gives (odometry and its TF off, the lidar's beams and angle
range, the camera's topic, a passive robot without a drive)."""

from __future__ import annotations

import math
import os
import threading
from collections.abc import Iterator
from pathlib import Path

import pytest
from gazebo_helpers import Launched

from ninjemys.idl.loader import get_message_class, get_service_class
from ninjemys.node import Node
from ninjemys.node.log import NodeLog
from ninjemys.packages.shipped import shipped_executable
from ninjemys.sim.puzzlebot_node import SimNode
from ninjemys.sim.robot_model import DriveSpec, load_robot_model
from ninjemys.sim.simcore import Simulation
from ninjemys.sim.world2d import World
from ninjemys.testing import run_master, wait_until

LaserScan = get_message_class("sensor_msgs/LaserScan")
Image = get_message_class("sensor_msgs/Image")
TFMessage = get_message_class("tf2_msgs/TFMessage")
Odometry = get_message_class("nav_msgs/Odometry")


@pytest.fixture
def master() -> Iterator[str]:
    with run_master() as uri:
        yield uri


@pytest.fixture
def client(master: str) -> Iterator[Node]:
    node = Node("sensor_config_client", anonymous=True, master_uri=master)
    try:
        yield node
    finally:
        node.shutdown("test over")


def collect(node: Node, topic: str, cls, seconds: float) -> list:  # type: ignore[no-untyped-def]
    got: list = []
    sub = node.subscriber(topic, cls, got.append, queue_size=100)
    try:
        threading.Event().wait(seconds)
    finally:
        sub.unregister()
    return got


def test_node_parameters_set_beams_angles_topics_and_turn_the_odom_tf_off(
    master: str, client: Node, tmp_path: Path
) -> None:
    cmd = shipped_executable("puzzlebot_sim", "sim_node").command(
        [
            "_world:=square", "_rate:=2.0", "_gui:=false", "_publish_odom_tf:=false",
            "_scan_beams:=720", f"_scan_angle_min:={-math.pi / 2}", f"_scan_angle_max:={math.pi / 2}",
            "_image_topic:=camera/image_raw", "_camera_info_topic:=camera/camera_info", "_odom_topic:=wheel_odom",
        ]
    )  # fmt: skip
    sim = Launched(cmd, dict(os.environ, ROS_MASTER_URI=master, PYTHONUNBUFFERED="1"), tmp_path / "sim.log")
    try:
        sim.wait_for("PuzzleBot simulator:")
        got: list = []
        sub = client.subscriber("/scan", LaserScan, got.append, queue_size=1)
        wait_until(lambda: got, 15, "a scan")
        sub.unregister()
        scan = got[0]
        assert len(scan.ranges) == 720
        assert (scan.angle_min, scan.angle_max) == pytest.approx((-math.pi / 2, math.pi / 2))
        assert scan.angle_increment == pytest.approx(math.pi / 719)
        topics = {t for t, _ in client.master.get_published_topics("/")}
        assert {"/camera/image_raw", "/camera/camera_info", "/wheel_odom"} <= topics
        assert "/camera/color/image_raw" not in topics and "/odom" not in topics
        images: list = []
        sub = client.subscriber("/camera/image_raw", Image, images.append, queue_size=1)
        wait_until(lambda: images, 15, "an image on camera/image_raw")
        sub.unregister()
        assert (images[0].width, images[0].height) == (320, 240)
        odom = collect(client, "/wheel_odom", Odometry, 1.0)
        assert odom, "odometry still published on its new topic"
        tfs = collect(client, "/tf", TFMessage, 1.0)
        pairs = {(t.header.frame_id, t.child_frame_id) for m in tfs for t in m.transforms}
        assert ("odom", "base_link") not in pairs  # publishOdomTF false: the students' own node publishes it
    finally:
        sim.stop()


def test_a_model_without_a_drive_is_passive_and_says_so(master: str, client: Node) -> None:
    """A RobotModel as a description without a drive plugin gives it (GZDESC fills it from URDFs)."""
    node = Node("passive_sim", master_uri=master)
    lines: list[str] = []
    log = NodeLog(node.name)
    log.warn = lambda msg, *args: lines.append(msg % args)  # type: ignore[method-assign]
    log.info = lambda msg, *args: None  # type: ignore[method-assign]
    try:
        sim = SimNode(node, log, Simulation(World("empty")), 0.0, None)
        model = load_robot_model("puzzlebot")
        model.drive = DriveSpec(kind="none")
        model.ignored_plugins = ["libgazebo_ros_p3d.so"]
        model.laser.topic = "base_scan"
        sim.add_robot("statue", model, 0.0, 0.0, 0.0, False)
        topics = {t for t, _ in client.master.get_published_topics("/")}
        assert "/base_scan" in topics and "/odom" not in topics and "/wl" not in topics
        subscribed = {t for t, _ in client.master.get_system_state()[1] if t == "/cmd_vel"}
        assert not subscribed
        assert any("no drive plugin" in line and "passive" in line for line in lines), lines
        assert any("libgazebo_ros_p3d.so" in line for line in lines), lines
        sim.start()
        got: list = []
        sub = client.subscriber("/base_scan", LaserScan, got.append, queue_size=1)
        wait_until(lambda: got, 15, "a scan from the passive robot")
        sub.unregister()
        sim.stop()
    finally:
        node.shutdown("test over")


WHEEL_TF_URDF = """<robot name="wheelie">
  <link name="base_link"><collision><geometry><cylinder radius="0.1" length="0.1"/></geometry></collision></link>
  <link name="left_wheel"><collision><geometry><cylinder radius="0.05" length="0.02"/></geometry></collision></link>
  <link name="right_wheel"><collision><geometry><cylinder radius="0.05" length="0.02"/></geometry></collision></link>
  <joint name="left_joint" type="continuous"><parent link="base_link"/><child link="left_wheel"/>
    <origin xyz="0 0.09 0.05" rpy="-1.5707963267948966 0 0"/><axis xyz="0 0 1"/></joint>
  <joint name="right_joint" type="continuous"><parent link="base_link"/><child link="right_wheel"/>
    <origin xyz="0 -0.09 0.05" rpy="-1.5707963267948966 0 0"/><axis xyz="0 0 1"/></joint>
  <gazebo><plugin name="drive" filename="libgazebo_ros_diff_drive.so">
    <leftJoint>left_joint</leftJoint><rightJoint>right_joint</rightJoint>
    <wheelSeparation>0.18</wheelSeparation><wheelDiameter>0.1</wheelDiameter>
    <robotBaseFrame>base_link</robotBaseFrame><publishWheelTF>{wheel_tf}</publishWheelTF>
    <updateRate>50</updateRate>
  </plugin></gazebo>
</robot>"""


@pytest.mark.parametrize("wheel_tf", [True, False])
def test_publish_wheel_tf_puts_the_turning_wheels_on_tf(master: str, client: Node, wheel_tf: bool) -> None:
    """gazebo_ros_diff_drive's publishWheelTF: base_link -> each wheel link on /tf, at the joint's
    origin and turned about its axis by the wheel's angle (the angle joint_states reports)."""
    node = Node("wheel_tf_sim", master_uri=master)
    log = NodeLog(node.name)
    try:
        sim = SimNode(node, log, Simulation(World("empty")), 2.0, None)
        model = load_robot_model(WHEEL_TF_URDF.format(wheel_tf=str(wheel_tf).lower()))
        assert [j.name for j in model.wheel_tf_joints] == (["left_joint", "right_joint"] if wheel_tf else [])
        io = sim.add_robot("wheelie", model, 0.0, 0.0, 0.0, False)
        io.robot.command(0.2, 0.0)
        sim.start()
        msgs = collect(client, "/tf", TFMessage, 1.5)
        sim.stop()
        wheels = [t for m in msgs for t in m.transforms if t.child_frame_id in ("left_wheel", "right_wheel")]
        assert any(t.child_frame_id == "base_link" for m in msgs for t in m.transforms)  # odom -> base
        if not wheel_tf:
            assert not wheels
            return
        assert {t.child_frame_id for t in wheels} == {"left_wheel", "right_wheel"}
        assert {t.header.frame_id for t in wheels} == {"base_link"}
        last = [t for t in wheels if t.child_frame_id == "left_wheel"][-1]
        tr, q = last.transform.translation, last.transform.rotation
        assert (tr.x, tr.y, tr.z) == pytest.approx((0.0, 0.09, 0.05))
        # roll(-pi/2) then the joint angle about the joint's z: qz / qw gives the angle back
        angle = 2.0 * math.atan2(q.z, q.w)  # (modulo a turn)
        assert abs(angle) > 0.01  # the wheel turned
        expected = model.wheel_tf_joints[0].transform(angle)
        assert (q.x, q.y, q.z, q.w) == pytest.approx(expected[3:], abs=1e-9)
    finally:
        node.shutdown("test over")


def test_a_push_moves_a_heavier_urdf_body_less(master: str) -> None:
    """apply_body_wrench pushes with the body's mass from the URDF's <inertial>s (the links fixed
    to the base: 2 kg + 2 kg here), where a description without any counts as 1 kg."""
    heavy = (
        WHEEL_TF_URDF.format(wheel_tf="false")
        .replace(
            '<link name="base_link">',
            '<link name="base_link"><inertial><mass value="2.0"/><inertia ixx="0.01" iyy="0.01" izz="0.02"'
            ' ixy="0" ixz="0" iyz="0"/></inertial>',
        )
        .replace(
            "</robot>",
            '<link name="deck"><inertial><origin xyz="0.1 0 0"/><mass value="2.0"/></inertial></link>'
            '<joint name="deck_joint" type="fixed"><parent link="base_link"/><child link="deck"/></joint></robot>',
        )
    )
    model = load_robot_model(heavy, robot_namespace="heavy")
    assert model.mass == pytest.approx(4.0)
    assert model.inertia_z == pytest.approx(0.02 + 2.0 * 0.1**2)
    light = load_robot_model(WHEEL_TF_URDF.format(wheel_tf="false"), robot_namespace="light")
    assert (light.mass, light.inertia_z) == (1.0, None)
    node = Node("push_sim", master_uri=master)
    try:
        sim = SimNode(node, NodeLog(node.name), Simulation(World("empty")), 0.0, None)
        sim.add_robot("heavy", model, 0.0, 0.0, 0.0, False)
        sim.add_robot("light", light, 0.0, 3.0, 0.0, False)
        ApplyBodyWrench = get_service_class("gazebo_msgs/ApplyBodyWrench")
        for name in ("heavy", "light"):
            req = ApplyBodyWrench._request_class()
            req.body_name, req.reference_frame = name, "world"
            req.wrench.force.x = 2.0
            req.duration.secs = 1
            assert sim.gazebo._apply_body_wrench(req).success
        for _ in range(150):
            sim._step_and_publish()
        moved = {n: sim.sim.robots[n].x for n in ("heavy", "light")}
        # 2 N for 1 s: a = F / m, x = a t^2 / 2 -> 0.25 m for 4 kg, 1 m for 1 kg
        assert moved["heavy"] == pytest.approx(0.25, abs=0.02)
        assert moved["light"] == pytest.approx(1.0, abs=0.05)
    finally:
        node.shutdown("test over")


@pytest.mark.parametrize(
    ("inertial", "reason"),
    [
        ('<mass value="heavy"/>', "<mass value> is not a number"),
        ('<mass value="-1"/>', "<mass value> must be a finite number >= 0"),
        ('<mass value="1"/><inertia izz="nan"/>', "<inertia izz> must be a finite number >= 0"),
    ],
)
def test_a_bad_inertial_names_the_link_and_the_reason(inertial: str, reason: str) -> None:
    from ninjemys.errors import NinjemysError

    urdf = WHEEL_TF_URDF.format(wheel_tf="false").replace(
        '<link name="base_link">', f'<link name="base_link"><inertial>{inertial}</inertial>'
    )
    with pytest.raises(NinjemysError, match="base_link") as err:
        load_robot_model(urdf)
    assert reason in str(err.value)
