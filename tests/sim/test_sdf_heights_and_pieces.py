"""Shapes held at their height and models of several pieces, as Gazebo has them (issue 23 leftovers).

Gazebo: a static model stays where its pose puts it (a table top at 0.75 m, a shelf in the air); a
model with physics falls onto the floor. A planar lidar below something held in the air sees under
it, and a robot lower than it drives under it. A model of several collision pieces (a table: top and
four legs) is one model: spawned, listed, moved and deleted whole."""

from __future__ import annotations

import math
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

from ninjemys.idl.loader import get_message_class, get_service_class
from ninjemys.node import Node
from ninjemys.node.log import NodeLog
from ninjemys.sim.puzzlebot_node import SimNode
from ninjemys.sim.robot_model import load_robot_model
from ninjemys.sim.sdf import load_sdf_world, sdf_model_obstacles
from ninjemys.sim.simcore import Simulation
from ninjemys.sim.world2d import Obstacle, World
from ninjemys.testing import run_master

SpawnModel = get_service_class("gazebo_msgs/SpawnModel")
DeleteModel = get_service_class("gazebo_msgs/DeleteModel")
GetModelProperties = get_service_class("gazebo_msgs/GetModelProperties")
ModelState = get_message_class("gazebo_msgs/ModelState")

NO_ENV = {"HOME": "/nonexistent"}

LEG = (
    '<collision name="{n}"><pose>{x} {y} 0.35 0 0 0</pose>'
    "<geometry><box><size>0.05 0.05 0.7</size></box></geometry></collision>"
)
#: a table as Gazebo's model database has them: one link, a top and four legs; static or not
TABLE = (
    '<model name="{name}">{static}<pose>{x} {y} {z} 0 0 0</pose><link name="link">'
    '<collision name="top"><pose>0 0 0.725 0 0 0</pose>'
    "<geometry><box><size>1.0 0.8 0.05</size></box></geometry></collision>"
    + "".join(
        LEG.format(n=f"leg{i}", x=sx * 0.45, y=sy * 0.35)
        for i, (sx, sy) in enumerate(((1, 1), (-1, 1), (-1, -1), (1, -1)))
    )
    + '<visual name="v"><geometry><box><size>1 0.8 0.05</size></box></geometry>'
    "<material><diffuse>0.6 0.4 0.2 1</diffuse></material></visual></link></model>"
)
BOX = (
    '<model name="{name}">{static}<pose>{x} {y} {z} 0 0 0</pose><link name="l"><collision name="c">'
    "<geometry><box><size>0.4 0.4 0.4</size></box></geometry></collision></link></model>"
)
STATIC = "<static>true</static>"

WORLD = (
    '<sdf version="1.6"><world name="heights">'
    + TABLE.format(name="table", static=STATIC, x=2, y=0, z=0)
    + BOX.format(name="shelf", static=STATIC, x=0, y=2, z=1.0)  # held at 0.8-1.2 m: above the lidar
    + BOX.format(name="dropped", static="", x=0, y=-2, z=1.0)  # falls: stands 0-0.4 m
    + BOX.format(name="sunk", static=STATIC, x=-2, y=0, z=0.0)  # half in the floor: 0-0.2 m shows
    + "</world></sdf>"
)


def beam(deg: float) -> int:
    """The PuzzleBot's 360 beams start at -pi."""
    return int(round((math.radians(deg) + math.pi) / (2 * math.pi / 360))) % 360


def test_static_shapes_stay_at_their_height_and_others_fall(tmp_path: Path) -> None:
    path = tmp_path / "w.world"
    path.write_text(WORLD)
    warnings: list[str] = []
    world = load_sdf_world(path, env=NO_ENV, warn=warnings.append)
    assert warnings == []  # nothing floats unreported any more: it is simulated
    by_name = {o.name: o for o in world.obstacles}
    top = by_name["table::link::top"]
    assert (top.base, top.height) == pytest.approx((0.7, 0.75))
    assert top.model == "table" and top.color == (153, 102, 51)
    assert {o.model_name for o in world.obstacles} == {"table", "shelf", "dropped", "sunk"}
    assert sum(o.model == "table" for o in world.obstacles) == 5
    assert (by_name["shelf"].base, by_name["shelf"].height) == pytest.approx((0.8, 1.2))
    assert (by_name["dropped"].base, by_name["dropped"].height) == pytest.approx((0.0, 0.4))
    assert (by_name["sunk"].base, by_name["sunk"].height) == pytest.approx((0.0, 0.2))


def test_the_lidar_sees_under_what_is_held_above_it(tmp_path: Path) -> None:
    path = tmp_path / "w.world"
    path.write_text(WORLD)
    sim = Simulation(load_sdf_world(path, env=NO_ENV))
    model = load_robot_model("puzzlebot")
    model.laser.noise = 0.0
    r = sim.add_robot("pb", model, 0.0, 0.0, 0.0)
    ranges = sim.scan(r).astype(np.float64)
    # ahead (+x): under the table top (0.7 m up) the near legs, at x = 2 - 0.45 - 0.025, y = +-0.35
    leg_x = 2.0 - 0.45 - 0.025
    ahead = ranges[beam(math.degrees(math.atan2(0.35, leg_x)))]
    assert ahead == pytest.approx(math.hypot(leg_x, 0.35), abs=0.03)
    assert math.isinf(ranges[beam(0)])  # straight ahead between the legs: under the top, nothing
    assert math.isinf(ranges[beam(90)])  # the shelf is above the lidar (0.17 m)
    assert ranges[beam(-90)] == pytest.approx(2.0 - 0.2, abs=1e-4)  # the box that fell
    # the box sunk half into the floor is 0.2 m tall: above the lidar, so seen
    assert ranges[beam(180)] == pytest.approx(2.0 - 0.2, abs=1e-4)


def test_a_robot_drives_under_a_table_top_but_not_through_a_leg(tmp_path: Path) -> None:
    path = tmp_path / "w.world"
    path.write_text(WORLD)
    sim = Simulation(load_sdf_world(path, env=NO_ENV))
    r = sim.add_robot("pb", load_robot_model("puzzlebot"), 0.0, 0.0, 0.0)
    for _ in range(1000):  # 10 s at 0.3 m/s: through under the table (x 1.5-2.5) and beyond
        r.command(0.3, 0.0)
        sim.step()
    assert r.x > 2.6 and not r.contact, (r.x, r.contact_with)
    # a robot can also be spawned under the top, but not on a leg
    sim.add_robot("under", load_robot_model("puzzlebot"), 2.0, 0.0, 0.0)
    with pytest.raises(Exception, match="leg"):
        sim.add_robot("on_leg", load_robot_model("puzzlebot"), 2.45, 0.35, 0.0)
    # the same robot into the fallen box: stopped at its face
    r2 = sim.add_robot("pb2", load_robot_model("puzzlebot"), 0.0, -1.0, -math.pi / 2)
    for _ in range(500):
        r2.command(0.3, 0.0)
        sim.step()
    assert r2.contact and r2.contact_with == "dropped"
    assert r2.y == pytest.approx(-2.0 + 0.2 + r2.model.body_radius, abs=0.01)


def test_model_documents_settle_at_the_spawn_height() -> None:
    doc = '<sdf version="1.6">{}</sdf>'
    (held,) = sdf_model_obstacles(doc.format(BOX.format(name="b", static=STATIC, x=0, y=0, z=0)), z=1.0)
    assert (held.base, held.height) == pytest.approx((0.8, 1.2))
    (fell,) = sdf_model_obstacles(doc.format(BOX.format(name="b", static="", x=0, y=0, z=0)), z=1.0)
    assert (fell.base, fell.height) == pytest.approx((0.0, 0.4))
    # centred on its origin at z 0: Gazebo pushes it out of the ground, its whole height shows
    (popped,) = sdf_model_obstacles(doc.format(BOX.format(name="b", static="", x=0, y=0, z=0)))
    assert (popped.base, popped.height) == pytest.approx((0.0, 0.4))
    table = sdf_model_obstacles(doc.format(TABLE.format(name="t", static="", x=0, y=0, z=0.5)))
    assert len(table) == 5 and {o.model for o in table} == {"t"}
    assert min(o.base for o in table) == 0.0 and max(o.height for o in table) == pytest.approx(0.75)


# -- through the /gazebo services ------------------------------------------------------------------


@pytest.fixture
def sim() -> Iterator[SimNode]:
    with run_master() as master:
        node = Node("pieces_sim", master_uri=master)
        try:
            yield SimNode(node, NodeLog(node.name), Simulation(World("empty")), 0.0, None)
        finally:
            node.shutdown("test over")


def spawn(
    sim: SimNode, name: str, xml: str, x: float = 0.0, y: float = 0.0, z: float = 0.0, yaw: float = 0.0
):  # type: ignore[no-untyped-def]
    req = SpawnModel._request_class()
    req.model_name, req.model_xml = name, xml
    p = req.initial_pose
    p.position.x, p.position.y, p.position.z = x, y, z
    p.orientation.z, p.orientation.w = math.sin(yaw / 2), math.cos(yaw / 2)
    return sim.gazebo._spawn(req)


def test_a_model_of_several_pieces_is_spawned_moved_and_deleted_whole(sim: SimNode) -> None:
    xml = '<sdf version="1.6">' + TABLE.format(name="table", static=STATIC, x=0, y=0, z=0) + "</sdf>"
    resp = spawn(sim, "desk", xml, 3.0, 1.0, 0.0, math.pi / 2)
    assert resp.success, resp.status_message
    pieces = [o for o in sim.sim.world.obstacles if o.model_name == "desk"]
    assert sorted(o.name for o in pieces) == [
        "desk::link::leg0", "desk::link::leg1", "desk::link::leg2", "desk::link::leg3", "desk::link::top",
    ]  # fmt: skip
    assert sim.gazebo.model_names() == ["desk"]
    assert sim.gazebo.model_pose("desk") == pytest.approx((3.0, 1.0, 0.0, math.pi / 2))
    # turned by 90 degrees: the top's 1.0 m side lies along y
    (top,) = [o for o in pieces if o.name.endswith("top")]
    assert top.outline.max(axis=0) - top.outline.min(axis=0) == pytest.approx([0.8, 1.0], abs=1e-9)
    req = GetModelProperties._request_class()
    req.model_name = "desk"
    props = sim.gazebo._get_model_properties(req)
    assert props.success and props.body_names == ["link"] and props.is_static
    assert props.geom_names == ["top", "leg0", "leg1", "leg2", "leg3"]
    # set_model_state moves every piece together
    state = ModelState()
    state.model_name = "desk"
    state.pose.position.x, state.pose.position.y = -2.0, 0.0
    state.pose.orientation.w = 1.0
    assert sim.gazebo.set_model_state(state) == (True, "SetModelState: set model state done")
    moved = [o for o in sim.sim.world.obstacles if o.model_name == "desk"]
    centre = np.vstack([o.outline for o in moved]).mean(axis=0)
    assert centre == pytest.approx([-2.0, 0.0], abs=1e-9)
    (top,) = [o for o in moved if o.name.endswith("top")]
    assert top.outline.max(axis=0) - top.outline.min(axis=0) == pytest.approx([1.0, 0.8], abs=1e-9)
    # the lidar of a robot beside it sees a leg, not the top
    io = sim.add_robot("puzzlebot", load_robot_model("puzzlebot"), 0.0, 0.35, 0.0, False)
    io.robot.model.laser.noise = 0.0
    ranges = sim.sim.scan(io.robot)
    assert float(ranges[beam(180)]) == pytest.approx(2.0 - 0.45 - 0.025, abs=1e-3)
    # delete_model takes it all away
    dreq = DeleteModel._request_class()
    dreq.model_name = "desk"
    assert sim.gazebo._delete(dreq).success
    assert not [o for o in sim.sim.world.obstacles if o.model_name == "desk"]
    assert sim.gazebo.model_names() == ["puzzlebot"]


def test_spawning_several_pieces_onto_a_robot_is_refused_unless_held_above_it(sim: SimNode) -> None:
    sim.add_robot("puzzlebot", load_robot_model("puzzlebot"), 0.0, 0.0, 0.0, False)
    xml = '<sdf version="1.6">' + TABLE.format(name="table", static=STATIC, x=0, y=0, z=0) + "</sdf>"
    # the robot stands under the top, clear of the legs: Gazebo puts the table over it
    assert spawn(sim, "over", xml, 0.0, 0.0).success
    resp = spawn(sim, "onto", xml, 0.45, 0.35)  # a leg on the robot
    assert not resp.success and "would overlap robot [puzzlebot]" in resp.status_message
    assert "onto" not in sim.gazebo.model_names()
    assert not [o for o in sim.sim.world.obstacles if o.model_name == "onto"]
    # a static box spawned at 1 m is held there, over the robot; without <static> it falls on it
    box = '<sdf version="1.6">' + BOX.format(name="b", static=STATIC, x=0, y=0, z=0) + "</sdf>"
    assert spawn(sim, "lamp", box, 0.0, 0.0, 1.0).success
    assert sim.gazebo.model_pose("lamp") == pytest.approx((0.0, 0.0, 1.0, 0.0))  # held where it was put
    box_physics = '<sdf version="1.6">' + BOX.format(name="b", static="", x=0, y=0, z=0) + "</sdf>"
    assert spawn(sim, "dropped", box_physics, 2.0, 0.0, 1.0).success
    assert sim.gazebo.model_pose("dropped") == pytest.approx((2.0, 0.0, 0.2, 0.0))  # resting on the floor
    box = '<sdf version="1.6">' + BOX.format(name="b", static="", x=0, y=0, z=0) + "</sdf>"
    dreq = DeleteModel._request_class()
    dreq.model_name = "over"  # (the table top over the robot would hold it: test_drop_onto_a_table.py)
    assert sim.gazebo._delete(dreq).success
    resp = spawn(sim, "falls", box, 0.0, 0.0, 1.0)
    assert not resp.success and "would overlap robot [puzzlebot]" in resp.status_message


def test_what_a_world_cannot_find_is_left_out_as_gazebo_does(tmp_path: Path) -> None:
    """sdformat reports "Unable to find uri[...]" for a model of Gazebo's online database that is not
    installed (model://bookshelf in the course worlds) and loads the world without it; a mesh that
    is not there leaves its collision out. ``spawn_model -database`` of a missing model still fails."""
    text = (
        '<?xml version="1.0"?>\n<sdf version="1.6"><world name="w">\n'
        "<include><uri>model://bookshelf</uri><pose>3 0 0 0 0 0</pose></include>\n"
        '<model name="m"><static>1</static><link name="l"><collision name="c">\n'
        "<geometry><mesh><uri>meshes/gone.dae</uri></mesh></geometry></collision></link></model>\n"
        + BOX.format(name="kept", static=STATIC, x=2, y=0, z=0.2)
        + "</world></sdf>"
    )
    path = tmp_path / "w.world"
    path.write_text(text)
    warnings: list[str] = []
    world = load_sdf_world(path, env=NO_ENV, warn=warnings.append)
    assert [o.name for o in world.obstacles] == ["kept"]
    (msg,) = warnings
    assert "Unable to find uri[model://bookshelf]" in msg and "w.world:3" in msg
    assert "Unable to find uri[meshes/gone.dae]" in msg and "w.world:5" in msg
    with pytest.raises(Exception, match="model 'bookshelf' of model://bookshelf not found"):
        sdf_model_obstacles(
            '<sdf version="1.4"><world name="default"><include><uri>model://bookshelf</uri></include></world></sdf>',
            env=NO_ENV,
        )


def test_an_xml_declaration_out_of_place_is_read_past(tmp_path: Path) -> None:
    """A world pasted together from a saved world and a model file (the course's track worlds) has a
    second ``<?xml ...?>`` inside ``<world>``; sdformat's TinyXML reads past it, expat would not."""
    text = '\n  <?xml version="1.0" ?>\n<sdf version="1.6"><world name="w">\n  <?xml version="1.0" ?>\n'
    text += (
        BOX.format(name="b", static="", x=1, y=0, z=0)
        + "\n<model name='bad'><pose>1 2</pose></model></world></sdf>"
    )
    path = tmp_path / "w.world"
    path.write_text(text)
    # read past the declarations: the error found is the real one, on its own line
    with pytest.raises(Exception, match=r"w.world:6: <pose>: expected 6 numbers"):
        load_sdf_world(path, env=NO_ENV)
    path.write_text(text.replace("<model name='bad'><pose>1 2</pose></model>", ""))
    assert [o.name for o in load_sdf_world(path, env=NO_ENV).obstacles] == ["b"]


def test_a_robot_spawned_slightly_into_a_wall_is_placed_and_may_only_move_away() -> None:
    """Gazebo spawns a robot overlapping a wall and its physics pushes it out (a course's maze
    launch spawns the PuzzleBot 7 cm from a wall, closer than its body circle's 12.8 cm): placed,
    with the overlap noted, as long as the overlap is less than half the body radius."""
    from ninjemys.sim.simcore import SpawnError
    from ninjemys.sim.world2d import box_outline

    wall = World("w", [Obstacle("wall", "box", box_outline(0.0, -0.5, 4.0, 0.2), 0.5, (90, 90, 90))])
    sim = Simulation(wall)
    model = load_robot_model("puzzlebot")
    radius = model.body_radius
    y = -0.4 + radius - 0.04  # 4 cm into the wall's face at y = -0.4
    r = sim.add_robot("pb", model, 0.0, y, -math.pi / 2)
    assert r.spawn_overlap == ("wall", pytest.approx(0.04))
    for _ in range(50):  # towards the wall: refused, it does not go deeper
        r.command(0.2, 0.0)
        sim.step()
    assert r.y == pytest.approx(y, abs=1e-9) and r.contact_with == "wall"
    r.yaw = math.pi / 2  # turned round on the spot
    for _ in range(50):  # away from it: free
        r.command(0.2, 0.0)
        sim.step()
    assert r.y > y + 0.05
    with pytest.raises(SpawnError, match=r"inside 'wall'"):
        sim.add_robot("deep", load_robot_model("puzzlebot"), 1.0, -0.4 + radius * 0.4, 0.0)


def test_a_maze_in_one_mesh_is_its_walls_not_its_hull(tmp_path: Path) -> None:
    """The course mazes are one COLLADA or STL of joined walls; Gazebo's rays meet its triangles. Its
    convex hull would fill the maze: the walls cut near the floor are its outline instead."""
    from ninjemys.sim.meshes import write_binary_stl

    ring = np.array([(0, 0), (2, 0), (2, 0.2), (0.2, 0.2), (0.2, 2), (0, 2)], dtype=float)  # an L
    low, high = np.column_stack([ring, np.zeros(6)]), np.column_stack([ring, np.full(6, 0.3)])
    tris = [(low[0], low[i], low[i + 1]) for i in range(1, 5)]  # a fan fits this L
    tris += [(high[0], high[i + 1], high[i]) for i in range(1, 5)]
    for i in range(6):
        j = (i + 1) % 6
        tris += [(low[i], low[j], high[j]), (low[i], high[j], high[i])]
    write_binary_stl(tmp_path / "maze.stl", np.array(tris))
    text = (
        '<sdf version="1.6"><world name="w"><model name="maze"><static>1</static><link name="walls">'
        '<collision name="collision"><geometry><mesh><uri>maze.stl</uri></mesh></geometry></collision>'
        "</link></model></world></sdf>"
    )
    path = tmp_path / "w.world"
    path.write_text(text)
    world = load_sdf_world(path, env=NO_ENV)
    # each side's two triangles are cut: two segments per side
    assert {o.model_name for o in world.obstacles} == {"maze"} and len(world.obstacles) == 12
    assert all(len(o.outline) == 2 and o.height == pytest.approx(0.3) for o in world.obstacles)
    sim = Simulation(world)
    model = load_robot_model("puzzlebot")
    model.laser.noise = 0.0
    r = sim.add_robot("pb", model, 1.0, 1.0, 0.0)  # inside the L's hull, clear of its walls
    ranges = sim.scan(r).astype(np.float64)
    assert ranges[beam(-90)] == pytest.approx(0.8, abs=1e-6)  # the wall's inner face at y = 0.2
    assert ranges[beam(180)] == pytest.approx(0.8, abs=1e-6)  # and at x = 0.2
    assert math.isinf(ranges[beam(45)])


def test_a_world_models_pose_is_its_sdf_pose(tmp_path: Path) -> None:
    """/gazebo/model_states gives a world model's own pose (its frame), not the centre of its shapes."""
    text = (
        '<sdf version="1.6"><world name="w"><model name="arm"><static>1</static><pose>1 2 0 0 0 0.5</pose>'
        '<link name="l"><collision name="c"><pose>0.5 0 0.1 0 0 0</pose><geometry><box><size>0.2 0.2 0.2</size>'
        "</box></geometry></collision></link></model></world></sdf>"
    )
    path = tmp_path / "w.world"
    path.write_text(text)
    sim = Simulation(load_sdf_world(path, env=NO_ENV))
    assert sim.obstacle_pose("arm") == pytest.approx((1.0, 2.0, 0.5))
    sim.move_obstacle("arm", 0.0, 0.0, 0.0)
    (ob,) = sim.world.obstacles
    assert ob.outline.mean(axis=0) == pytest.approx([0.5, 0.0], abs=1e-9)
    assert sim.obstacle_pose("arm") == pytest.approx((0.0, 0.0, 0.0))


def test_a_collada_triangle_past_its_positions_names_the_file(tmp_path: Path) -> None:
    from ninjemys.sim.meshes import MeshError, load_mesh

    dae = (
        '<?xml version="1.0"?><COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">'
        '<library_geometries><geometry id="g"><mesh><source id="p"><float_array id="a" count="9">'
        '0 0 0 1 0 0 0 1 0</float_array></source><vertices id="v"><input semantic="POSITION" source="#p"/>'
        '</vertices><triangles count="1"><input semantic="VERTEX" source="#v" offset="0"/><p>0 1 7</p>'
        "</triangles></mesh></geometry></library_geometries></COLLADA>"
    )
    (tmp_path / "bad.dae").write_text(dae)
    with pytest.raises(MeshError, match=r"bad.dae: <triangles> index 7 is past the 3 positions"):
        load_mesh(tmp_path / "bad.dae")
    (tmp_path / "good.dae").write_text(dae.replace("0 1 7", "0 1 2"))
    (part,) = load_mesh(tmp_path / "good.dae")
    assert part.triangles.shape == (1, 3, 3) and len(part.vertices) == 3


def test_a_textured_track_plane_is_a_picture_the_camera_sees(tmp_path: Path) -> None:
    """The course's line-following tracks are a plane with an OGRE material script whose texture is a
    PNG (``model://track/materials/scripts`` + ``.../textures``): the camera sees the line on the floor."""
    import cv2

    model = tmp_path / "models" / "track"
    (model / "materials" / "scripts").mkdir(parents=True)
    (model / "materials" / "textures").mkdir(parents=True)
    (model / "materials" / "scripts" / "track.material").write_text(
        "material other\n{\n technique { pass { texture_unit { texture nothing.png } } }\n}\n"
        "material track_line\n{\n  technique\n  {\n    pass\n    {\n      texture_unit\n      {\n"
        "        texture line.png\n      }\n    }\n  }\n}\n"
    )
    image = np.full((200, 200, 3), 255, dtype=np.uint8)
    image[95:105, :] = 0  # a black line across the middle: along x, at y = 0
    image[:10, :] = (0, 0, 255)  # a red band along the +y edge (BGR): which way is up
    cv2.imwrite(str(model / "materials" / "textures" / "line.png"), image)
    text = (
        '<?xml version="1.0"?>\n<sdf version="1.6"><world name="w"><model name="track"><static>1</static>'
        '<link name="l"><visual name="v"><geometry><plane><normal>0 0 1</normal><size>4 4</size></plane>'
        "</geometry><material><script><uri>model://track/materials/scripts</uri>"
        "<uri>model://track/materials/textures</uri><name>track_line</name></script></material></visual>"
        '<collision name="c"><geometry><plane><normal>0 0 1</normal><size>4 4</size></plane></geometry>'
        "</collision></link></model></world></sdf>"
    )
    path = tmp_path / "w.world"
    path.write_text(text)
    warnings: list[str] = []
    world = load_sdf_world(
        path, env={**NO_ENV, "GAZEBO_MODEL_PATH": str(tmp_path / "models")}, warn=warnings.append
    )
    assert warnings == [] and world.obstacles == []
    (picture,) = world.floor_images
    assert picture.rgb.shape == (200, 200, 3) and (picture.width, picture.height) == (4.0, 4.0)
    sim = Simulation(world)
    floor = sim._floor
    assert floor is not None

    def floor_rgb(x: float, y: float) -> tuple[int, ...]:
        col = int((x - floor.origin_x) / floor.resolution)
        row = int((y - floor.origin_y) / floor.resolution)
        return tuple(int(v) for v in floor.palette[int(floor.texture[row, col]) - 1])

    assert floor_rgb(1.0, 0.0) == (0, 0, 0) and floor_rgb(1.0, 1.0) == (255, 255, 255)
    assert floor_rgb(0.0, 1.95) == (255, 0, 0)  # the image's top row lies at +y
    on = sim.add_robot("on", load_robot_model("puzzlebot"), -1.0, 0.0, 0.0)
    rgb, _ = sim.render(on)
    bottom = rgb[-1, on.camera.width // 2].astype(int)
    assert bottom.max() < 60  # the line ahead of the robot, under the image's centre
    off = sim.add_robot("off", load_robot_model("puzzlebot"), -1.0, 1.0, 0.0)
    rgb, _ = sim.render(off)
    assert rgb[-1, off.camera.width // 2].astype(int).min() > 150  # white floor beside it


def test_models_a_package_exports_for_gazebo_ros_are_found(tmp_path: Path) -> None:
    """The maker's puzzlebot_world exports ``<gazebo_ros gazebo_model_path="${prefix}/models"/>``:
    gazebo_ros' paths plugin adds it to the model path, so its worlds' model:// includes resolve
    with nothing but the workspace sourced."""
    pkg = tmp_path / "src" / "course_world"
    (pkg / "models" / "pillar").mkdir(parents=True)
    (pkg / "package.xml").write_text(
        '<package format="2"><name>course_world</name><version>0.0.1</version><description>d</description>'
        '<maintainer email="a@b.c">a</maintainer><license>BSD</license><exec_depend>gazebo_ros</exec_depend>'
        '<export><gazebo_ros gazebo_model_path="${prefix}/models"/>'
        '<gazebo_ros gazebo_media_path="${prefix}/models"/></export></package>'
    )
    (pkg / "models" / "pillar" / "model.sdf").write_text(
        '<sdf version="1.6">' + BOX.format(name="pillar", static=STATIC, x=0, y=0, z=0.2) + "</sdf>"
    )
    text = '<sdf version="1.6"><world name="w"><include><uri>model://pillar</uri></include></world></sdf>'
    path = tmp_path / "w.world"
    path.write_text(text)
    env = {**NO_ENV, "ROS_PACKAGE_PATH": str(tmp_path / "src")}
    (ob,) = load_sdf_world(path, env=env).obstacles
    assert ob.name == "pillar" and ob.height == pytest.approx(0.4)
    warnings: list[str] = []
    assert load_sdf_world(path, env=NO_ENV, warn=warnings.append).obstacles == []
    assert "Unable to find uri[model://pillar]" in warnings[0]
