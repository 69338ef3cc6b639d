"""Heights as Gazebo's physics leaves them (issue 23 leftovers, item 1).

A model with physics falls onto the floor or onto what is under it (a static table top, a box that
landed before it), never through it; a static one stays where it is put. A robot from a URDF
stands on its wheels: /gazebo/model_states gives its root link's height above the floor then
(Gazebo drops a robot spawned with ``-z 0.5``), and its links follow from there."""

from __future__ import annotations

import math
from collections.abc import Iterator

import numpy as np
import pytest
from gazebo_helpers import two_wheel_urdf

from ninjemys.idl.loader import get_service_class
from ninjemys.node import Node
from ninjemys.node.log import NodeLog
from ninjemys.sim.puzzlebot_node import SimNode
from ninjemys.sim.robot_model import model_from_urdf
from ninjemys.sim.sdf import overlaps, parse_sdf_world, sdf_model_obstacles
from ninjemys.sim.simcore import Simulation
from ninjemys.sim.world2d import World
from ninjemys.testing import run_master

SpawnModel = get_service_class("gazebo_msgs/SpawnModel")
GetModelState = get_service_class("gazebo_msgs/GetModelState")
GetLinkState = get_service_class("gazebo_msgs/GetLinkState")

NO_ENV = {"HOME": "/nonexistent"}

#: a table: top 0.70-0.75 m, four legs; 1.0 x 0.8 m
TABLE = (
    '<model name="{name}"><static>true</static><pose>{x} {y} 0 0 0 0</pose><link name="link">'
    '<collision name="top"><pose>0 0 0.725 0 0 0</pose><geometry><box><size>1.0 0.8 0.05</size></box>'
    "</geometry></collision>"
    + "".join(
        f'<collision name="leg{i}"><pose>{sx * 0.45} {sy * 0.35} 0.35 0 0 0</pose>'
        "<geometry><box><size>0.05 0.05 0.7</size></box></geometry></collision>"
        for i, (sx, sy) in enumerate(((1, 1), (-1, 1), (-1, -1), (1, -1)))
    )
    + "</link></model>"
)
#: a 0.2 m box with physics (its origin at its centre)
BOX = (
    '<model name="{name}"><pose>{x} {y} {z} 0 0 0</pose><link name="l"><collision name="c">'
    "<geometry><box><size>0.2 0.2 0.2</size></box></geometry></collision></link></model>"
)


def _by_name(world: World) -> dict:
    return {o.name: o for o in world.obstacles}


def test_a_box_dropped_over_a_table_lands_on_its_top_and_one_beside_it_on_the_floor() -> None:
    text = (
        '<sdf version="1.6"><world name="w">'
        + TABLE.format(name="table", x=0, y=0)
        + BOX.format(name="on_table", x=0.2, y=0.1, z=2.0)
        + BOX.format(name="beside", x=2.0, y=0.0, z=2.0)
        + BOX.format(name="on_box", x=0.25, y=0.1, z=3.0)  # lands on on_table: a stack
        + BOX.format(name="edge", x=0.55, y=0.0, z=1.5)  # overhangs the table's edge: still held by it
        + "</world></sdf>"
    )
    world = parse_sdf_world(text, "w.world", NO_ENV)
    ob = _by_name(world)
    assert (ob["on_table"].base, ob["on_table"].height) == pytest.approx((0.75, 0.95))
    assert (ob["beside"].base, ob["beside"].height) == pytest.approx((0.0, 0.2))
    assert (ob["on_box"].base, ob["on_box"].height) == pytest.approx((0.95, 1.15))
    assert (ob["edge"].base, ob["edge"].height) == pytest.approx((0.75, 0.95))
    # the table itself is where it was put
    assert ob["table::link::top"].base == pytest.approx(0.70)


def test_a_box_spawned_into_a_table_top_is_pushed_up_onto_it_and_one_under_it_falls_to_the_floor() -> None:
    text = (
        '<sdf version="1.6"><world name="w">'
        + TABLE.format(name="table", x=0, y=0)
        + BOX.format(name="into", x=0.0, y=0.0, z=0.80)  # 0.70-0.90: its middle above the top
        + BOX.format(name="under", x=0.0, y=0.0, z=0.40)  # under the top: onto the floor
        + "</world></sdf>"
    )
    ob = _by_name(parse_sdf_world(text, "w.world", NO_ENV))
    assert ob["into"].base == pytest.approx(0.75)
    assert ob["under"].base == pytest.approx(0.0)


def test_outlines_that_only_touch_hold_nothing() -> None:
    a = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=float)
    assert overlaps(a, a + [0.5, 0.5])
    assert not overlaps(a, a + [1.0, 0.0])  # side by side
    assert not overlaps(a, a + [1.2, 0.0])
    assert overlaps(a, np.array([[0.5, -1.0], [0.5, 2.0]]))  # a wall across it


def test_a_spawned_model_lands_on_the_world_under_it() -> None:
    from ninjemys.sim.sdf import Support

    table_top = Support(np.array([[-0.5, -0.4], [0.5, -0.4], [0.5, 0.4], [-0.5, 0.4]]), 0.75)
    drops: dict[str, float] = {}
    (box,) = sdf_model_obstacles(
        '<sdf version="1.6">' + BOX.format(name="b", x=0, y=0, z=0) + "</sdf>",
        z=2.0,
        env=NO_ENV,
        drops=drops,
        supports=[table_top],
    )
    assert (box.base, box.height) == pytest.approx((0.75, 0.95))
    assert drops == {"b": pytest.approx(2.0 - 0.1 - 0.75)}


# -- through the /gazebo services ------------------------------------------------------------------

ROBOT = two_wheel_urdf("axlebot")


@pytest.fixture
def sim() -> Iterator[SimNode]:
    with run_master() as master:
        node = Node("drop_sim", master_uri=master)
        try:
            yield SimNode(node, NodeLog(node.name), Simulation(World("empty")), 0.0, None)
        finally:
            node.shutdown("test over")


def spawn(sim: SimNode, name: str, xml: str, x: float = 0.0, y: float = 0.0, z: float = 0.0):  # type: ignore[no-untyped-def]
    req = SpawnModel._request_class()
    req.model_name, req.model_xml = name, xml
    req.initial_pose.position.x, req.initial_pose.position.y, req.initial_pose.position.z = x, y, z
    req.initial_pose.orientation.w = 1.0
    resp = sim.gazebo._spawn(req)
    assert resp.success, resp.status_message
    return resp


def state_z(sim: SimNode, name: str) -> float:
    req = GetModelState._request_class()
    req.model_name = name
    resp = sim.gazebo._get_model_state(req)
    assert resp.success, resp.status_message
    return float(resp.pose.position.z)


def test_a_urdf_robot_spawned_in_the_air_stands_on_its_wheels(sim: SimNode) -> None:
    assert model_from_urdf(ROBOT, "axlebot.urdf").rest_z == pytest.approx(0.07)
    spawn(sim, "high", ROBOT, 0.0, 0.0, 0.5)  # spawn_model -z 0.5: it falls
    spawn(sim, "low", ROBOT, 1.0, 0.0, 0.0)  # -z 0: its wheels would be in the floor: pushed up
    assert state_z(sim, "high") == pytest.approx(0.07)
    assert state_z(sim, "low") == pytest.approx(0.07)
    pose = sim.gazebo.model_pose("high")
    assert pose is not None and pose[2] == pytest.approx(0.07)
    # the wheel links' axles are a wheel radius above the floor
    req = GetLinkState._request_class()
    req.link_name = "high::wheel_left"
    resp = sim.gazebo._get_link_state(req)
    assert resp.success, resp.status_message
    assert resp.link_state.pose.position.z == pytest.approx(0.05)
    assert resp.link_state.pose.position.y == pytest.approx(0.09)


def test_an_sdf_box_spawned_over_a_spawned_table_lands_on_it(sim: SimNode) -> None:
    spawn(sim, "table", '<sdf version="1.6">' + TABLE.format(name="t", x=0, y=0) + "</sdf>", 2.0, 1.0)
    spawn(sim, "box", '<sdf version="1.6">' + BOX.format(name="b", x=0, y=0, z=0) + "</sdf>", 2.1, 1.0, 1.5)
    assert state_z(sim, "box") == pytest.approx(0.85)  # its centre: 0.75 + 0.1
    (box,) = [o for o in sim.sim.world.obstacles if o.model_name == "box"]
    assert (box.base, box.height) == pytest.approx((0.75, 0.95))
    # beside the table it falls to the floor
    spawn(
        sim,
        "floor_box",
        '<sdf version="1.6">' + BOX.format(name="b", x=0, y=0, z=0) + "</sdf>",
        4.0,
        1.0,
        1.5,
    )
    assert state_z(sim, "floor_box") == pytest.approx(0.1)


def test_a_urdf_box_falls_onto_the_table_and_a_static_one_stays_in_the_air(sim: SimNode) -> None:
    spawn(sim, "table", '<sdf version="1.6">' + TABLE.format(name="t", x=0, y=0) + "</sdf>", 0.0, 0.0)
    urdf = (
        '<robot name="crate"><link name="l"><collision><geometry><box size="0.3 0.3 0.2"/></geometry>'
        '</collision><visual><geometry><box size="0.3 0.3 0.2"/></geometry></visual></link>{gz}</robot>'
    )
    spawn(
        sim,
        "crate",
        urdf.format(gz='<gazebo reference="l"><material>Gazebo/Red</material></gazebo>'),
        0,
        0,
        2,
    )
    assert state_z(sim, "crate") == pytest.approx(0.85)
    (crate,) = [o for o in sim.sim.world.obstacles if o.name == "crate"]
    assert (crate.base, crate.height) == pytest.approx((0.75, 0.95))
    assert crate.color == (255, 0, 0)  # the <gazebo> block's stock material
    spawn(sim, "lamp", urdf.format(gz="<gazebo><static>true</static></gazebo>"), 3.0, 0.0, 1.5)
    assert state_z(sim, "lamp") == pytest.approx(1.5)
    (lamp,) = [o for o in sim.sim.world.obstacles if o.name == "lamp"]
    assert (lamp.base, lamp.height) == pytest.approx((1.4, 1.6))
    assert math.isclose(sim.gazebo.model_pose("lamp")[2], 1.5)  # type: ignore[index]


def test_a_world_files_models_report_the_heights_they_settled_at() -> None:
    text = (
        '<sdf version="1.6"><world name="w">'
        + TABLE.format(name="table", x=0, y=0)
        + BOX.format(name="on_table", x=0.2, y=0.1, z=2.0)
        + BOX.format(name="beside", x=2.0, y=0.0, z=2.0)
        + '<model name="shelf"><static>true</static><pose>4 0 1.2 0 0 0</pose><link name="l">'
        '<collision name="c"><geometry><box><size>0.5 0.3 0.04</size></box></geometry></collision></link></model>'
        + "</world></sdf>"
    )
    world = parse_sdf_world(text, "w.world", NO_ENV)
    assert world.model_heights == pytest.approx({"table": 0.0, "on_table": 0.85, "beside": 0.1, "shelf": 1.2})
    with run_master() as master:
        node = Node("world_heights", master_uri=master)
        try:
            sn = SimNode(node, NodeLog(node.name), Simulation(world), 0.0, None)
            assert state_z(sn, "on_table") == pytest.approx(0.85)
            assert state_z(sn, "shelf") == pytest.approx(1.2)
        finally:
            node.shutdown("test over")


def test_a_pose_of_three_numbers_is_a_position_as_gazebo_11_loads_the_makers_models() -> None:
    """The maker's ``puzzlebot_base`` and ``office_floor`` models have ``<pose>0 0 0.0</pose>`` on a
    visual; Gazebo 11 loads them. Ours reads x y z with no rotation and notes it once."""
    text = (
        '<sdf version="1.6"><world name="w"><model name="m"><static>1</static><pose>1 2 0.5</pose>'
        '<link name="l"><collision name="c"><pose>0 0 0.0</pose><geometry><box><size>0.2 0.2 0.2</size>'
        "</box></geometry></collision></link></model></world></sdf>"
    )
    warnings: list[str] = []
    (box,) = parse_sdf_world(text, "w.world", NO_ENV, warnings.append).obstacles
    assert box.outline.mean(axis=0) == pytest.approx([1.0, 2.0])
    assert (box.base, box.height) == pytest.approx((0.4, 0.6))
    (warning,) = warnings
    assert warning.count("<pose> of 3 numbers") == 1 and "w.world:1" in warning


def test_a_spawned_ground_plane_is_a_model_and_a_sun_is_not(sim: SimNode) -> None:
    database = (
        '<sdf version="1.6"><world name="default"><include><uri>model://{}</uri></include></world></sdf>'
    )
    spawn(sim, "gp", database.format("ground_plane"))
    spawn(sim, "sun", database.format("sun"))
    spawn(sim, "crate", '<sdf version="1.6">' + BOX.format(name="b", x=0, y=0, z=0) + "</sdf>", 1.0, 0.0, 0.5)
    assert sim.gazebo.model_names() == ["gp", "crate"]
    assert state_z(sim, "gp") == 0.0
    assert not [o for o in sim.sim.world.obstacles if o.model_name == "gp"]
    from ninjemys.sim.gazebo_api import DeleteModel

    req = DeleteModel._request_class()
    req.model_name = "gp"
    assert sim.gazebo._delete(req).success
    assert sim.gazebo.model_names() == ["crate"]
