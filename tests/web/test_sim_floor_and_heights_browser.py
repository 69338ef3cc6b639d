"""The simulator's page draws a Gazebo world as Gazebo shows it from above (issue 23 leftovers, item 3).

A textured floor plane (a course's track) is a picture under the models; models are in their
colours (a ``Gazebo/Red`` script is red), with their heights: what is held in the air (a table top)
is drawn see-through, and the page knows each piece's base and top; a model spawned later appears,
resting where Gazebo's physics leaves it (a box dropped over the table lies on its top)."""

from __future__ import annotations

import contextlib
import math
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

from ninjemys.idl.loader import get_service_class
from ninjemys.node import Node
from ninjemys.packages.shipped import shipped_executable
from ninjemys.testing import free_port, run_master, wait_until

pytestmark = pytest.mark.browser

SpawnModel = get_service_class("gazebo_msgs/SpawnModel")


def _world(tmp_path: Path) -> Path:
    import cv2

    scripts = tmp_path / "track" / "materials" / "scripts"
    textures = tmp_path / "track" / "materials" / "textures"
    scripts.mkdir(parents=True)
    textures.mkdir(parents=True)
    (scripts / "track.material").write_text(
        "material Track/Green\n{\n technique { pass { texture_unit { texture green.png } } }\n}\n"
    )
    picture = np.zeros((64, 64, 3), dtype=np.uint8)
    picture[:, :] = (40, 200, 40)  # BGR: a green floor
    cv2.imwrite(str(textures / "green.png"), picture)
    text = f"""<?xml version="1.0"?>
<sdf version="1.6"><world name="floorworld">
  <model name="track"><static>true</static><link name="l"><visual name="v">
    <geometry><plane><normal>0 0 1</normal><size>6 6</size></plane></geometry>
    <material><script><uri>file://{scripts}</uri><name>Track/Green</name></script></material></visual>
  </link></model>
  <model name="red_box"><static>true</static><pose>-1.5 -1.5 0.25 0 0 0</pose><link name="l">
    <collision name="c"><geometry><box><size>0.6 0.6 0.5</size></box></geometry></collision>
    <visual name="v"><geometry><box><size>0.6 0.6 0.5</size></box></geometry><material><script>
      <uri>file://media/materials/scripts/gazebo.material</uri><name>Gazebo/Red</name></script></material>
    </visual></link></model>
  <model name="shelf"><static>true</static><pose>1.5 1.5 1.0 0 0 0</pose><link name="l">
    <collision name="c"><geometry><box><size>1.0 0.8 0.05</size></box></geometry></collision>
    <visual name="v"><geometry><box><size>1.0 0.8 0.05</size></box></geometry><material>
      <diffuse>0 0 1 1</diffuse></material></visual></link></model>
  <model name="wall"><static>true</static><pose>0 3.2 0.5 0 0 0</pose><link name="l">
    <collision name="c"><geometry><box><size>6 0.2 1</size></box></geometry></collision></link></model>
</world></sdf>
"""
    path = tmp_path / "floor.world"
    path.write_text(text)
    return path


@contextlib.contextmanager
def _sim(tmp_path: Path):  # type: ignore[no-untyped-def]
    with run_master() as uri:
        port = free_port()
        log_path = tmp_path / "sim.log"
        cmd = shipped_executable("puzzlebot_sim", "sim_node").command(
            ["--port", str(port), "--no-browser", f"_world:={_world(tmp_path)}", "_rate:=2.0"]
        )
        with open(log_path, "wb") as log:
            proc = subprocess.Popen(
                cmd,
                env=dict(os.environ, ROS_MASTER_URI=uri, PYTHONUNBUFFERED="1", HOME=str(tmp_path)),
                stdout=log,
                stderr=subprocess.STDOUT,
                stdin=subprocess.DEVNULL,
            )
        try:
            wait_until(lambda: b"puzzlebot_sim view:" in log_path.read_bytes(), what="view URL")
            yield f"http://localhost:{port}/", uri
        finally:
            proc.terminate()
            try:
                proc.wait(10)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()


_PIXEL = """([x, y]) => {
  const [a, b] = window.puzzlebot.px(x, y);
  const c = document.getElementById("pb-world");
  return Array.from(c.getContext("2d").getImageData(Math.round(a), Math.round(b), 1, 1).data);
}"""


def test_floor_pictures_colours_heights_and_spawned_models_in_the_page(tmp_path, browser_page) -> None:  # type: ignore[no-untyped-def]
    page = browser_page
    with _sim(tmp_path) as (url, master):
        page.goto(url + "puzzlebot")
        page.wait_for_function("window.puzzlebot && window.puzzlebot.world", timeout=20000)
        page.wait_for_function("document.body.dataset.floorPictures === '1'", timeout=20000)
        world = page.evaluate("window.puzzlebot.world")
        (floor,) = world["floor_images"]
        assert (floor["width"], floor["height"]) == (6.0, 6.0)
        obstacles = {o["name"]: o for o in world["obstacles"]}
        assert obstacles["red_box"]["color"] == [255, 0, 0]
        assert obstacles["shelf"]["color"] == [0, 0, 255]
        assert obstacles["shelf"]["base"] == pytest.approx(0.975)
        assert obstacles["shelf"]["height"] == pytest.approx(1.025)
        assert obstacles["red_box"]["base"] == 0.0
        page.evaluate("new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r)))")
        # the floor picture is drawn where nothing stands on it; the red box over it, red
        assert page.evaluate(_PIXEL, [1.5, -1.5])[:3] == [40, 200, 40]
        assert page.evaluate(_PIXEL, [-1.5, -1.5])[:3] == [255, 0, 0]
        # the shelf is held in the air: see-through, the green floor shows through the blue
        r, g, b, _ = page.evaluate(_PIXEL, [1.5, 1.5])
        assert b > 100 and g > 60 and r < 60, (r, g, b)
        # a box spawned over the shelf lands on it; the page is sent the world again
        revision = int(page.evaluate("document.body.dataset.worldRevision"))
        node = Node("floor_test", master_uri=master)
        try:
            spawn = node.service_proxy("/gazebo/spawn_sdf_model", SpawnModel)
            spawn.wait_for_service(10.0)
            req = SpawnModel._request_class()
            req.model_name = "crate"
            req.model_xml = (
                '<sdf version="1.6"><model name="crate"><link name="l"><collision name="c"><geometry><box>'
                "<size>0.3 0.3 0.3</size></box></geometry></collision><visual name='v'><geometry><box>"
                "<size>0.3 0.3 0.3</size></box></geometry><material><script><name>Gazebo/Orange</name>"
                "</script></material></visual></link></model></sdf>"
            )
            req.initial_pose.position.x, req.initial_pose.position.y, req.initial_pose.position.z = (
                1.5,
                1.5,
                2.0,
            )
            req.initial_pose.orientation.w = 1.0
            resp = spawn.call(req)
            assert resp.success, resp.status_message
        finally:
            node.shutdown("test over")
        page.wait_for_function(f"Number(document.body.dataset.worldRevision) > {revision}", timeout=20000)
        crate = next(o for o in page.evaluate("window.puzzlebot.world.obstacles") if o["name"] == "crate")
        assert crate["color"] == [255, 130, 12]
        assert (crate["base"], crate["height"]) == pytest.approx((1.025, 1.325))
        assert math.isclose(page.evaluate("window.puzzlebot.world.floor_images.length"), 1)
