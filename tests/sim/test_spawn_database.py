"""``spawn_model -sdf -database NAME`` (issue 23 leftovers): the model is looked up on
GAZEBO_MODEL_PATH, then among the shipped models, read by the SDF reader (its collision shapes, heights
and colour) and placed at the spawn pose; a model with nothing solid (a light, a ground plane) is
accepted and adds nothing; what cannot be spawned is refused with the reason."""

from __future__ import annotations

import math
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

from ninjemys.idl.loader import get_service_class
from ninjemys.node import Node
from ninjemys.node.log import NodeLog
from ninjemys.sim.puzzlebot_node import SimNode
from ninjemys.sim.robot_model import load_robot_model
from ninjemys.sim.simcore import Simulation
from ninjemys.sim.spawn_model import DATABASE_TEMPLATE
from ninjemys.sim.world2d import World
from ninjemys.testing import run_master

SpawnModel = get_service_class("gazebo_msgs/SpawnModel")
DeleteModel = get_service_class("gazebo_msgs/DeleteModel")

PILLAR = """<?xml version="1.0"?>
<sdf version="1.6"><model name="pillar"><static>true</static><pose>0 0 0.4 0 0 0</pose><link name="l">
  <collision name="c"><geometry><cylinder><radius>0.2</radius><length>0.8</length></cylinder></geometry></collision>
  <visual name="v"><geometry><cylinder><radius>0.2</radius><length>0.8</length></cylinder></geometry>
    <material><diffuse>0 0 1 1</diffuse></material></visual>
</link></model></sdf>
"""
TWO_PIECES = (
    '<sdf version="1.6"><model name="gate"><static>true</static><link name="l">'
    '<collision name="a"><pose>0 -1 0 0 0 0</pose><geometry><box><size>0.2 0.2 1</size></box></geometry></collision>'
    '<collision name="b"><pose>0 1 0 0 0 0</pose><geometry><box><size>0.2 0.2 1</size></box></geometry></collision>'
    "</link></model></sdf>"
)


@pytest.fixture
def sim(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[SimNode]:
    models = tmp_path / "models"
    (models / "my_pillar").mkdir(parents=True)
    (models / "my_pillar" / "model.config").write_text(
        '<?xml version="1.0"?><model><name>my_pillar</name><sdf version="1.6">model.sdf</sdf></model>'
    )
    (models / "my_pillar" / "model.sdf").write_text(PILLAR)
    monkeypatch.setenv("GAZEBO_MODEL_PATH", str(models))
    with run_master() as master:
        node = Node("database_sim", master_uri=master)
        try:
            yield SimNode(node, NodeLog(node.name), Simulation(World("empty")), 0.0, None)
        finally:
            node.shutdown("test over")


def spawn(sim: SimNode, name: str, xml: str, x: float = 0.0, y: float = 0.0, yaw: float = 0.0):  # type: ignore[no-untyped-def]
    req = SpawnModel._request_class()
    req.model_name, req.model_xml = name, xml
    req.initial_pose.position.x, req.initial_pose.position.y = x, y
    req.initial_pose.orientation.z, req.initial_pose.orientation.w = math.sin(yaw / 2), math.cos(yaw / 2)
    return sim.gazebo._spawn(req)


def obstacle(sim: SimNode, name: str):  # type: ignore[no-untyped-def]
    (ob,) = [o for o in sim.sim.world.obstacles if o.name == name]
    return ob


def test_a_shipped_model_is_placed_at_the_spawn_pose_with_its_size_and_colour(sim: SimNode) -> None:
    resp = spawn(sim, "box1", DATABASE_TEMPLATE.format("cardboard_box"), 2.0, 1.0, math.pi / 2)
    assert resp.success, resp.status_message
    ob = obstacle(sim, "box1")
    assert ob.kind == "box" and ob.height == pytest.approx(0.3)
    assert ob.outline.mean(axis=0) == pytest.approx([2.0, 1.0], abs=1e-9)
    # 0.5 x 0.4 turned by 90 degrees: 0.4 along x, 0.5 along y
    span = ob.outline.max(axis=0) - ob.outline.min(axis=0)
    assert span == pytest.approx([0.4, 0.5], abs=1e-9)
    assert ob.color != (180, 130, 80)  # the model's material, not the generic crate colour
    assert "box1" in sim.gazebo.model_names()
    req = DeleteModel._request_class()
    req.model_name = "box1"
    assert sim.gazebo._delete(req).success
    assert "box1" not in sim.gazebo.model_names()


def test_a_model_on_gazebo_model_path_is_seen_by_the_lidar(sim: SimNode) -> None:
    resp = spawn(sim, "p", DATABASE_TEMPLATE.format("my_pillar"), 2.0, 0.0)
    assert resp.success, resp.status_message
    ob = obstacle(sim, "p")
    assert ob.kind == "cylinder" and ob.height == pytest.approx(0.8) and ob.color == (0, 0, 255)
    io = sim.add_robot("puzzlebot", load_robot_model("puzzlebot"), 0.0, 0.0, 0.0, False)
    ranges = sim.sim.scan(io.robot)
    laser = io.robot.model.laser
    assert laser is not None
    angles = laser.angle_min + np.arange(laser.beams) * (2 * math.pi / laser.beams)
    ahead = int(np.argmin(np.abs(np.angle(np.exp(1j * angles)))))
    lidar_x = laser.pose.xyz[0]
    assert float(ranges[ahead]) == pytest.approx(2.0 - 0.2 - lidar_x, abs=0.02)


def test_nothing_solid_is_accepted_and_adds_nothing(sim: SimNode) -> None:
    before = len(sim.sim.world.obstacles)
    for model in ("sun", "ground_plane"):
        assert spawn(sim, model, DATABASE_TEMPLATE.format(model)).success
    assert len(sim.sim.world.obstacles) == before


def test_what_cannot_be_spawned_is_refused_with_the_reason(sim: SimNode) -> None:
    resp = spawn(sim, "nope", DATABASE_TEMPLATE.format("no_such_model"))
    assert not resp.success and "no_such_model" in resp.status_message
    # a model of several pieces is spawned whole now (tests/sim/test_sdf_heights_and_pieces.py)
    resp = spawn(sim, "gate", TWO_PIECES)
    assert resp.success, resp.status_message
    assert sim.gazebo.model_names() == ["gate"]
    assert sorted(o.name for o in sim.sim.world.obstacles) == ["gate::l::a", "gate::l::b"]
