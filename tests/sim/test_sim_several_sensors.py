"""Several lidars and cameras on one robot (issue 23 leftovers): each ``<sensor>`` with its gazebo_ros
plugin publishes on its own topic, in its own frame, at its own pose and size, as Gazebo does (the
first lidar and camera used to be the only ones)."""

from __future__ import annotations

import math
import threading
from collections.abc import Iterator
from typing import Any

import numpy as np
import pytest

from ninjemys.idl.loader import get_message_class
from ninjemys.node import Node
from ninjemys.node.log import NodeLog
from ninjemys.sim.puzzlebot_node import SimNode
from ninjemys.sim.robot_model import load_robot_model
from ninjemys.sim.simcore import Simulation
from ninjemys.sim.world2d import World
from ninjemys.testing import run_master, wait_until

LaserScan = get_message_class("sensor_msgs/LaserScan")
Image = get_message_class("sensor_msgs/Image")
CameraInfo = get_message_class("sensor_msgs/CameraInfo")


def lidar(name: str, topic: str, frame: str, samples: int) -> str:
    return f"""<gazebo reference="{frame}"><sensor type="ray" name="{name}"><update_rate>20</update_rate>
    <ray><scan><horizontal><samples>{samples}</samples><min_angle>-0.5</min_angle><max_angle>0.5</max_angle>
    </horizontal></scan><range><min>0.05</min><max>6</max></range></ray>
    <plugin name="{name}_plugin" filename="libgazebo_ros_laser.so"><topicName>{topic}</topicName>
    <frameName>{frame}</frameName></plugin></sensor></gazebo>"""


def camera(name: str, ns: str, frame: str, width: int, height: int) -> str:
    return f"""<gazebo reference="{frame}"><sensor type="camera" name="{name}"><update_rate>10</update_rate>
    <camera><horizontal_fov>1.0</horizontal_fov><image><width>{width}</width><height>{height}</height></image>
    <clip><near>0.05</near><far>20</far></clip></camera>
    <plugin name="{name}_plugin" filename="libgazebo_ros_camera.so"><cameraName>{ns}</cameraName>
    <imageTopicName>image_raw</imageTopicName><cameraInfoTopicName>camera_info</cameraInfoTopicName>
    <frameName>{frame}</frameName></plugin></sensor></gazebo>"""


URDF = f"""<robot name="lookout">
  <link name="base_link"><collision><geometry><cylinder radius="0.1" length="0.1"/></geometry></collision></link>
  <link name="left_wheel"><collision><geometry><cylinder radius="0.05" length="0.02"/></geometry></collision></link>
  <link name="right_wheel"><collision><geometry><cylinder radius="0.05" length="0.02"/></geometry></collision></link>
  <link name="front_laser"/><link name="rear_laser"/><link name="front_cam"/><link name="rear_cam"/>
  <joint name="left_joint" type="continuous"><parent link="base_link"/><child link="left_wheel"/>
    <origin xyz="0 0.09 0.05" rpy="-1.5707963267948966 0 0"/><axis xyz="0 0 1"/></joint>
  <joint name="right_joint" type="continuous"><parent link="base_link"/><child link="right_wheel"/>
    <origin xyz="0 -0.09 0.05" rpy="-1.5707963267948966 0 0"/><axis xyz="0 0 1"/></joint>
  <joint name="front_laser_joint" type="fixed"><parent link="base_link"/><child link="front_laser"/>
    <origin xyz="0.1 0 0.2"/></joint>
  <joint name="rear_laser_joint" type="fixed"><parent link="base_link"/><child link="rear_laser"/>
    <origin xyz="-0.1 0 0.2" rpy="0 0 3.141592653589793"/></joint>
  <joint name="front_cam_joint" type="fixed"><parent link="base_link"/><child link="front_cam"/>
    <origin xyz="0.1 0 0.15"/></joint>
  <joint name="rear_cam_joint" type="fixed"><parent link="base_link"/><child link="rear_cam"/>
    <origin xyz="-0.1 0 0.15" rpy="0 0 3.141592653589793"/></joint>
  <gazebo><plugin name="drive" filename="libgazebo_ros_diff_drive.so">
    <leftJoint>left_joint</leftJoint><rightJoint>right_joint</rightJoint>
    <wheelSeparation>0.18</wheelSeparation><wheelDiameter>0.1</wheelDiameter>
    <robotBaseFrame>base_link</robotBaseFrame></plugin></gazebo>
  {lidar("front_lidar", "front/scan", "front_laser", 101)}
  {lidar("rear_lidar", "rear/scan", "rear_laser", 51)}
  {camera("front_camera", "front_cam", "front_cam", 64, 48)}
  {camera("rear_camera", "rear_cam", "rear_cam", 32, 24)}
</robot>"""


@pytest.fixture
def sim() -> Iterator[tuple[SimNode, Node]]:
    with run_master() as master:
        node = Node("several_sensors_sim", master_uri=master)
        client = Node("several_sensors_client", master_uri=master)
        try:
            sn = SimNode(node, NodeLog(node.name), Simulation(World("empty")), 0.0, None)
            sn.sim.add_obstacle("wall_ahead", "box", (0.2, 4.0), 2.0, 0.0, 0.0, 1.0, (200, 0, 0))
            sn.sim.add_obstacle("wall_behind", "box", (0.2, 4.0), -3.0, 0.0, 0.0, 1.0, (0, 0, 200))
            yield sn, client
        finally:
            client.shutdown("test over")
            node.shutdown("test over")


def first(client: Node, topic: str, cls: Any, sn: SimNode) -> Any:
    got: list[Any] = []
    ready = threading.Event()

    def keep(msg: Any) -> None:
        got.append(msg)
        ready.set()

    sub = client.subscriber(topic, cls, keep, queue_size=1)
    try:
        wait_until(lambda: sub.get_num_connections() > 0, 10, f"a connection to {topic}")

        def stepped() -> bool:
            sn._step_and_publish()
            return ready.wait(0.01)

        wait_until(stepped, 15, f"a message on {topic}")
    finally:
        sub.unregister()
    return got[0]


def test_each_lidar_and_camera_has_its_own_topic_frame_pose_and_size(sim: tuple[SimNode, Node]) -> None:
    sn, client = sim
    model = load_robot_model(URDF)
    assert model.laser is not None and model.camera is not None
    assert [spec.topic for spec in model.extra_lasers] == ["/rear/scan"]
    assert [spec.image_topic for spec in model.extra_cameras] == ["/rear_cam/image_raw"]
    sn.add_robot("lookout", model, 0.0, 0.0, 0.0, False)

    front = first(client, "/front/scan", LaserScan, sn)
    rear = first(client, "/rear/scan", LaserScan, sn)
    assert (front.header.frame_id, len(front.ranges)) == ("front_laser", 101)
    assert (rear.header.frame_id, len(rear.ranges)) == ("rear_laser", 51)
    # the middle beams: 2 m ahead less the wall's half thickness and the lidar's 0.1 m offset;
    # the rear lidar turned by pi sees the wall 3 m behind
    assert front.ranges[50] == pytest.approx(2.0 - 0.1 - 0.1, abs=0.03)
    assert rear.ranges[25] == pytest.approx(3.0 - 0.1 - 0.1, abs=0.03)

    front_img = first(client, "/front_cam/image_raw", Image, sn)
    rear_img = first(client, "/rear_cam/image_raw", Image, sn)
    assert (front_img.header.frame_id, front_img.width, front_img.height) == ("front_cam", 64, 48)
    assert (rear_img.header.frame_id, rear_img.width, rear_img.height) == ("rear_cam", 32, 24)

    def centre(img: Any) -> tuple[int, int, int]:
        px = np.frombuffer(bytes(img.data), dtype=np.uint8).reshape(img.height, img.width, 3)
        r, g, b = (int(v) for v in px[img.height // 2, img.width // 2])
        return r, g, b

    r, _g, b = centre(front_img)
    assert r > b, "the front camera sees the red wall ahead"
    r, _g, b = centre(rear_img)
    assert b > r, "the rear camera sees the blue wall behind"
    info = first(client, "/rear_cam/camera_info", CameraInfo, sn)
    assert (info.width, info.height, info.header.frame_id) == (32, 24, "rear_cam")
    assert info.K[0] == pytest.approx((32 / 2) / math.tan(0.5), rel=1e-6)
