"""The PuzzleBot simulator's page in headless chromium: world, robot, lidar, cameras, keyboard teleop.

The page's one data path is the gateway on its server: the view's JSON channel, the camera topics,
cmd_vel publications and the /gazebo/* services. What the page holds is read back from the page."""

from __future__ import annotations

import contextlib
import os
import subprocess

import pytest
from pngdecode import decode_png
from web_helpers import wait_until

from ninjemys.idl.loader import get_message_class
from ninjemys.node import Node
from ninjemys.packages.shipped import shipped_executable
from ninjemys.testing import free_port, run_master

pytestmark = pytest.mark.browser


@pytest.fixture
def web_sim(tmp_path):  # type: ignore[no-untyped-def]
    with _sim(tmp_path) as (url, _uri):
        yield url


@contextlib.contextmanager
def _sim(tmp_path):  # type: ignore[no-untyped-def]
    """The simulator with its view on a free port: (the page's base URL, the master's URI)."""
    with run_master() as uri:
        port = free_port()
        log_path = tmp_path / "sim.log"
        cmd = shipped_executable("puzzlebot_sim", "sim_node").command(
            ["--port", str(port), "--no-browser", "_world:=square", "_rate:=2.0"]
        )
        with open(log_path, "wb") as log:
            proc = subprocess.Popen(
                cmd,
                env=dict(os.environ, ROS_MASTER_URI=uri, PYTHONUNBUFFERED="1"),
                stdout=log,
                stderr=subprocess.STDOUT,
                stdin=subprocess.DEVNULL,
            )
        try:
            wait_until(lambda: b"puzzlebot_sim view:" in log_path.read_bytes(), what="view URL")
            assert f"puzzlebot_sim view: http://localhost:{port}/puzzlebot" in log_path.read_text()
            yield f"http://localhost:{port}/", uri
        finally:
            proc.terminate()
            try:
                proc.wait(10)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()


def _robot(page) -> dict:  # type: ignore[no-untyped-def]
    """The first robot as the page last heard of it (through the gateway)."""
    return page.evaluate("window.puzzlebot.update.robots[0]")


def test_page_shows_the_world_and_drives_the_robot(web_sim, browser_page) -> None:  # type: ignore[no-untyped-def]
    url = web_sim
    page = browser_page
    page.goto(url + "puzzlebot")
    page.wait_for_function("document.body.dataset.robots === 'puzzlebot'", timeout=20000)
    page.wait_for_function("(document.body.dataset.scanRobots || '').includes('puzzlebot')", timeout=20000)
    # the camera images arrive while the page shows them
    page.wait_for_function(
        "Number(document.getElementById('pb-color').dataset.loaded || 0) >= 1", timeout=20000
    )
    page.wait_for_function(
        "Number(document.getElementById('pb-depth').dataset.loaded || 0) >= 1", timeout=20000
    )
    # the colour image the page drew from the camera topic is a real render: floor at the bottom,
    # something else above (looked at before driving: a robot that drove on under load may face a wall)
    width, height, top, bottom = page.evaluate(
        """(() => {
          const c = document.getElementById("pb-color"), g = c.getContext("2d");
          const px = (y) => Array.from(g.getImageData(2, y, 1, 1).data);
          return [c.width, c.height, px(2), px(c.height - 3)];
        })()"""
    )
    assert (width, height) == (320, 240) and top != bottom and top[3] == 255
    start = _robot(page)
    assert start["x"] == 0.0 and start["scan"] is not None
    # drive forward with the keyboard for a moment
    page.locator("canvas#pb-world").click()
    page.keyboard.down("ArrowUp")
    page.wait_for_function("document.body.dataset.lastCommand === '0.3,0'", timeout=10000)
    wait_until(lambda: _robot(page)["x"] > 0.15, what="the robot moving forward")
    page.keyboard.up("ArrowUp")
    page.wait_for_function("document.body.dataset.lastCommand === '0,0'", timeout=10000)
    assert page.evaluate("window.puzzlebot.trails.get('puzzlebot').length") > 1, "the robot leaves a trail"
    # the top-down canvas shows the room's walls (drawn white-ish) and the yellow 1 m square
    box = page.locator("canvas#pb-world").bounding_box()
    shot = decode_png(
        page.screenshot(clip={"x": box["x"], "y": box["y"], "width": box["width"], "height": box["height"]})
    )
    yellow = (shot[:, :, 0] > 200) & (shot[:, :, 1] > 170) & (shot[:, :, 2] < 90)
    assert yellow.sum() > 50
    # page buttons reach the Gazebo-style controls
    page.get_by_role("button", name="reset world").click()
    wait_until(lambda: _robot(page)["x"] == 0.0, what="reset world from the page")


_FAKE_GAMEPAD = """
(() => {
  const pad = { id: "Fake Xbox Controller (STANDARD GAMEPAD)", index: 0, connected: true, mapping: "standard",
                axes: [0, 0, 0, 0], buttons: Array.from({ length: 17 }, () => ({ pressed: false, value: 0 })),
                timestamp: 0 };
  window.fakePad = pad;
  navigator.getGamepads = () => [pad, null, null, null];
})();
"""


def test_a_game_controller_in_the_page_publishes_joy_and_drives_through_teleop_twist_joy(
    tmp_path, browser_page
) -> None:  # type: ignore[no-untyped-def]
    page = browser_page
    page.add_init_script(_FAKE_GAMEPAD)
    with _sim(tmp_path) as (url, master):
        page.goto(url + "puzzlebot")
        page.wait_for_function("document.body.dataset.robots === 'puzzlebot'", timeout=20000)
        page.wait_for_function("(document.body.dataset.gamepad || '').startsWith('Fake Xbox')", timeout=10000)
        joys: list = []
        node = Node("gamepad_test", master_uri=master)
        node.subscriber("/joy", get_message_class("sensor_msgs/Joy"), joys.append)
        teleop = subprocess.Popen(
            shipped_executable("teleop_twist_joy", "teleop_node").command(
                ["_enable_button:=0", "_scale_linear:=0.3"]
            ),
            env=dict(os.environ, ROS_MASTER_URI=master),
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        try:
            # the stick pushed up (the browser says -1, joy_node's convention +1), the enable button held
            page.evaluate("fakePad.axes[1] = -1; fakePad.buttons[0] = { pressed: true, value: 1 }")
            wait_until(lambda: any(m.buttons[0] == 1 and m.axes[1] > 0.99 for m in list(joys)), what="a Joy")
            sample = next(m for m in list(joys) if m.axes[1] > 0.99)
            assert sample.header.frame_id == "browser_gamepad" and len(sample.buttons) == 17
            wait_until(lambda: _robot(page)["x"] > 0.1, timeout=30, what="the robot driven by the controller")
            page.evaluate("fakePad.axes[1] = 0; fakePad.buttons[0] = { pressed: false, value: 0 }")
            wait_until(lambda: joys[-1].axes[1] == 0 and joys[-1].buttons[0] == 0, what="the released state")
        finally:
            teleop.terminate()
            teleop.wait(10)
            node.shutdown()
