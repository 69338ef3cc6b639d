"""rviz's RobotModel draws an OBJ mesh's parts in the colours of its ``mtllib`` (issue 23 leftovers),
as rviz draws a mesh's own materials; parts the library does not colour, and OBJs whose library
cannot be read, take the URDF visual's material."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from rviz_helpers import M, tf_message, transform

from ninjemys.master.core import MasterThread
from ninjemys.node import Node
from ninjemys.testing import wait_until
from ninjemys.web.rviz import Rviz

pytestmark = pytest.mark.browser

OBJ = """# three triangles, three materials
mtllib parts.mtl
v 0 0 0
v 0.1 0 0
v 0 0.1 0
v 0.2 0 0
v 0.3 0 0
v 0.2 0.1 0
v 0.4 0 0
v 0.5 0 0
v 0.4 0.1 0
o fin
usemtl blue_part
f 1 2 3
usemtl yellow_part
f 4 5 6
usemtl not_in_the_library
f 7 8 9
"""
MTL = """# a Wavefront material library
newmtl blue_part
Ka 0 0 0
Kd 0 0 1
d 1
newmtl yellow_part
Kd 1 1 0
Tr 0.5
"""
LOST = "mtllib missing.mtl\nv 0 0 0\nv 0.1 0 0\nv 0 0.1 0\nusemtl blue_part\nf 1 2 3\n"

COLOURS = """(suffix) => {
  const d = rviz.displays.find((d) => d.cfg.name === 'Robot');
  let found = null;
  d.group.traverse((o) => { if ((o.userData.meshUri || '').endsWith(suffix)) found = o; });
  if (!found) return null;
  const out = [];
  found.traverse((o) => {
    if (!o.isMesh) return;
    for (const m of Array.isArray(o.material) ? o.material : [o.material])
      out.push([m.color.getHexString(), Math.round(m.opacity * 100) / 100]);
  });
  return out;
}"""


@pytest.fixture
def live(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[str]:
    pkg = tmp_path / "src" / "obj_bot"
    (pkg / "meshes").mkdir(parents=True)
    (pkg / "package.xml").write_text(
        '<package format="2"><name>obj_bot</name><version>0.0.1</version><description>d</description>'
        "<maintainer email='a@b.c'>a</maintainer><license>BSD</license></package>"
    )
    (pkg / "meshes" / "fin.obj").write_text(OBJ)
    (pkg / "meshes" / "parts.mtl").write_text(MTL)
    (pkg / "meshes" / "lost.obj").write_text(LOST)
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(tmp_path / "src"))
    urdf = """<robot name="obj_bot">
  <link name="base_link"><visual><geometry><mesh filename="package://obj_bot/meshes/fin.obj"/></geometry>
    <material name="red"><color rgba="1 0 0 1"/></material></visual></link>
  <link name="lost"><visual><geometry><mesh filename="package://obj_bot/meshes/lost.obj"/></geometry>
    <material name="green"><color rgba="0 1 0 1"/></material></visual></link>
  <joint name="lost_joint" type="fixed"><parent link="base_link"/><child link="lost"/><origin xyz="1 0 0"/></joint>
</robot>"""
    config = tmp_path / "obj.rviz"
    config.write_text(
        "Visualization Manager:\n  Displays:\n    - Class: rviz/RobotModel\n      Name: Robot\n"
        "      Enabled: true\n      Robot Description: robot_description\n"
        "  Global Options:\n    Fixed Frame: map\n"
    )
    with MasterThread() as uri:
        peer = Node("rviz_obj_peer", anonymous=True, master_uri=uri)
        peer.set_param("/robot_description", urdf)
        pub = peer.publisher("/tf_static", M("tf2_msgs/TFMessage"), queue_size=1, latch=True)
        pub.publish(tf_message(transform("map", "base_link", 0.0, 0.0)))
        rviz = Rviz(uri, str(config), update_period=0.2)
        try:
            yield rviz.start()
        finally:
            rviz.stop()
            peer.shutdown("test over")


def test_obj_parts_take_their_mtl_colours_and_the_rest_the_visuals(live: str, browser_page: Any) -> None:
    page = browser_page
    page.goto(live + "?view=top&scale=100&fixed=map")
    page.wait_for_function("window.rviz && window.rviz.ready", timeout=20000)
    status = page.locator('.rv-display[data-name="Robot"] .rv-status')
    # "loading 2 meshes" first, then "2 meshes" once both are in the scene
    wait_until(
        lambda: "2 meshes" in (text := status.inner_text()) and "loading" not in text,
        what=f"mesh status ({status.inner_text()!r})",
    )
    # Kd per usemtl; d and Tr give the opacity; a name the library lacks: the URDF's red
    assert page.evaluate(COLOURS, "fin.obj") == [["0000ff", 1], ["ffff00", 0.5], ["ff0000", 1]]
    # a library that cannot be read: drawn all the same, in the visual's green
    assert page.evaluate(COLOURS, "lost.obj") == [["00ff00", 1]]
