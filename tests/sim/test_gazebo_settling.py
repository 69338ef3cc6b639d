"""Robots and models settle as Gazebo's physics settles them (issue 23 leftovers, items 1 to 3).

1. A robot spawned over a table top lands on it (its model pose z is the top plus its own rest
   height), drives there without meeting the legs under it, and falls to the floor when its centre
   leaves the top; one spawned beside it or under it stands on the floor.
2. ``/gazebo/set_model_state`` with a z re-settles: a robot or a model with physics falls onto what
   is under it (or is pushed up out of a table top); a static model stays where it is put.
3. While physics is paused nothing settles: get_model_state, get_link_state and /gazebo/model_states
   report the pose a model was spawned or set at, until unpause_physics."""

from __future__ import annotations

from collections.abc import Iterator

import pytest
from test_drop_onto_a_table import BOX, ROBOT, TABLE, spawn, state_z

from ninjemys.idl.loader import get_message_class, get_service_class
from ninjemys.node import Node
from ninjemys.node.log import NodeLog
from ninjemys.sim.puzzlebot_node import SimNode
from ninjemys.sim.sdf import parse_sdf_world
from ninjemys.sim.simcore import Simulation
from ninjemys.sim.world2d import World
from ninjemys.testing import run_master, wait_until

SetModelState = get_service_class("gazebo_msgs/SetModelState")
GetLinkState = get_service_class("gazebo_msgs/GetLinkState")
ModelStates = get_message_class("gazebo_msgs/ModelStates")

TABLE_SDF = '<sdf version="1.6">' + TABLE.format(name="t", x=0, y=0) + "</sdf>"
BOX_SDF = '<sdf version="1.6">' + BOX.format(name="b", x=0, y=0, z=0) + "</sdf>"
#: the robot's root link stands 7 cm above what it stands on; the table top is at 0.75 m
REST = 0.07
TOP = 0.75


@pytest.fixture
def sim() -> Iterator[SimNode]:
    with run_master() as master:
        node = Node("settle_sim", master_uri=master)
        try:
            yield SimNode(node, NodeLog(node.name), Simulation(World("empty")), 0.0, None)
        finally:
            node.shutdown("test over")


def set_state(sim: SimNode, name: str, x: float, y: float, z: float) -> tuple[bool, str]:
    req = SetModelState._request_class()
    s = req.model_state
    s.model_name = name
    s.pose.position.x, s.pose.position.y, s.pose.position.z = x, y, z
    s.pose.orientation.w = 1.0
    resp = sim.gazebo._set_model_state(req)
    return resp.success, resp.status_message


def step(sim: SimNode, n: int) -> None:
    for _ in range(n):
        with sim.lock:
            sim._step_and_publish()


def test_a_robot_spawned_over_a_table_lands_on_its_top_and_falls_off_its_edge(sim: SimNode) -> None:
    spawn(sim, "table", TABLE_SDF, 0.0, 0.0)
    spawn(sim, "up", ROBOT, 0.2, 0.0, 1.0)  # spawn_model -z 1: over the table top
    spawn(sim, "beside", ROBOT, 2.0, 0.0, 1.0)  # nothing under it: the floor
    spawn(sim, "under", ROBOT, -2.0, 0.0, 0.0)
    # a static box 0.3 m tall: a robot dropped over it stands on it
    crate = '<sdf version="1.6">' + BOX.format(name="c", x=0, y=0, z=0).replace(
        "<link", "<static>true</static><link"
    )
    spawn(sim, "crate", crate.replace("0.2 0.2 0.2", "0.6 0.6 0.3") + "</sdf>", 3.0, 3.0, 0.15)
    spawn(sim, "on_crate", ROBOT, 3.0, 3.0, 0.8)
    assert state_z(sim, "on_crate") == pytest.approx(0.3 + REST)
    assert state_z(sim, "up") == pytest.approx(TOP + REST)
    assert state_z(sim, "beside") == pytest.approx(REST)
    assert state_z(sim, "under") == pytest.approx(REST)
    up = sim.sim.robots["up"]
    assert up.elevation == pytest.approx(TOP)
    # its camera-less sensors and links ride on the top: the wheel axles are a radius above it
    req = GetLinkState._request_class()
    req.link_name = "up::wheel_left"
    assert sim.gazebo._get_link_state(req).link_state.pose.position.z == pytest.approx(TOP + 0.05)
    # it drives over the legs below it and off the +x edge (0.5 m): then it stands on the floor
    up.command(0.3, 0.0)
    step(sim, 60)  # 0.6 s: x 0.2 -> 0.38, still on the top
    assert not up.contact and state_z(sim, "up") == pytest.approx(TOP + REST)
    step(sim, 100)  # x 0.68: its centre has left the top
    assert up.x > 0.5 and not up.contact
    assert state_z(sim, "up") == pytest.approx(REST)


def test_a_robot_under_a_table_top_passes_under_it_and_one_on_it_is_not_stopped_by_the_legs(
    sim: SimNode,
) -> None:
    spawn(sim, "table", TABLE_SDF, 0.0, 0.0)
    spawn(sim, "low", ROBOT, -1.0, 0.0, 0.0)
    low = sim.sim.robots["low"]
    low.command(0.3, 0.0)
    step(sim, 700)  # 2.1 m: under the table and out the other side (the legs are at y +-0.35)
    assert low.x > 0.9 and not low.contact
    assert state_z(sim, "low") == pytest.approx(REST)


def test_set_model_state_re_settles_robots_and_models_with_physics_and_holds_static_ones(
    sim: SimNode,
) -> None:
    spawn(sim, "table", TABLE_SDF, 0.0, 0.0)
    spawn(sim, "bot", ROBOT, 2.0, 0.0, 0.0)
    spawn(sim, "box", BOX_SDF, -2.0, 0.0, 0.0)
    lamp = (
        '<robot name="lamp"><link name="l"><collision><geometry><box size="0.2 0.2 0.2"/></geometry>'
        "</collision></link><gazebo><static>true</static></gazebo></robot>"
    )
    spawn(sim, "lamp", lamp, -3.0, 0.0, 0.1)
    # a robot put in the air over the table lands on its top, one put into the floor stands on it
    assert set_state(sim, "bot", 0.1, 0.0, 1.5)[0]
    assert state_z(sim, "bot") == pytest.approx(TOP + REST)
    assert set_state(sim, "bot", 2.0, 0.0, 3.0)[0]
    assert state_z(sim, "bot") == pytest.approx(REST)
    # a box with physics set over the table lands on it, its collision raised with it
    assert set_state(sim, "box", 0.2, 0.1, 2.0)[0]
    assert state_z(sim, "box") == pytest.approx(TOP + 0.1)
    (box,) = [o for o in sim.sim.world.obstacles if o.model_name == "box"]
    assert (box.base, box.height) == pytest.approx((TOP, TOP + 0.2))
    # set into the table top (its middle above it): pushed up onto it; beside it: onto the floor
    assert set_state(sim, "box", -0.2, 0.0, 0.8)[0]
    assert state_z(sim, "box") == pytest.approx(TOP + 0.1)
    assert set_state(sim, "box", -2.0, 1.0, 1.0)[0]
    assert state_z(sim, "box") == pytest.approx(0.1)
    (box,) = [o for o in sim.sim.world.obstacles if o.model_name == "box"]
    assert (box.base, box.height) == pytest.approx((0.0, 0.2))
    # a static model stays in the air where it is put, its collision with it
    assert set_state(sim, "lamp", -3.0, 0.0, 1.2)[0]
    assert state_z(sim, "lamp") == pytest.approx(1.2)
    (held,) = [o for o in sim.sim.world.obstacles if o.model_name == "lamp"]
    assert (held.base, held.height) == pytest.approx((1.1, 1.3))
    # a static model pushed wholly under the floor is refused, with the reason
    ok, status = set_state(sim, "lamp", -3.0, 0.0, -1.0)
    assert not ok and "under the floor" in status


def test_a_paused_world_reports_spawn_poses_until_unpaused(sim: SimNode) -> None:
    spawn(sim, "table", TABLE_SDF, 0.0, 0.0)
    sim.gazebo._pause(None)
    spawn(sim, "box", BOX_SDF, 0.2, 0.1, 2.0)
    spawn(sim, "bot", ROBOT, 3.0, 0.0, 0.5)
    assert state_z(sim, "box") == pytest.approx(2.0)
    assert state_z(sim, "bot") == pytest.approx(0.5)
    # the links follow the model: the wheel axles 2 cm below the root link
    req = GetLinkState._request_class()
    req.link_name = "bot::wheel_left"
    assert sim.gazebo._get_link_state(req).link_state.pose.position.z == pytest.approx(0.48)
    # /gazebo/model_states says the same
    got: list = []
    client = sim.node
    client.subscriber("/gazebo/model_states", ModelStates, got.append, queue_size=10)
    wait_until(lambda: sim.gazebo.model_states_pub.get_num_connections(), 10, "model_states subscriber")
    sim.gazebo.after_step(sim._stamp())
    wait_until(lambda: got, 10, "/gazebo/model_states")
    zs = {n: p.position.z for n, p in zip(got[-1].name, got[-1].pose, strict=True)}
    assert zs["box"] == pytest.approx(2.0) and zs["bot"] == pytest.approx(0.5)
    # a set_model_state while paused is held too
    assert set_state(sim, "bot", -0.2, -0.2, 1.4)[0]
    assert state_z(sim, "bot") == pytest.approx(1.4)
    sim.gazebo._unpause(None)
    assert state_z(sim, "box") == pytest.approx(TOP + 0.1)
    assert state_z(sim, "bot") == pytest.approx(TOP + REST)
    # running, a spawn settles at once
    spawn(sim, "box2", BOX_SDF, -2.0, 0.0, 2.0)
    assert state_z(sim, "box2") == pytest.approx(0.1)


def test_a_world_loaded_paused_shows_its_models_where_the_file_puts_them_until_unpaused() -> None:
    text = (
        '<sdf version="1.6"><world name="w">'
        + TABLE.format(name="table", x=0, y=0)
        + BOX.format(name="crate", x=0.2, y=0.1, z=2.0)
        + "</world></sdf>"
    )
    world = parse_sdf_world(text, "w.world", {"HOME": "/nonexistent"})
    with run_master() as master:
        node = Node("paused_world_sim", master_uri=master)
        try:
            sim = SimNode(node, NodeLog(node.name), Simulation(world), 0.0, None)
            sim.stepper.paused = True  # what ~paused does at start
            sim.gazebo.hold_world_models()
            assert state_z(sim, "crate") == pytest.approx(2.0)
            assert state_z(sim, "table") == pytest.approx(0.0)  # static: where the file puts it
            sim.gazebo._unpause(None)
            assert state_z(sim, "crate") == pytest.approx(TOP + 0.1)
        finally:
            node.shutdown("test over")
