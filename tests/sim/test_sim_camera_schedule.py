"""The camera is rendered at its update_rate in simulated time, and only while someone reads its
images (issue 23: a fast simulation renders per simulated second what Gazebo would, no more)."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import pytest

from ninjemys.idl.loader import get_message_class
from ninjemys.node import Node
from ninjemys.node.log import NodeLog
from ninjemys.sim.puzzlebot_node import SimNode
from ninjemys.sim.robot_model import load_robot_model
from ninjemys.sim.simcore import Simulation
from ninjemys.sim.world2d import load_world
from ninjemys.sim.worlds import world_path
from ninjemys.testing import run_master, wait_until

Image = get_message_class("sensor_msgs/Image")
CameraInfo = get_message_class("sensor_msgs/CameraInfo")


@pytest.fixture
def sim() -> Iterator[tuple[SimNode, Node, list[tuple[bool, bool]]]]:
    with run_master() as master:
        node = Node("camera_schedule_sim", master_uri=master)
        client = Node("camera_schedule_client", master_uri=master)
        try:
            sn = SimNode(
                node, NodeLog(node.name), Simulation(load_world(world_path("office")), 0.01), 0.0, None
            )
            sn.add_robot("puzzlebot", load_robot_model("puzzlebot"), 0.0, 0.0, 0.0, False)
            renders: list[tuple[bool, bool]] = []
            real = sn.sim.render

            def counted(
                r: Any, scene: Any = None, colour: bool = True, depth: bool = True, extra: Any = None
            ) -> Any:
                renders.append((colour, depth))
                return real(r, scene, colour, depth, extra)

            sn.sim.render = counted  # type: ignore[method-assign]
            yield sn, client, renders
        finally:
            client.shutdown("test over")
            node.shutdown("test over")


def steps(sn: SimNode, n: int) -> None:
    for _ in range(n):
        sn._step_and_publish()


def test_rendered_at_its_rate_in_simulated_time_and_only_when_read(
    sim: tuple[SimNode, Node, list[tuple[bool, bool]]],
) -> None:
    sn, client, renders = sim
    camera = sn.io["puzzlebot"].robot.model.camera
    assert camera is not None and camera.rate == 30.0
    steps(sn, 300)  # 3 simulated seconds, nobody subscribed
    assert renders == []
    sub = client.subscriber("/" + camera.image_topic, Image, lambda _m: None, queue_size=1)
    wait_until(lambda: sn.io["puzzlebot"].pubs["image"].get_num_connections() > 0, 10, "the image subscriber")
    steps(sn, 300)  # 3 simulated seconds: 30 Hz, colour only (nobody reads the depth image)
    assert len(renders) == pytest.approx(90, abs=1) and set(renders) == {(True, False)}
    sub.unregister()
    wait_until(lambda: sn.io["puzzlebot"].pubs["image"].get_num_connections() == 0, 10, "the unsubscription")
    renders.clear()
    info = client.subscriber("/" + camera.info_topic, CameraInfo, lambda _m: None, queue_size=1)
    wait_until(lambda: sn.io["puzzlebot"].pubs["color_info"].get_num_connections() > 0, 10, "camera_info")
    steps(sn, 300)  # camera_info alone needs no image at all
    info.unregister()
    assert renders == []
