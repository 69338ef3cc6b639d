"""Visual-only models (issue 23 leftovers, item 4): a link with ``<visual>`` and no ``<collision>``
(an ArUco tag board, a fiducial marker) is seen by Gazebo's cameras and not by its ray sensors nor
its physics: a lidar beam and a robot pass through it, a falling box does not land on it."""

from __future__ import annotations

import math
from collections.abc import Iterator

import numpy as np
import pytest
from test_drop_onto_a_table import BOX, spawn, state_z

from ninjemys.node import Node
from ninjemys.node.log import NodeLog
from ninjemys.sim.puzzlebot_node import SimNode
from ninjemys.sim.robot_model import load_robot_model
from ninjemys.sim.sdf import parse_sdf_world
from ninjemys.sim.simcore import Simulation, scan_angles
from ninjemys.sim.world2d import World
from ninjemys.testing import run_master

NO_ENV = {"HOME": "/nonexistent"}

#: a red tag board 1.5 m ahead of the robot, 0.4 m wide, from 0 to 0.4 m (static, as marker models are)
BOARD = (
    '<model name="{name}"><static>true</static><pose>1.5 0 0.2 0 0 0</pose><link name="tag">'
    '<visual name="face"><geometry><box><size>0.02 0.4 0.4</size></box></geometry>'
    "<material><diffuse>1 0 0 1</diffuse><ambient>1 0 0 1</ambient></material></visual></link></model>"
)
#: the same board with a collision: a solid board, for comparison
SOLID_BOARD = BOARD.replace(
    "</visual>",
    '</visual><collision name="c"><geometry><box><size>0.02 0.4 0.4</size></box></geometry></collision>',
)


def _world(board: str) -> World:
    return parse_sdf_world(
        '<sdf version="1.6"><world name="w">' + board.format(name="aruco") + "</world></sdf>",
        "w.world",
        NO_ENV,
    )


def _ahead(sim: Simulation) -> tuple[float, np.ndarray]:
    """The lidar's range straight ahead and the camera's middle column."""
    r = sim.robots["pb"]
    ranges = sim.scan(r)
    laser = r.model.laser
    assert laser is not None
    lo, _hi, inc = scan_angles(laser)
    ahead = int(round((0.0 - laser.pose.rpy[2] - lo) / inc)) % laser.beams
    rgb, _depth = sim.render(r, depth=False)
    return float(ranges[ahead]), rgb[:, rgb.shape[1] // 2]


def test_the_camera_sees_a_visual_only_board_the_lidar_does_not() -> None:
    world = _world(BOARD)
    (board,) = world.obstacles
    assert not board.solid and board.name == "aruco"
    assert "aruco" not in world.bare_models
    sim = Simulation(world)
    sim.add_robot("pb", load_robot_model("puzzlebot"), 0.0, 0.0, 0.0)
    rng, column = _ahead(sim)
    red = (column[:, 0] > 80) & (column[:, 1] < 60) & (column[:, 2] < 60)  # in the shade: 0.4 x 255
    assert red.sum() > 5, "the camera does not see the board"
    assert not (rng < 1.6), f"the lidar sees the visual-only board at {rng} m"
    # with a collision, the lidar sees it too (the test's own check that the board is in the beam)
    solid = Simulation(_world(SOLID_BOARD))
    solid.add_robot("pb", load_robot_model("puzzlebot"), 0.0, 0.0, 0.0)
    rng_solid, column_solid = _ahead(solid)
    assert rng_solid == pytest.approx(1.49 - load_robot_model("puzzlebot").laser.pose.xyz[0], abs=0.05)  # type: ignore[union-attr]
    assert ((column_solid[:, 0] > 80) & (column_solid[:, 1] < 60)).sum() == red.sum()


def test_a_robot_drives_through_a_visual_only_board_and_is_stopped_by_a_solid_one() -> None:
    for board, stopped in ((BOARD, False), (SOLID_BOARD, True)):
        sim = Simulation(_world(board))
        r = sim.add_robot("pb", load_robot_model("puzzlebot"), 0.0, 0.0, 0.0)
        r.command(0.3, 0.0)
        for _ in range(1000):  # 10 s: 3 m
            sim.step()
        assert r.contact is stopped
        assert bool(r.x < 1.5) is stopped


@pytest.fixture
def sim() -> Iterator[SimNode]:
    with run_master() as master:
        node = Node("visual_sim", master_uri=master)
        try:
            yield SimNode(node, NodeLog(node.name), Simulation(World("empty")), 0.0, None)
        finally:
            node.shutdown("test over")


def test_spawned_visual_only_models_hold_nothing_up_and_block_no_spawn(sim: SimNode) -> None:
    spawn(
        sim, "tag", '<sdf version="1.6">' + BOARD.format(name="t").replace("1.5 0 0.2", "0 0 0.2") + "</sdf>"
    )
    (tag,) = [o for o in sim.sim.world.obstacles if o.model_name == "tag"]
    assert not tag.solid
    # a box dropped on it falls through to the floor; a robot can be spawned on it
    spawn(sim, "box", '<sdf version="1.6">' + BOX.format(name="b", x=0, y=0, z=0) + "</sdf>", 0.0, 0.0, 2.0)
    assert state_z(sim, "box") == pytest.approx(0.1)
    sim.sim.remove_obstacle("box")
    sim.add_robot("pb", load_robot_model("puzzlebot"), 0.0, 0.0, math.pi / 2, False)
    # a URDF marker: a visual and no collision is seen only, and stays where it is spawned
    urdf = (
        '<robot name="marker"><link name="l"><visual><geometry><box size="0.3 0.3 0.01"/></geometry>'
        '<material name="w"><color rgba="1 1 1 1"/></material></visual></link></robot>'
    )
    spawn(sim, "marker", urdf, 3.0, 0.0, 1.0)
    (marker,) = [o for o in sim.sim.world.obstacles if o.model_name == "marker"]
    assert not marker.solid and state_z(sim, "marker") == pytest.approx(1.0)
