"""Topic and frame names of robots whose description names them (issue 23 leftovers): a robot put
under its own name in a multi-robot world (``SimNode.add_robot(namespaced=True)``) or under a spawn's
robot_namespace gets ``/<name>/odom``, never ``heavy//odom``."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from ninjemys.node import Node
from ninjemys.node.log import NodeLog
from ninjemys.sim.puzzlebot_node import SimNode, scoped
from ninjemys.sim.robot_model import load_robot_model
from ninjemys.sim.simcore import Simulation
from ninjemys.sim.world2d import World
from ninjemys.testing import run_master

DIFF_DRIVE_URDF = """<robot name="wheelie">
  <link name="base_link"><collision><geometry><cylinder radius="0.1" length="0.1"/></geometry></collision></link>
  <link name="left_wheel"><collision><geometry><cylinder radius="0.05" length="0.02"/></geometry></collision></link>
  <link name="right_wheel"><collision><geometry><cylinder radius="0.05" length="0.02"/></geometry></collision></link>
  <link name="laser"/>
  <joint name="left_joint" type="continuous"><parent link="base_link"/><child link="left_wheel"/>
    <origin xyz="0 0.09 0.05" rpy="-1.5707963267948966 0 0"/><axis xyz="0 0 1"/></joint>
  <joint name="right_joint" type="continuous"><parent link="base_link"/><child link="right_wheel"/>
    <origin xyz="0 -0.09 0.05" rpy="-1.5707963267948966 0 0"/><axis xyz="0 0 1"/></joint>
  <joint name="laser_joint" type="fixed"><parent link="base_link"/><child link="laser"/>
    <origin xyz="0 0 0.2"/></joint>
  <gazebo><plugin name="drive" filename="libgazebo_ros_diff_drive.so">
    <leftJoint>left_joint</leftJoint><rightJoint>right_joint</rightJoint>
    <wheelSeparation>0.18</wheelSeparation><wheelDiameter>0.1</wheelDiameter>
    <robotBaseFrame>base_link</robotBaseFrame>
  </plugin></gazebo>
  <gazebo reference="laser"><sensor type="ray" name="lidar"><update_rate>10</update_rate>
    <ray><scan><horizontal><samples>90</samples><min_angle>-3.14159</min_angle><max_angle>3.14159</max_angle>
    </horizontal></scan><range><min>0.1</min><max>8</max></range></ray>
    <plugin name="laser" filename="libgazebo_ros_laser.so"><topicName>scan</topicName><frameName>laser</frameName></plugin>
  </sensor></gazebo>
</robot>"""


@pytest.fixture
def master() -> Iterator[str]:
    with run_master() as uri:
        yield uri


def test_scoped_joins_a_prefix_and_a_description_name_with_one_slash() -> None:
    assert scoped("", "/odom") == "/odom"
    assert scoped("", "odom") == "odom"
    assert scoped("heavy/", "/odom") == "heavy/odom"
    assert scoped("heavy/", "odom") == "heavy/odom"
    assert scoped("heavy/", "/heavy/odom") == "/heavy/odom"  # already in the robot's namespace
    assert scoped("heavy/", "heavy/odom") == "heavy/odom"  # a frame tf-prefixed by its plugin


def topics_of(node: Node) -> set[str]:
    return {t for t, _ in node.get_publications()} | {t for t, _ in node.get_subscriptions()}


def test_namespaced_robots_from_descriptions_get_single_slash_names(master: str) -> None:
    node = Node("names_sim", master_uri=master)
    try:
        sim = SimNode(node, NodeLog(node.name), Simulation(World("empty")), 0.0, None)
        heavy = sim.add_robot("heavy", load_robot_model(DIFF_DRIVE_URDF), 0.0, 0.0, 0.0, True)
        light = sim.add_robot("light", load_robot_model(DIFF_DRIVE_URDF), 0.0, 3.0, 0.0, True)
        names = topics_of(node)
        assert not [t for t in names if "//" in t]
        for robot in ("heavy", "light"):
            for topic in ("odom", "scan", "cmd_vel"):
                assert f"/{robot}/{topic}" in names
        assert "/odom" not in names and "/scan" not in names
        assert "/heavy/contact" not in names  # a Gazebo description without a bumper has no contact topic
        # frames: tf_prefix style, one slash
        assert heavy.frame("odom") == "heavy/odom" and light.frame("base_link") == "light/base_link"
        assert heavy.frame("heavy/odom") == "heavy/odom"
    finally:
        node.shutdown("test over")


def test_a_spawn_namespace_puts_description_topics_under_it_once(master: str) -> None:
    """spawn_model -robot_namespace pb2 with a description whose plugins name ``/odom`` (no
    robotNamespace of its own), and one loaded with the namespace (``/pb3/odom``): each once."""
    node = Node("names_spawn_sim", master_uri=master)
    try:
        sim = SimNode(node, NodeLog(node.name), Simulation(World("empty")), 0.0, None)
        sim.add_robot("first", load_robot_model(DIFF_DRIVE_URDF), 0.0, 0.0, 0.0, False)
        sim.add_robot("pb2", load_robot_model(DIFF_DRIVE_URDF), 0.0, 3.0, 0.0, False, "pb2")
        model = load_robot_model(DIFF_DRIVE_URDF, robot_namespace="/pb3")
        assert model.drive.odom_topic == "/pb3/odom"
        sim.add_robot("pb3", model, 3.0, 0.0, 0.0, False, "/pb3")
        names = topics_of(node)
        assert not [t for t in names if "//" in t]
        assert {"/odom", "/pb2/odom", "/pb3/odom", "/pb2/scan", "/pb3/scan", "/pb2/cmd_vel"} <= names
    finally:
        node.shutdown("test over")
