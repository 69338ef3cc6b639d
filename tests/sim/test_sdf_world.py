"""Gazebo .world files (SDF) read into the simulator's world: shapes, poses, includes, meshes, errors."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from ninjemys.sim.meshes import MeshError, load_mesh_parts, write_binary_stl
from ninjemys.sim.robot_model import load_robot_model
from ninjemys.sim.sdf import GAZEBO_MATERIALS, SHIPPED_MODELS, SdfError, load_sdf_world
from ninjemys.sim.simcore import Simulation

NO_ENV = {"HOME": "/nonexistent"}  # only the shipped models on the model path

WORLD = """<?xml version="1.0"?>
<sdf version="1.6">
  <world name="course">
    <physics type="ode"><max_step_size>0.001</max_step_size></physics>
    <light type="point" name="lamp"><pose>0 0 3 0 0 0</pose></light>
    <include><uri>model://ground_plane</uri></include>
    <include><uri>model://sun</uri></include>
    <model name="red_box">
      <static>true</static>
      <pose>2 0 0.25 0 0 0</pose>
      <link name="link">
        <collision name="c"><geometry><box><size>0.5 1 0.5</size></box></geometry></collision>
        <visual name="v"><geometry><box><size>0.5 1 0.5</size></box></geometry>
          <material><script><uri>file://media/materials/scripts/gazebo.material</uri>
          <name>Gazebo/Red</name></script></material></visual>
      </link>
    </model>
    <model name="post">
      <pose>0 1.5 0.5 0 0 0</pose>
      <link name="link">
        <collision name="c"><geometry><cylinder><radius>0.3</radius><length>1</length></cylinder></geometry></collision>
        <visual name="v"><geometry><cylinder><radius>0.3</radius><length>1</length></cylinder></geometry>
          <material><ambient>0 0 1 1</ambient><diffuse>0 0.5 1 1</diffuse></material></visual>
      </link>
    </model>
    <include>
      <uri>model://unit_box</uri>
      <name>crate</name>
      <pose>-3 0 0.5 0 0 0</pose>
    </include>
    <include>
      <uri>model://construction_cone</uri>
      <pose>0 -2 0 0 0 0</pose>
    </include>
    <model name="outer">
      <pose>1 1 0 0 0 0.7853981633974483</pose>
      <model name="inner">
        <pose>1 0 0 0 0 0</pose>
        <link name="l">
          <pose>0 0 0.2 0 0 0</pose>
          <collision name="c"><geometry><box><size>0.4 0.4 0.4</size></box></geometry></collision>
        </link>
      </model>
    </model>
    <actor name="walker"><skin><filename>walk.dae</filename></skin></actor>
  </world>
</sdf>
"""


def write(tmp_path: Path, text: str, name: str = "w.world") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def beam(deg: float) -> int:
    """Index of the beam at ``deg`` for the PuzzleBot's 360 beams that start at -pi."""
    return int(round((math.radians(deg) + math.pi) / (2 * math.pi / 360))) % 360


def test_scan_ranges_of_a_world_with_boxes_cylinders_and_included_models(tmp_path):
    world = load_sdf_world(write(tmp_path, WORLD), env=NO_ENV, warn=lambda _m: None)
    assert world.name == "course"
    sim = Simulation(world)
    model = load_robot_model("puzzlebot")
    model.laser.noise = 0.0
    r = sim.add_robot("pb", model, 0.0, 0.0, 0.0)
    ranges = sim.scan(r).astype(np.float64)
    expected = {
        0: 2.0 - 0.25,  # ahead: the red box's near face
        90: 1.5 - 0.3,  # left: the post (a vertex of its 24-gon lies on this beam)
        180: 3.0 - 0.5,  # behind: the included unit_box renamed crate, moved by the include's pose
        -90: 2.0 - 0.18,  # right: the STL cone's base (a vertex of its 32-gon)
        45: math.hypot(1 + math.cos(math.pi / 4), 1 + math.sin(math.pi / 4)) - 0.2,  # nested models
    }
    for deg, dist in expected.items():
        assert ranges[beam(deg)] == pytest.approx(dist, abs=1e-4), deg
    # between the shapes the beams see nothing: the ground plane and the lights are not obstacles
    assert np.isinf(ranges[beam(135)]) and np.isinf(ranges[beam(-45)])


def test_names_colours_and_heights(tmp_path):
    world = load_sdf_world(write(tmp_path, WORLD), env=NO_ENV, warn=lambda _m: None)
    by_name = {o.name: o for o in world.obstacles}
    assert set(by_name) == {"red_box", "post", "crate", "construction_cone", "outer"}
    assert by_name["red_box"].color == GAZEBO_MATERIALS["gazebo/red"] == (255, 0, 0)
    assert by_name["post"].color == (0, 128, 255)  # diffuse wins over ambient
    assert by_name["construction_cone"].color == (255, 115, 0)
    assert by_name["red_box"].height == pytest.approx(0.5)
    assert by_name["crate"].height == pytest.approx(1.0)
    assert by_name["construction_cone"].height == pytest.approx(0.5)
    assert by_name["outer"].height == pytest.approx(0.4)
    assert by_name["construction_cone"].kind == "mesh" and by_name["post"].kind == "cylinder"


def test_unsupported_elements_are_listed_once_and_not_fatal(tmp_path):
    text = WORLD.replace(
        "<static>true</static>",
        '<static>true</static><plugin name="p" filename="libgazebo_ros_planar_move.so"/>',
    ).replace("</world>", '<actor name="second"/><road name="r"/></world>')
    warnings: list[str] = []
    load_sdf_world(write(tmp_path, text), env=NO_ENV, warn=warnings.append)
    assert len(warnings) == 1
    (msg,) = warnings
    assert "w.world" in msg and msg.count("<actor>") == 1 and "<road>" in msg
    assert "libgazebo_ros_planar_move.so" in msg
    assert "physics" not in msg and "light" not in msg  # nothing a floor plan loses


def test_the_empty_world_as_gazebo_ros_ships_it_has_no_obstacles(tmp_path):
    empty = (
        '<?xml version="1.0"?><sdf version="1.4"><world name="default">'
        "<include><uri>model://ground_plane</uri></include><include><uri>model://sun</uri></include>"
        "</world></sdf>"
    )
    warnings: list[str] = []
    world = load_sdf_world(write(tmp_path, empty), env=NO_ENV, warn=warnings.append)
    assert world.name == "default" and world.obstacles == [] and warnings == []


def test_gazebo_model_path_comes_before_the_shipped_models(tmp_path):
    models = tmp_path / "models" / "unit_box"
    models.mkdir(parents=True)
    (models / "model.sdf").write_text(
        '<sdf version="1.5"><model name="unit_box"><link name="l"><collision name="c">'
        "<geometry><sphere><radius>0.25</radius></sphere></geometry></collision></link></model></sdf>"
    )
    text = '<sdf version="1.5"><world name="w"><include><uri>model://unit_box</uri></include></world></sdf>'
    world = load_sdf_world(
        write(tmp_path, text), env={"GAZEBO_MODEL_PATH": str(tmp_path / "models")}, warn=print
    )
    (ob,) = world.obstacles
    # a sphere centred on the model's origin at z 0: Gazebo's physics pushes it up out of the ground
    assert ob.kind == "sphere" and (ob.base, ob.height) == pytest.approx((0.0, 0.5))
    assert (SHIPPED_MODELS / "unit_box" / "model.sdf").is_file()


def test_poses_compose_with_roll_and_pitch(tmp_path):
    # a cylinder lying along y (rolled a quarter turn): its footprint is a 0.4 x 2 rectangle
    text = (
        '<sdf version="1.7"><world name="w"><model name="log"><pose>2 2 0.2 1.5707963267948966 0 0</pose>'
        '<link name="l"><collision name="c"><geometry><cylinder><radius>0.2</radius><length>2</length>'
        "</cylinder></geometry></collision></link></model></world></sdf>"
    )
    (ob,) = load_sdf_world(write(tmp_path, text), env=NO_ENV).obstacles
    lo, hi = ob.outline.min(axis=0), ob.outline.max(axis=0)
    assert lo == pytest.approx([1.8, 1.0], abs=1e-9) and hi == pytest.approx([2.2, 3.0], abs=1e-9)
    assert ob.height == pytest.approx(0.4)


def test_saved_state_moves_models(tmp_path):
    text = WORLD.replace(
        "</world>",
        '<state world_name="course"><model name="red_box"><pose>5 5 0.25 0 0 0</pose></model>'
        '<model name="crate"><pose>-5 -5 0.5 0 0 0</pose></model></state></world>',
    )
    by_name = {o.name: o for o in load_sdf_world(write(tmp_path, text), env=NO_ENV, warn=print).obstacles}
    assert by_name["red_box"].outline.mean(axis=0) == pytest.approx([5, 5])
    assert by_name["crate"].outline.mean(axis=0) == pytest.approx([-5, -5])


DAE = """<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><unit name="centimeter" meter="0.01"/><up_axis>Y_UP</up_axis></asset>
  <library_geometries>
    <geometry id="block-mesh"><mesh>
      <source id="block-positions"><float_array id="block-array" count="24">
        -50 0 -25  50 0 -25  50 0 25  -50 0 25  -50 80 -25  50 80 -25  50 80 25  -50 80 25
      </float_array></source>
      <vertices id="block-vertices"><input semantic="POSITION" source="#block-positions"/></vertices>
      <triangles count="2"><input semantic="VERTEX" source="#block-vertices" offset="0"/>
        <p>0 1 2 0 2 3</p></triangles>
    </mesh></geometry>
  </library_geometries>
  <library_visual_scenes><visual_scene id="Scene">
    <node id="a"><translate>100 0 0</translate><instance_geometry url="#block-mesh"/></node>
    <node id="b"><instance_geometry url="#block-mesh"/></node>
  </visual_scene></library_visual_scenes>
  <scene><instance_visual_scene url="#Scene"/></scene>
</COLLADA>
"""


def test_meshes_dae_with_units_up_axis_nodes_and_scale(tmp_path):
    (tmp_path / "block.dae").write_text(DAE)
    text = (
        '<sdf version="1.6"><world name="w"><model name="m"><static>1</static><link name="l">'
        '<collision name="c"><geometry><mesh><uri>block.dae</uri><scale>2 1 1</scale></mesh></geometry>'
        "</collision></link></model></world></sdf>"
    )
    obs = load_sdf_world(write(tmp_path, text), env=NO_ENV).obstacles
    assert [o.name for o in obs] == ["m::l::c", "m::l::c#1"]  # two placed parts, two footprints
    a, b = obs
    # centimetres, Y up: the 100 x 80 x 50 cm block stands 0.8 m tall, 0.5 m deep; x scaled by 2
    assert a.outline.min(axis=0) == pytest.approx([1.0, -0.25]) and a.outline.max(axis=0) == pytest.approx(
        [3.0, 0.25]
    )
    assert b.outline.min(axis=0) == pytest.approx([-1.0, -0.25])
    assert a.height == pytest.approx(0.8) and b.height == pytest.approx(0.8)


def test_stl_ascii_and_binary_and_connected_parts(tmp_path):
    tri = np.array([[[0, 0, 0], [1, 0, 0], [0, 1, 1]], [[5, 5, 0], [6, 5, 0], [5, 6, 2]]], dtype=float)
    write_binary_stl(tmp_path / "b.stl", tri)
    ascii_text = "solid t\n" + "".join(
        "facet normal 0 0 1\nouter loop\n"
        + "".join(f"vertex {x} {y} {z}\n" for x, y, z in t)
        + "endloop\nendfacet\n"
        for t in tri
    )
    (tmp_path / "a.stl").write_text(ascii_text + "endsolid t\n")
    for name in ("a.stl", "b.stl"):
        parts = load_mesh_parts(tmp_path / name)
        assert len(parts) == 2  # two triangles sharing no vertex: two parts
        assert sorted(float(p[:, 2].max()) for p in parts) == [1.0, 2.0]
    (tmp_path / "bad.stl").write_text("solid t\nvertex 1 2\n")
    with pytest.raises(MeshError, match=r"bad.stl:2: vertex: expected three numbers"):
        load_mesh_parts(tmp_path / "bad.stl")


@pytest.mark.parametrize(
    ("text", "pattern"),
    [
        ('<sdf version="1.6"><world name="w"><model name="m">\n<pose>1 2 3 4</pose></model></world></sdf>',
         r"w.world:2: <pose>: expected 6 numbers \(x y z roll pitch yaw\), got '1 2 3 4'"),
        ('<sdf version="1.6"><world name="w">\n<model name="m"><link name="l"><collision name="c">'
         "<geometry><box/></geometry></collision></link></model></world></sdf>",
         r"w.world:2: <box>: missing <size>"),
        ('<sdf version="1.6"><world name="w">\n\n<model name="m"></world></sdf>',
         r"w.world:3: not well-formed XML: mismatched tag"),
        ('<sdf version="1.6"><world name="w"><model name="m"><link name="l"><collision name="c">\n'
         "<geometry><cylinder><radius>-1</radius><length>1</length></cylinder></geometry></collision>"
         "</link></model></world></sdf>",
         r"w.world:2: <radius>: expected a number > 0, got '-1'"),
        ('<robot name="r"/>', r"w.world:1: <robot>: the root element of an SDF file is <sdf>"),
        ('<sdf version="1.6"><model name="m"/></sdf>', r"w.world:1: <sdf>: no <world> in this file"),
    ],
)  # fmt: skip
def test_malformed_sdf_names_file_line_element_and_reason(tmp_path, text, pattern):
    with pytest.raises(SdfError, match=pattern):
        load_sdf_world(write(tmp_path, text), env=NO_ENV)


def test_mesh_uris_by_package_and_model(tmp_path):
    pkg = tmp_path / "src" / "course_worlds"
    (pkg / "meshes").mkdir(parents=True)
    (pkg / "package.xml").write_text(
        '<package format="2"><name>course_worlds</name><version>0.0.1</version><description>d</description>'
        "<maintainer email='a@b.c'>a</maintainer><license>BSD</license></package>"
    )
    tri = np.array([[[0, 0, 0], [1, 0, 0], [0, 1, 0.3]]], dtype=float)
    write_binary_stl(pkg / "meshes" / "t.stl", tri)
    text = (
        '<sdf version="1.6"><world name="w"><model name="m"><link name="l"><collision name="c"><geometry>'
        "<mesh><uri>package://course_worlds/meshes/t.stl</uri></mesh></geometry></collision></link></model>"
        "</world></sdf>"
    )
    env = {"ROS_PACKAGE_PATH": str(tmp_path / "src"), "HOME": "/nonexistent"}
    (ob,) = load_sdf_world(write(tmp_path, text), env=env).obstacles
    assert ob.height == pytest.approx(0.3) and len(ob.outline) == 3
    # a world whose mesh cannot be found loads without it, as Gazebo's does
    warnings: list[str] = []
    other = write(tmp_path, text.replace("course_worlds/meshes", "other"))
    assert load_sdf_world(other, env=env, warn=warnings.append).obstacles == []
    assert "Unable to find uri[package://other/t.stl]" in warnings[0]


def test_the_camera_sees_models_at_their_heights_and_colours(tmp_path):
    """A short red box before a tall green wall: red up to the box's top, the wall above it."""

    def model(name: str, x: float, size: str, z: float, colour: str) -> str:
        geometry = f"<geometry><box><size>{size}</size></box></geometry>"
        return (
            f'<model name="{name}"><static>true</static><pose>{x} 0 {z} 0 0 0</pose><link name="l">'
            f'<collision name="c">{geometry}</collision><visual name="v">{geometry}'
            f"<material><script><name>{colour}</name></script></material></visual></link></model>"
        )

    text = (
        '<sdf version="1.6"><world name="w"><include><uri>model://ground_plane</uri></include>'
        + model("crate", 1.5, "0.4 0.4 0.3", 0.15, "Gazebo/Red")
        + model("wall", 6.0, "0.2 8 2", 1.0, "Gazebo/Green")
        + "</world></sdf>"
    )
    sim = Simulation(load_sdf_world(write(tmp_path, text), env=NO_ENV))
    r = sim.add_robot("pb", load_robot_model("puzzlebot"), 0.0, 0.0, 0.0)
    rgb, depth = sim.render(r)
    cam = r.camera
    u = cam.width // 2
    cam_x = r.model.camera.pose.xyz[0]

    def row_at(z: float, d: float) -> int:  # the image row whose ray is at height z at depth d
        return int(round(cam.cy - (z - cam.cam_z) / d * cam.fy))

    near, far = 1.3 - cam_x, 5.9 - cam_x
    rows = [row_at(0.25, near), row_at(0.05, near), row_at(0.4, near), row_at(1.5, far), row_at(2.3, far)]
    assert all(0 <= v < cam.height for v in rows) and len(set(rows)) == 5
    for v in (row_at(0.25, near), row_at(0.05, near)):  # the crate (its side in the shade: 0.4 x 255)
        r_, g, b = rgb[v, u]
        assert r_ > 80 and g < 30 and b < 30 and depth[v, u] == round(near * 1000), (v, rgb[v, u])
    for v in (row_at(0.4, near), row_at(1.5, far)):  # above the crate: the wall behind it
        r_, g, b = rgb[v, u]
        assert g > 80 and r_ < 30 and b < 30 and depth[v, u] == round(far * 1000), (v, rgb[v, u])
    v = row_at(2.3, far)  # above the wall: sky, no depth
    assert depth[v, u] == 0 and tuple(rgb[v, u]) not in {(255, 0, 0), (0, 255, 0)}


def test_model_documents_as_spawn_sdf_model_receives_them():
    from ninjemys.sim.sdf import parse_sdf_world, sdf_model_obstacles

    model = (
        '<sdf version="1.6"><model name="crate"><pose>0 0 0.25 0 0 0.5</pose><link name="l">'
        '<collision name="c"><geometry><box><size>1 0.5 0.5</size></box></geometry></collision></link>'
        "</model></sdf>"
    )
    (ob,) = sdf_model_obstacles(model, env=NO_ENV)
    assert ob.name == "crate" and ob.height == pytest.approx(0.5)
    assert ob.outline.mean(axis=0) == pytest.approx([0, 0], abs=1e-9)
    # spawn_model -database NAME sends a world of one include
    include = '<sdf version="1.4"><world name="default"><include><uri>model://cardboard_box</uri></include></world></sdf>'
    (box,) = sdf_model_obstacles(include, env=NO_ENV)
    assert box.name == "cardboard_box" and box.height == pytest.approx(0.3)
    assert parse_sdf_world(include, "<text>", env=NO_ENV).obstacles[0].name == "cardboard_box"
    with pytest.raises(SdfError, match=r"<spawn_sdf_model>:1: <sdf>: no <model> in this SDF document"):
        sdf_model_obstacles('<sdf version="1.6"><light name="l"/></sdf>', env=NO_ENV)


def test_a_static_shape_is_held_at_its_height_and_not_reported(tmp_path):
    text = (
        '<sdf version="1.6"><world name="w"><model name="table"><static>1</static><link name="top">'
        '<pose>0 0 0.75 0 0 0</pose><collision name="c">\n<geometry><box><size>1 1 0.05</size></box>'
        "</geometry></collision></link></model></world></sdf>"
    )
    warnings: list[str] = []
    (ob,) = load_sdf_world(write(tmp_path, text), env=NO_ENV, warn=warnings.append).obstacles
    assert (ob.base, ob.height) == pytest.approx((0.725, 0.775))
    assert warnings == []  # simulated now (tests/sim/test_sdf_heights_and_pieces.py)
