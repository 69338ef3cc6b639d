"""What a Gazebo description publishes besides its drive and sensors: only what its plugins ask for
(issue 23 leftovers, item 5). Gazebo has no /tf_static of its own (robot_state_publisher sends the
fixed joints), no ``contact`` topic and no ``base_pose_ground_truth``: a ``libgazebo_ros_p3d.so``
publishes the true pose on its topicName in its frameName, a ``libgazebo_ros_bumper.so`` contact
sensor gazebo_msgs/ContactsState on its bumperTopicName. Our own PuzzleBot keeps its topics."""

from __future__ import annotations

from collections.abc import Iterator

import pytest
from gazebo_helpers import two_wheel_urdf

from ninjemys.idl.loader import get_message_class
from ninjemys.node import Node
from ninjemys.node.log import NodeLog
from ninjemys.sim.description.xmltree import DescriptionError
from ninjemys.sim.puzzlebot_node import SimNode
from ninjemys.sim.robot_model import load_robot_model, model_from_urdf
from ninjemys.sim.simcore import Simulation
from ninjemys.sim.world2d import Obstacle, World, box_outline
from ninjemys.testing import run_master, wait_until

Odometry = get_message_class("nav_msgs/Odometry")
ContactsState = get_message_class("gazebo_msgs/ContactsState")


P3D = """<gazebo><plugin name="truth" filename="libgazebo_ros_p3d.so">
    <alwaysOn>true</alwaysOn><updateRate>20.0</updateRate><bodyName>base_link</bodyName>
    <topicName>ground_truth/state</topicName><frameName>world</frameName></plugin></gazebo>"""
BUMPER = """<gazebo reference="base_link"><sensor name="bumper" type="contact"><update_rate>50</update_rate>
    <contact><collision>base_link_collision</collision></contact>
    <plugin name="bumper_plugin" filename="libgazebo_ros_bumper.so">
      <bumperTopicName>bumper</bumperTopicName><frameName>base_link</frameName></plugin></sensor></gazebo>"""


@pytest.fixture
def sim() -> Iterator[tuple[SimNode, Node]]:
    with run_master() as master:
        node = Node("plugin_sim", master_uri=master)
        client = Node("plugin_client", master_uri=master)
        try:
            wall = Obstacle("wall", "box", box_outline(1.0, 0.0, 0.1, 2.0), 0.5, (128, 128, 128))
            world = World("empty", obstacles=[wall])
            yield SimNode(node, NodeLog(node.name), Simulation(world), 0.0, None), client
        finally:
            client.shutdown("test over")
            node.shutdown("test over")


def _published(client: Node) -> dict[str, str]:
    return dict(client.master.get_published_topics("/"))


def test_a_gazebo_description_without_p3d_or_bumper_publishes_no_truth_contact_or_tf_static(sim) -> None:  # type: ignore[no-untyped-def]
    sn, client = sim
    model = model_from_urdf(two_wheel_urdf("plugbot"), "plugbot.urdf")
    assert model.ground_truth is None and model.contact_topic is None and model.bumper is None
    sn.add_robot("plugbot", model, 0.0, 0.0, 0.0, False)
    topics = _published(client)
    assert "/cmd_vel" not in topics  # subscribed, not published
    assert "/odom" in topics
    for absent in ("/tf_static", "/contact", "/base_pose_ground_truth", "/bumper_states"):
        assert absent not in topics, f"{absent} is published, Gazebo would not"


def test_our_puzzlebot_keeps_its_ground_truth_contact_and_tf_static(sim) -> None:  # type: ignore[no-untyped-def]
    sn, client = sim
    sn.add_robot("puzzlebot", load_robot_model("puzzlebot"), 0.0, 0.0, 0.0, False)
    topics = _published(client)
    assert topics["/base_pose_ground_truth"] == "nav_msgs/Odometry"
    assert topics["/contact"] == "std_msgs/Bool"
    assert topics["/tf_static"] == "tf2_msgs/TFMessage"


def test_p3d_publishes_the_true_pose_on_its_topic_frame_and_rate(sim) -> None:  # type: ignore[no-untyped-def]
    sn, client = sim
    model = model_from_urdf(two_wheel_urdf("plugbot", P3D), "plugbot.urdf")
    sn.add_robot("plugbot", model, -0.5, 0.25, 0.0, False)
    topics = _published(client)
    assert topics["/ground_truth/state"] == "nav_msgs/Odometry"
    assert "/base_pose_ground_truth" not in topics and "/contact" not in topics
    got: list = []
    client.subscriber("/ground_truth/state", Odometry, got.append, queue_size=100)
    pub = sn.io["plugbot"].pubs["ground_truth"]
    wait_until(lambda: pub.get_num_connections(), 10, "the subscriber connected")
    for _ in range(100):  # one simulated second at 100 steps a second: 20 messages at 20 Hz
        with sn.lock:
            sn._step_and_publish()
    wait_until(lambda: len(got) >= 20, 10, "20 ground truth messages")
    stamps = [m.header.stamp.to_sec() for m in got]
    assert [round(b - a, 6) for a, b in zip(stamps[1:], stamps[2:], strict=False)] == [0.05] * (
        len(got) - 2
    )  # 20 Hz
    msg = got[-1]
    assert (msg.header.frame_id, msg.child_frame_id) == ("world", "base_link")
    assert (msg.pose.pose.position.x, msg.pose.pose.position.y) == pytest.approx((-0.5, 0.25))


def test_a_bumper_publishes_contacts_state_and_names_what_it_touches(sim) -> None:  # type: ignore[no-untyped-def]
    sn, client = sim
    model = model_from_urdf(two_wheel_urdf("plugbot", BUMPER), "plugbot.urdf")
    assert model.bumper is not None and model.bumper.rate == 50.0
    sn.add_robot("plugbot", model, 0.7, 0.0, 0.0, False)
    topics = _published(client)
    assert topics["/bumper"] == "gazebo_msgs/ContactsState"
    assert "/contact" not in topics
    got: list = []
    client.subscriber("/bumper", ContactsState, got.append, queue_size=100)
    wait_until(lambda: sn.io["plugbot"].pubs["bumper"].get_num_connections(), 10, "the subscriber connected")
    with sn.lock:
        sn._step_and_publish()
    wait_until(lambda: got, 10, "a ContactsState")
    assert got[-1].states == [] and got[-1].header.frame_id == "base_link"
    sn.io["plugbot"].robot.command(0.3, 0.0)  # drive into the wall at x 0.95
    for _ in range(300):
        with sn.lock:
            sn._step_and_publish()
    wait_until(lambda: got and got[-1].states, 10, "a contact")
    (state,) = got[-1].states
    assert state.collision1_name == "plugbot::base_link_collision"
    assert state.collision2_name == "wall"


def test_a_p3d_without_its_body_or_topic_is_refused_naming_the_element() -> None:
    bad = P3D.replace("<bodyName>base_link</bodyName>", "")
    with pytest.raises(DescriptionError, match=r"plugbot.urdf:\d+.*<bodyName> is required"):
        model_from_urdf(two_wheel_urdf("plugbot", bad), "plugbot.urdf")
    bad = P3D.replace("<bodyName>base_link</bodyName>", "<bodyName>chassis</bodyName>")
    with pytest.raises(DescriptionError, match="bodyName 'chassis' names no link"):
        model_from_urdf(two_wheel_urdf("plugbot", bad), "plugbot.urdf")
