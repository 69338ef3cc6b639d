"""Gazebo material scripts become colours (issue 23 leftovers, item 2).

``<material><script><uri>file://media/materials/scripts/gazebo.material</uri><name>Gazebo/Red</name>``
is red without Gazebo installed (our table of its stock names); a material of one's own is read from
the ``.material`` file its ``<uri>`` names (``file://``, ``model://``, a folder of scripts): its
diffuse colour, else its ambient, else its texture's mean colour. A name found nowhere is drawn grey
and named once in the world's warning; nothing fails."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from ninjemys.sim.description.build import model_from_description
from ninjemys.sim.gazebo_materials import script_colour, stock_colour
from ninjemys.sim.sdf import DEFAULT_COLOUR, parse_sdf_world

STOCK_URI = "file://media/materials/scripts/gazebo.material"


def _box(name: str, x: float, material: str) -> str:
    return (
        f'<model name="{name}"><static>true</static><pose>{x} 0 0 0 0 0</pose><link name="l">'
        '<collision name="c"><pose>0 0 0.2 0 0 0</pose><geometry><box><size>0.4 0.4 0.4</size></box>'
        f'</geometry></collision><visual name="v"><geometry><box><size>0.4 0.4 0.4</size></box></geometry>'
        f"<material>{material}</material></visual></link></model>"
    )


def _script(uris: list[str], name: str) -> str:
    return "<script>" + "".join(f"<uri>{u}</uri>" for u in uris) + f"<name>{name}</name></script>"


def test_stock_names_need_no_gazebo_installed() -> None:
    assert stock_colour("Gazebo/Red") == (255, 0, 0)
    assert stock_colour("Gazebo/BlueGlow") == stock_colour("gazebo/blue") == (0, 0, 255)
    assert stock_colour("Gazebo/GreyTransparent") == stock_colour("Gazebo/Grey")
    assert stock_colour("Gazebo/Orange") == (255, 130, 12)
    assert stock_colour("Custom/Thing") is None


def test_world_materials_from_stock_names_own_scripts_and_textures(tmp_path: Path) -> None:
    import cv2

    model = tmp_path / "models" / "painted"
    (model / "materials" / "scripts").mkdir(parents=True)
    (model / "materials" / "textures").mkdir(parents=True)
    (model / "materials" / "scripts" / "painted.material").write_text(
        "material Painted/Teal\n{\n  technique\n  {\n    pass\n    {\n      ambient 0.1 0.1 0.1 1\n"
        "      diffuse 0.0 0.5 0.5 1.0\n    }\n  }\n}\n"
        "material Painted/AmbientOnly : Painted/Teal\n{ technique { pass { ambient 1 0.5 0 1 } } }\n"
        "material Painted/Checker\n{\n  technique\n  {\n    pass\n    {\n      texture_unit\n      {\n"
        "        texture checker.png\n      }\n    }\n  }\n}\n"
    )
    checker = np.zeros((8, 8, 3), dtype=np.uint8)
    checker[:, :4] = (0, 0, 200)  # BGR: half red (200, 0, 0), half black
    cv2.imwrite(str(model / "materials" / "textures" / "checker.png"), checker)
    own = tmp_path / "own.material"
    own.write_text("material Own/Purple\n{\n technique { pass { diffuse 0.5 0 0.5 } }\n}\n")
    scripts = "model://painted/materials/scripts"
    text = (
        '<sdf version="1.6"><world name="w">'
        + _box("red", 0, _script([STOCK_URI], "Gazebo/Red"))
        + _box("glow", 1, _script([STOCK_URI], "Gazebo/GreenGlow"))
        + _box("teal", 2, _script([scripts, "model://painted/materials/textures"], "Painted/Teal"))
        + _box("amber", 3, _script([scripts], "Painted/AmbientOnly"))
        + _box("checker", 4, _script([scripts], "Painted/Checker"))
        + _box("purple", 5, _script([f"file://{own}"], "Own/Purple"))
        + _box("mystery", 6, _script([STOCK_URI], "Nowhere/ToBeFound"))
        + _box("mystery2", 7, _script([STOCK_URI], "Nowhere/ToBeFound"))
        + "</world></sdf>"
    )
    warnings: list[str] = []
    env = {"HOME": "/nonexistent", "GAZEBO_MODEL_PATH": str(tmp_path / "models")}
    world = parse_sdf_world(text, str(tmp_path / "w.world"), env, warnings.append)
    colour = {o.name: o.color for o in world.obstacles}
    assert colour["red"] == (255, 0, 0)
    assert colour["glow"] == (0, 255, 0)
    assert colour["teal"] == (0, 128, 128)  # diffuse wins over ambient
    assert colour["amber"] == (255, 128, 0)  # ambient when there is no diffuse
    assert colour["checker"] == (100, 0, 0)  # the texture's mean colour
    assert colour["purple"] == (128, 0, 128)  # file:///absolute/path.material
    assert colour["mystery"] == colour["mystery2"] == DEFAULT_COLOUR  # grey, not fatal
    (warning,) = warnings
    assert warning.count("Nowhere/ToBeFound") == 1 and "drawn grey" in warning


def test_file_media_uris_are_read_from_gazebo_resource_path(tmp_path: Path) -> None:
    """With Gazebo's resources present (GAZEBO_RESOURCE_PATH), a non-stock name in its scripts is read there."""
    scripts = tmp_path / "gz" / "media" / "materials" / "scripts"
    scripts.mkdir(parents=True)
    (scripts / "gazebo.material").write_text(
        "material Gazebo/Mauve\n{ technique { pass { diffuse 0.8 0.4 0.6 } } }\n"
    )
    assert script_colour(scripts / "gazebo.material", "Gazebo/Mauve") == (204, 102, 153)
    text = (
        '<sdf version="1.6"><world name="w">'
        + _box("m", 0, _script([STOCK_URI], "Gazebo/Mauve"))
        + "</world></sdf>"
    )
    env = {"HOME": "/nonexistent", "GAZEBO_RESOURCE_PATH": str(tmp_path / "gz")}
    (box,) = parse_sdf_world(text, str(tmp_path / "w.world"), env).obstacles
    assert box.color == (204, 102, 153)


URDF = """<robot name="r">
  <link name="base_link"><collision><origin xyz="0 0 0.05"/><geometry><box size="0.2 0.16 0.06"/></geometry>
  </collision><visual><geometry><box size="0.2 0.16 0.06"/></geometry><material name="m"><color rgba="0 1 0 1"/>
  </material></visual></link>
  <link name="wl"><collision><geometry><cylinder radius="0.05" length="0.02"/></geometry></collision></link>
  <link name="wr"><collision><geometry><cylinder radius="0.05" length="0.02"/></geometry></collision></link>
  <joint name="jl" type="continuous"><parent link="base_link"/><child link="wl"/><origin xyz="0 0.09 0.05"/></joint>
  <joint name="jr" type="continuous"><parent link="base_link"/><child link="wr"/><origin xyz="0 -0.09 0.05"/></joint>
  <gazebo reference="base_link"><material>{material}</material></gazebo>
  <gazebo><plugin name="dd" filename="libgazebo_ros_diff_drive.so"><leftJoint>jl</leftJoint>
  <rightJoint>jr</rightJoint></plugin></gazebo>
</robot>"""


@pytest.mark.parametrize(
    ("material", "colour", "warned"),
    [
        ("Gazebo/Orange", (255, 130, 12), False),
        ("Gazebo/RedGlow", (255, 0, 0), False),
        ("My/Paint", (0, 255, 0), True),
    ],
)
def test_a_robots_gazebo_material_is_its_colour_or_named_once(
    material: str, colour: tuple, warned: bool
) -> None:
    m = model_from_description(URDF.format(material=material), "r.urdf")
    assert m.color == colour
    named = [w for w in m.warnings if material in w]
    assert len(named) == (1 if warned else 0)
    if warned:
        assert "r.urdf:" in named[0] and "keeps its URDF colour" in named[0]


def test_a_relative_file_uri_of_a_mesh_is_looked_for_on_the_resource_path_then_beside_the_world(
    tmp_path: Path,
) -> None:
    stl = (
        "solid s\n"
        + "".join(
            f"facet normal 0 0 1\nouter loop\nvertex {a}\nvertex {b}\nvertex {c}\nendloop\nendfacet\n"
            for a, b, c in (("0 0 0", "1 0 0", "0 1 0.5"), ("1 0 0", "1 1 0.5", "0 1 0.5"))
        )
        + "endsolid s\n"
    )
    (tmp_path / "gz" / "media" / "meshes").mkdir(parents=True)
    (tmp_path / "gz" / "media" / "meshes" / "ramp.stl").write_text(stl)
    (tmp_path / "world" / "media" / "meshes").mkdir(parents=True)
    (tmp_path / "world" / "media" / "meshes" / "beside.stl").write_text(stl)

    def world(uri: str) -> str:
        return (
            '<sdf version="1.6"><world name="w"><model name="m"><static>1</static><link name="l">'
            f'<collision name="c"><geometry><mesh><uri>{uri}</uri></mesh></geometry></collision>'
            "</link></model></world></sdf>"
        )

    env = {"HOME": "/nonexistent", "GAZEBO_RESOURCE_PATH": str(tmp_path / "gz")}
    source = str(tmp_path / "world" / "w.world")
    (ramp,) = parse_sdf_world(world("file://media/meshes/ramp.stl"), source, env).obstacles
    (beside,) = parse_sdf_world(world("file://media/meshes/beside.stl"), source, env).obstacles
    for ob in (ramp, beside):
        assert ob.height == pytest.approx(0.5)
        assert ob.outline.max(axis=0) == pytest.approx([1.0, 1.0])


def test_media_a_package_exports_for_gazebo_ros_is_searched(tmp_path: Path) -> None:
    """The maker's puzzlebot_gazebo exports ``gazebo_media_path="${prefix}/models"``; its floor (an
    8 m wooden plane with a logo) and goal markers name ``file://media/materials/scripts/
    mcr2_materials.material``, found there as gazebo_ros' paths plugin finds it."""
    import cv2

    pkg = tmp_path / "src" / "course_gazebo"
    media = pkg / "models" / "media" / "materials"
    (media / "scripts").mkdir(parents=True)
    (media / "textures").mkdir(parents=True)
    (pkg / "package.xml").write_text(
        '<package format="2"><name>course_gazebo</name><version>0.0.1</version><description>d</description>'
        '<maintainer email="a@b.c">m</maintainer><license>BSD</license>'
        '<export><gazebo_ros gazebo_media_path="${prefix}/models"/></export></package>'
    )
    (media / "scripts" / "course.material").write_text(
        "material course/wood\n{\n technique { pass { texture_unit { texture wood.png } } }\n}\n"
    )
    wood = np.zeros((16, 16, 3), dtype=np.uint8)
    wood[:, :] = (30, 90, 160)  # BGR
    cv2.imwrite(str(media / "textures" / "wood.png"), wood)
    text = (
        '<sdf version="1.6"><world name="w"><model name="floor"><static>1</static><link name="l">'
        '<visual name="v"><geometry><plane><normal>0 0 1</normal><size>8 8</size></plane></geometry>'
        "<material>"
        + _script(["file://media/materials/scripts/course.material"], "course/wood")
        + "</material>"
        "</visual></link></model></world></sdf>"
    )
    warnings: list[str] = []
    env = {"HOME": "/nonexistent", "ROS_PACKAGE_PATH": str(tmp_path / "src")}
    world = parse_sdf_world(text, str(tmp_path / "w.world"), env, warnings.append)
    (floor,) = world.floor_images
    assert (floor.width, floor.height) == (8.0, 8.0)
    assert floor.rgb[0, 0].tolist() == [160, 90, 30]
    assert warnings == []
    assert world.bare_models == ["floor"]  # a plane: a model with nothing solid


def test_an_ambient_beside_a_stock_picture_tints_it_and_replaces_a_plain_colour(tmp_path: Path) -> None:
    """The Building Editor saves its walls as ``Gazebo/Bricks`` with ``<ambient>1 1 1 1</ambient>``
    and Gazebo shows bricks (a course world's house: white walls would be taken for the white ball a
    ball chaser looks for); beside a plain colour, the ambient is the colour."""

    def wall(name: str, script: str, extra: str) -> str:
        return (
            f'<model name="{name}"><static>1</static><link name="l"><visual name="v"><geometry><box>'
            "<size>1 0.1 1</size></box></geometry><material><script>"
            f"<uri>file://media/materials/scripts/gazebo.material</uri><name>{script}</name></script>{extra}"
            '</material></visual><collision name="c"><geometry><box><size>1 0.1 1</size></box></geometry>'
            "</collision></link></model>"
        )

    text = (
        '<sdf version="1.6"><world name="w">'
        + wall("bricks", "Gazebo/Bricks", "<ambient>1 1 1 1</ambient>")
        + wall("dim_wood", "Gazebo/Wood", "<diffuse>0.5 0.5 0.5 1</diffuse>")
        + wall("grey", "Gazebo/Grey", "<ambient>0.2 0.4 0.6 1</ambient>")
        + "</world></sdf>"
    )
    colours = {o.name: o.color for o in parse_sdf_world(text, str(tmp_path / "w.world"), {}).obstacles}
    assert colours["bricks"] == stock_colour("Gazebo/Bricks")
    wood = stock_colour("Gazebo/Wood")
    assert wood is not None and colours["dim_wood"] == tuple(round(c * 0.5) for c in wood)
    assert colours["grey"] == (51, 102, 153)
