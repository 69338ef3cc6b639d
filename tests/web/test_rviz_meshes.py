"""rviz's RobotModel draws URDF mesh visuals (STL, DAE, OBJ) from package:// and file:// URIs."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from rviz_helpers import M, screenshot_rgb, tf_message, transform

from ninjemys.master.core import MasterThread
from ninjemys.node import Node
from ninjemys.sim.meshes import write_binary_stl
from ninjemys.testing import wait_until
from ninjemys.web.rviz import Rviz

pytestmark = pytest.mark.browser

# a Z-up COLLADA triangle pair 0.2 x 0.2 m, in centimetres
DAE = """<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><unit name="centimeter" meter="0.01"/><up_axis>Z_UP</up_axis></asset>
  <library_geometries><geometry id="sq"><mesh>
    <source id="sq-pos"><float_array id="sq-arr" count="12">-10 -10 0 10 -10 0 10 10 0 -10 10 0</float_array>
      <technique_common><accessor source="#sq-arr" count="4" stride="3">
        <param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/>
      </accessor></technique_common></source>
    <vertices id="sq-v"><input semantic="POSITION" source="#sq-pos"/></vertices>
    <triangles count="2"><input semantic="VERTEX" source="#sq-v" offset="0"/><p>0 1 2 0 2 3</p></triangles>
  </mesh></geometry></library_geometries>
  <library_visual_scenes><visual_scene id="s"><node id="n"><instance_geometry url="#sq"/></node></visual_scene>
  </library_visual_scenes>
  <scene><instance_visual_scene url="#s"/></scene>
</COLLADA>
"""

OBJ = "v 0 0 0\nv 0.1 0 0\nv 0 0.1 0.3\nf 1 2 3\n"


def box_triangles(sx: float, sy: float, sz: float) -> np.ndarray:
    c = np.array([[x, y, z] for x in (-sx, sx) for y in (-sy, sy) for z in (-sz, sz)]) / 2
    faces = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    return np.array([[c[a], c[b], c[d]] for a, b, cc, d in faces for a, b, d in ((a, b, cc), (a, cc, d))])


@pytest.fixture
def live(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[dict[str, Any]]:
    pkg = tmp_path / "src" / "mesh_bot"
    (pkg / "meshes").mkdir(parents=True)
    (pkg / "package.xml").write_text(
        '<package format="2"><name>mesh_bot</name><version>0.0.1</version><description>d</description>'
        "<maintainer email='a@b.c'>a</maintainer><license>BSD</license></package>"
    )
    write_binary_stl(pkg / "meshes" / "base.stl", box_triangles(0.6, 0.4, 0.2))
    (pkg / "meshes" / "plate.dae").write_text(DAE)
    (pkg / "meshes" / "fin.obj").write_text(OBJ)
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(tmp_path / "src"))
    urdf = f"""<robot name="mesh_bot">
  <material name="red"><color rgba="1 0 0 1"/></material>
  <link name="base_link"><visual><geometry><mesh filename="package://mesh_bot/meshes/base.stl" scale="2 1 1"/>
    </geometry><material name="red"/></visual></link>
  <link name="plate"><visual><geometry><mesh filename="package://mesh_bot/meshes/plate.dae"/></geometry></visual></link>
  <link name="fin"><visual><geometry><mesh filename="file://{pkg}/meshes/fin.obj"/></geometry>
    <material name="green"><color rgba="0 1 0 1"/></material></visual></link>
  <link name="ghost"><visual><geometry><mesh filename="package://mesh_bot/meshes/nope.stl"/></geometry></visual></link>
  <joint name="plate_joint" type="fixed"><parent link="base_link"/><child link="plate"/><origin xyz="3 0 0"/></joint>
  <joint name="fin_joint" type="fixed"><parent link="base_link"/><child link="fin"/><origin xyz="-3 0 0"/></joint>
  <joint name="ghost_joint" type="fixed"><parent link="base_link"/><child link="ghost"/></joint>
</robot>"""
    config = tmp_path / "mesh.rviz"
    config.write_text(
        "Visualization Manager:\n  Displays:\n    - Class: rviz/RobotModel\n      Name: Robot\n"
        "      Enabled: true\n      Robot Description: robot_description\n"
        "    - Class: rviz/Marker\n      Name: Mesh marker\n      Enabled: true\n      Marker Topic: /marker\n"
        "  Global Options:\n    Fixed Frame: map\n    Background Color: 48; 48; 48\n"
    )
    with MasterThread() as uri:
        peer = Node("rviz_mesh_peer", anonymous=True, master_uri=uri)
        peer.set_param("/robot_description", urdf)
        pub = peer.publisher("/tf_static", M("tf2_msgs/TFMessage"), queue_size=1, latch=True)
        pub.publish(tf_message(transform("map", "base_link", 0.0, 0.0)))
        marker = M("visualization_msgs/Marker")(ns="mesh", id=1, type=10, action=0)
        marker.header.frame_id = "map"
        marker.pose.position.y = 3.0
        marker.pose.orientation.w = 1.0
        marker.scale.x = marker.scale.y = marker.scale.z = 1.0
        marker.color.g = marker.color.a = 1.0
        marker.mesh_resource = "package://mesh_bot/meshes/base.stl"
        mpub = peer.publisher("/marker", M("visualization_msgs/Marker"), queue_size=1, latch=True)
        mpub.publish(marker)
        rviz = Rviz(uri, str(config), update_period=0.2)
        try:
            yield {"url": rviz.start(), "keep": (pub, mpub)}
        finally:
            rviz.stop()
            peer.shutdown("test over")


BOUNDS = """(uri, display = 'Robot') => {
  const d = rviz.displays.find((d) => d.cfg.name === display);
  let found = null;
  d.group.traverse((o) => { if (o.userData.meshUri === uri) found = o; });
  if (!found) return null;
  found.updateWorldMatrix(true, true);
  const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
  const colours = [];
  found.traverse((o) => {
    if (!o.isMesh) return;
    const pos = o.geometry.attributes.position, v = o.position.clone();
    for (let i = 0; i < pos.count; i++) {
      v.fromBufferAttribute(pos, i).applyMatrix4(o.matrixWorld);
      ['x', 'y', 'z'].forEach((k, j) => { lo[j] = Math.min(lo[j], v[k]); hi[j] = Math.max(hi[j], v[k]); });
    }
    colours.push(o.material.color ? o.material.color.getHexString() : null);
  });
  const r = (a) => a.map((x) => Math.round(x * 1000) / 1000);
  return { lo: r(lo), hi: r(hi), colours };
}"""


def test_robot_model_draws_stl_dae_and_obj_meshes(live: dict[str, Any], browser_page: Any) -> None:
    page = browser_page
    page.goto(live["url"] + "?view=top&scale=100&fixed=map")
    page.wait_for_function("window.rviz && window.rviz.ready", timeout=20000)
    status = page.locator('.rv-display[data-name="Robot"] .rv-status')
    wait_until(
        lambda: "meshes not drawn" in status.inner_text(), what=f"mesh status ({status.inner_text()!r})"
    )
    text = status.inner_text()
    assert "4 links from /robot_description" in text
    assert "1 of 4 meshes not drawn: package://mesh_bot/meshes/nope.stl" in text and "no such file" in text
    # the STL box 0.6 x 0.4 x 0.2, scaled 2 in x, red from the named material, at base_link (the origin)
    stl = page.evaluate(BOUNDS, "package://mesh_bot/meshes/base.stl")
    assert stl == {"lo": [-0.6, -0.2, -0.1], "hi": [0.6, 0.2, 0.1], "colours": ["ff0000"]}
    # the DAE: centimetres and Z-up applied, 3 m ahead through its joint
    dae = page.evaluate(BOUNDS, "package://mesh_bot/meshes/plate.dae")
    assert dae["lo"] == [2.9, -0.1, 0.0] and dae["hi"] == [3.1, 0.1, 0.0]
    # the OBJ by file://, green from its inline material
    fin = page.evaluate(
        "() => { let u = null; rviz.displays[0].group.traverse((o) => {"
        " if ((o.userData.meshUri || '').endsWith('fin.obj')) u = o.userData.meshUri; }); return u; }"
    )
    assert fin.startswith("file://") and page.evaluate(BOUNDS, fin) == {
        "lo": [-3.0, 0.0, 0.0],
        "hi": [-2.9, 0.1, 0.3],
        "colours": ["00ff00"],
    }
    # a MESH_RESOURCE marker draws the same file, in the marker's colour, at its pose
    wait_until(
        lambda: (
            page.evaluate(f"() => ({BOUNDS})('package://mesh_bot/meshes/base.stl', 'Mesh marker')")
            is not None
        ),
        what="the mesh marker's file",
    )
    mk = page.evaluate(f"() => ({BOUNDS})('package://mesh_bot/meshes/base.stl', 'Mesh marker')")
    assert mk == {"lo": [-0.3, 2.8, -0.1], "hi": [0.3, 3.2, 0.1], "colours": ["00ff00"]}
    # and the pixels: the top view shows the red box where base_link is, 1.2 m long and 0.4 m wide
    page.wait_for_timeout(300)
    rgb = screenshot_rgb(page).astype(int)

    def red(rgb_: list[int]) -> bool:  # lit or not, red dominates (the background is grey 48)
        r, g, b = rgb_
        return r > 90 and g < 40 and b < 40

    def pixel(x: float, y: float) -> list[int]:
        p = page.evaluate("([x, y]) => rviz.project(x, y, 0.1)", [x, y])
        return list(rgb[int(p["y"]), int(p["x"])])

    for x, y in ((0.0, 0.0), (0.5, 0.0), (-0.5, 0.1)):
        assert red(pixel(x, y)), (x, y, pixel(x, y))
    for x, y in ((0.0, 0.35), (0.75, 0.0)):
        assert not red(pixel(x, y)), (x, y, pixel(x, y))
