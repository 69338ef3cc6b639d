"""rviz in headless chromium: each display draws what its topic carries, in the fixed frame."""

from __future__ import annotations

import math
import signal
import subprocess
import threading
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
import yaml
from rviz_helpers import M, grid, scan, screenshot_rgb, tf_message, top_view_url, transform

from ninjemys.idl.loader import get_message_class
from ninjemys.master.core import MasterThread
from ninjemys.node import Node
from ninjemys.testing import wait_until
from ninjemys.web.rviz import Rviz

pytestmark = pytest.mark.browser

CONFIG = """
Visualization Manager:
  Class: ""
  Displays:
    - Class: rviz/Grid
      Enabled: false
      Name: Grid
    - Class: rviz/Map
      Enabled: true
      Name: Map
      Topic: /map
      Alpha: 1
      Color Scheme: map
    - Class: rviz/LaserScan
      Enabled: true
      Name: LaserScan
      Topic: /scan
      Color: 255; 0; 0
      Size (Pixels): 5
    - Class: rviz/Camera
      Enabled: true
      Name: FrontCamera
      Image Topic: /camera/image_raw
  Global Options:
    Background Color: 48; 48; 48
    Fixed Frame: map
"""


@pytest.fixture
def graph(tmp_path: Path) -> Iterator[dict[str, Any]]:
    """A master, a peer node to publish with, and rviz (loading ``CONFIG``) on it."""
    config = tmp_path / "test.rviz"
    config.write_text(CONFIG)
    with MasterThread() as uri:
        peer = Node("rviz_test_peer", anonymous=True, master_uri=uri)
        rviz = Rviz(uri, str(config), update_period=0.2)
        try:
            url = rviz.start()
            yield {"uri": uri, "peer": peer, "rviz": rviz, "url": url, "config": config}
        finally:
            rviz.stop()
            peer.shutdown("test over")


def _open(page: Any, url: str) -> None:
    page.goto(url)
    page.wait_for_function("window.rviz && window.rviz.ready && window.rviz.ros.connected", timeout=20000)


def _status(page: Any, name: str) -> str:
    return page.locator(f'.rv-display[data-name="{name}"] .rv-status').inner_text()


def test_scan_points_land_where_the_geometry_says(graph: dict[str, Any], browser_page: Any) -> None:
    peer = graph["peer"]
    static = peer.publisher("/tf_static", M("tf2_msgs/TFMessage"), queue_size=1, latch=True)
    static.publish(tf_message(transform("map", "laser", 1.0, 0.5, math.pi / 2)))
    angles = [-0.5, 0.0, 0.5]
    pub = peer.publisher("/scan", M("sensor_msgs/LaserScan"), queue_size=1, latch=True)
    pub.publish(scan("laser", [2.0, 2.0, 2.0], angles[0], 0.5))
    page = browser_page
    _open(page, top_view_url(graph["url"], 0, 0, 50))
    wait_until(lambda: "3 points" in _status(page, "LaserScan"), what="the scan")
    page.wait_for_timeout(300)
    img = screenshot_rgb(page)
    box = page.locator("#rv-canvas").bounding_box()
    cx, cy = box["x"] + box["width"] / 2, box["y"] + box["height"] / 2
    for a in angles:
        # laser frame (2 cos a, 2 sin a), rotated 90° and moved to (1, 0.5) in map
        x, y = 1.0 - 2 * math.sin(a), 0.5 + 2 * math.cos(a)
        px, py = round(cx + x * 50), round(cy - y * 50)
        r, g, b = img[py, px]
        assert r > 200 and g < 60 and b < 60, (
            f"no red point at map ({x:.2f}, {y:.2f}) = pixel ({px}, {py}): {img[py, px]}"
        )
    # and nothing red where a beam would land without the transform
    r, g, b = img[round(cy), round(cx + 2 * 50)]
    assert not (r > 200 and g < 60), "a point drawn in the laser frame, not the fixed frame"


def test_map_occupied_cells_are_drawn(graph: dict[str, Any], browser_page: Any) -> None:
    peer = graph["peer"]
    # 10 x 10 cells of 0.2 m from (-1, -1): the left half free, the right half occupied, one unknown row
    data = []
    for row in range(10):
        for col in range(10):
            data.append(-1 if row == 9 else (100 if col >= 5 else 0))
    pub = peer.publisher("/map", M("nav_msgs/OccupancyGrid"), queue_size=1, latch=True)
    pub.publish(grid("map", 10, 10, 0.2, -1.0, -1.0, data))
    page = browser_page
    _open(page, top_view_url(graph["url"], 0, 0, 100))
    wait_until(lambda: "10×10" in _status(page, "Map"), what="the map")
    page.wait_for_timeout(300)
    img = screenshot_rgb(page)
    box = page.locator("#rv-canvas").bounding_box()
    cx, cy = box["x"] + box["width"] / 2, box["y"] + box["height"] / 2

    def at(x: float, y: float) -> Any:
        return img[round(cy - y * 100), round(cx + x * 100)]

    assert at(-0.5, 0.0).min() > 230, "free cells are white"
    assert at(0.5, 0.0).max() < 25, "occupied cells are black"
    unknown = at(0.0, 0.9)
    assert (unknown[0], unknown[1], unknown[2]) == (0x70, 0x89, 0x86), "unknown cells are rviz's grey-green"
    assert tuple(at(1.5, 0.0)) == (48, 48, 48), "outside the map is the background"


def test_rviz_file_displays_and_unsupported_ones_are_named(graph: dict[str, Any], browser_page: Any) -> None:
    page = browser_page
    _open(page, graph["url"])
    names = page.locator(".rv-display").evaluate_all("els => els.map(e => e.dataset.name)")
    assert names == ["Grid", "Map", "LaserScan"]
    assert 'rviz/Camera "FrontCamera"' in page.locator("#rv-unsupported").inner_text()
    assert page.locator('.rv-display[data-name="Grid"] .enabled').is_checked() is False
    assert page.locator('.rv-display[data-name="Map"] .topic').input_value() == "/map"


GOAL_LISTENER = """
import sys
import rospy
from geometry_msgs.msg import PoseStamped
rospy.init_node("goal_listener")
def got(msg):
    q = msg.pose.orientation
    print("GOAL", msg.header.frame_id, round(msg.pose.position.x, 2), round(msg.pose.position.y, 2),
          round(q.z, 3), round(q.w, 3), flush=True)
rospy.Subscriber("/move_base_simple/goal", PoseStamped, got)
print("READY", flush=True)
rospy.spin()
"""


@pytest.mark.ros1
def test_nav_goal_click_reaches_a_rospy_subscriber(graph: dict[str, Any], browser_page: Any) -> None:
    from ninjemys.testing import ROS1_PYTHON, have_ros1, ros1_env

    if not have_ros1():
        pytest.skip("Debian's ROS 1 is not installed")
    listener = subprocess.Popen(
        [ROS1_PYTHON, "-u", "-c", GOAL_LISTENER],
        env=ros1_env(graph["uri"]),
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
        text=True,
    )
    lines: list[str] = []

    def read() -> None:
        for line in listener.stdout:
            lines.append(line)

    reader = threading.Thread(target=read, daemon=True)
    reader.start()
    try:
        wait_until(lambda: any("READY" in x for x in lines), what="the rospy listener")
        page = browser_page
        _open(page, top_view_url(graph["url"], 0, 0, 50, fixed="odom"))
        # the tools advertise at start-up (as rviz's): wait for the graph to connect the listener
        wait_until(
            lambda: page.evaluate("rviz.ros.topics().some(t => t.name === '/move_base_simple/goal')"),
            what="the goal topic advertised",
        )
        page.wait_for_timeout(1000)
        page.get_by_role("button", name="2D Nav Goal").click()
        start = page.evaluate("rviz.project(1.5, -1.0)")
        end = page.evaluate("rviz.project(1.5, 0.0)")  # dragged towards +y: yaw 90°
        page.mouse.move(start["x"], start["y"])
        page.mouse.down()
        page.mouse.move(end["x"], end["y"], steps=4)
        page.mouse.up()
        goal = wait_until(lambda: next((x for x in lines if x.startswith("GOAL")), None), what="the goal")
        assert goal.split() == ["GOAL", "odom", "1.5", "-1.0", "0.707", "0.707"]
        # the tool is one-shot, as rviz's: the camera tool is active again
        assert "active" in page.get_by_role("button", name="Move Camera").get_attribute("class")
    finally:
        listener.send_signal(signal.SIGINT)
        try:
            listener.wait(5)
        except subprocess.TimeoutExpired:
            listener.kill()
            listener.wait()


def test_wrong_type_and_missing_transform_are_named_and_the_page_keeps_working(
    graph: dict[str, Any], browser_page: Any
) -> None:
    peer = graph["peer"]
    # /scan carries a map (the wrong type for the LaserScan display); /map is in a frame tf does not know
    bad = peer.publisher("/scan", M("nav_msgs/OccupancyGrid"), queue_size=1, latch=True)
    bad.publish(grid("map", 2, 2, 1.0, 0, 0, [0, 0, 0, 0]))
    m = peer.publisher("/map", M("nav_msgs/OccupancyGrid"), queue_size=1, latch=True)
    m.publish(grid("ghost", 2, 2, 1.0, 0, 0, [0, 100, 0, 100]))
    page = browser_page
    _open(page, graph["url"])
    wait_until(
        lambda: (
            "topic /scan is nav_msgs/OccupancyGrid, not sensor_msgs/LaserScan" in _status(page, "LaserScan")
        ),
        what="the wrong type message",
    )
    wait_until(lambda: "No transform from [ghost] to [map]" in _status(page, "Map"), what="the tf message")
    # the page keeps working: the map shows once its frame is known, and the scan display can be re-pointed
    static = peer.publisher("/tf_static", M("tf2_msgs/TFMessage"), queue_size=1, latch=True)
    static.publish(tf_message(transform("map", "ghost", 0, 0), transform("map", "laser", 0, 0)))
    wait_until(lambda: "No transform" not in _status(page, "Map"), what="the map placed")
    good = peer.publisher("/scan2", M("sensor_msgs/LaserScan"), queue_size=1, latch=True)
    good.publish(scan("laser", [1.0, 1.0], 0.0, 0.1))
    wait_until(
        lambda: page.evaluate("rviz.ros.topics().some(t => t.name === '/scan2')"), what="/scan2 listed"
    )
    topic = page.locator('.rv-display[data-name="LaserScan"] .topic')
    topic.fill("/scan2")
    topic.dispatch_event("change")
    wait_until(lambda: "2 points in [laser]" in _status(page, "LaserScan"), what="the scan on /scan2")
    assert "not sensor_msgs/LaserScan" not in _status(page, "LaserScan")


def test_a_broken_rviz_file_is_named_with_its_line(tmp_path: Path, browser_page: Any) -> None:
    config = tmp_path / "broken.rviz"
    config.write_text("Visualization Manager:\n  Displays:\n    - Class: rviz/Grid\n   Name: [oops\n")
    with MasterThread() as uri:
        rviz = Rviz(uri, str(config), update_period=0.2)
        try:
            url = rviz.start()
            page = browser_page
            _open(page, url)
            text = page.locator("#rv-messages").inner_text()
            assert f"{config}:4:" in text
            # rviz's defaults are shown instead, and they work
            assert page.locator(".rv-display").evaluate_all("els => els.map(e => e.dataset.name)") == [
                "Grid",
                "TF",
            ]
        finally:
            rviz.stop()


def test_the_edited_display_list_is_saved_in_rviz_layout(graph: dict[str, Any], browser_page: Any) -> None:
    page = browser_page
    _open(page, graph["url"])
    page.select_option("#rv-add-class", "rviz/Path")
    page.click("#rv-add")
    path = page.locator('.rv-display[data-name="Path"]')
    path.locator(".topic").fill("/move_base/GlobalPlanner/plan")
    path.locator(".topic").dispatch_event("change")
    page.locator('.rv-display[data-name="LaserScan"] .remove').click()
    page.locator('.rv-display[data-name="Grid"] .enabled').check()
    page.fill("#rv-fixed", "odom")
    page.dispatch_event("#rv-fixed", "change")
    page.click("#rv-save")
    wait_until(lambda: "saved to" in page.locator("#rv-saved").inner_text(), what="the save")
    doc = yaml.safe_load(graph["config"].read_text())
    manager = doc["Visualization Manager"]
    assert manager["Global Options"]["Fixed Frame"] == "odom"
    by_name = {d["Name"]: d for d in manager["Displays"]}
    assert set(by_name) == {"Grid", "Map", "Path", "FrontCamera"}  # the camera display is kept as it was
    assert (
        by_name["Path"]["Class"] == "rviz/Path"
        and by_name["Path"]["Topic"] == "/move_base/GlobalPlanner/plan"
    )
    assert by_name["Grid"]["Enabled"] is True
    assert by_name["Map"]["Color Scheme"] == "map" and by_name["Map"]["Topic"] == "/map"
    assert by_name["FrontCamera"]["Image Topic"] == "/camera/image_raw"


def test_pose_estimate_and_publish_point_tools(graph: dict[str, Any], browser_page: Any) -> None:
    peer = graph["peer"]
    got: dict[str, Any] = {}
    peer.subscriber(
        "/initialpose",
        M("geometry_msgs/PoseWithCovarianceStamped"),
        lambda m: got.setdefault("pose", m),
        queue_size=1,
    )
    peer.subscriber(
        "/clicked_point", M("geometry_msgs/PointStamped"), lambda m: got.setdefault("point", m), queue_size=1
    )
    page = browser_page
    errors: list[str] = []
    page.on("pageerror", lambda exc: errors.append(str(exc)))
    _open(page, top_view_url(graph["url"], 0, 0, 50))
    wait_until(
        lambda: page.evaluate(
            "['/initialpose', '/clicked_point'].every(n => rviz.ros.topics().some(t => t.name === n))"
        ),
        what="the tools advertised",
    )
    page.wait_for_timeout(1000)
    page.get_by_role("button", name="2D Pose Estimate").click()
    a, b = page.evaluate("rviz.project(-1, 2)"), page.evaluate("rviz.project(-2, 2)")  # heading -x: yaw 180°
    page.mouse.move(a["x"], a["y"])
    page.mouse.down()
    page.mouse.move(b["x"], b["y"], steps=3)
    page.mouse.up()
    page.get_by_role("button", name="Publish Point").click()
    c = page.evaluate("rviz.project(0.5, -0.5)")
    page.mouse.click(c["x"], c["y"])
    wait_until(lambda: "pose" in got and "point" in got, what="both tools' messages")
    pose, point = got["pose"], got["point"]
    assert pose.header.frame_id == "map"
    assert (round(pose.pose.pose.position.x, 2), round(pose.pose.pose.position.y, 2)) == (-1.0, 2.0)
    assert abs(abs(pose.pose.pose.orientation.z) - 1.0) < 1e-3
    assert pose.pose.covariance[0] == 0.25 and pose.pose.covariance[7] == 0.25
    assert abs(pose.pose.covariance[35] - (math.pi / 12) ** 2) < 1e-9
    assert point.header.frame_id == "map"
    assert (round(point.point.x, 2), round(point.point.y, 2), point.point.z) == (0.5, -0.5, 0.0)
    # the 3D view draws the same scene: switching views raises nothing
    page.select_option("#rv-viewmode", "orbit")
    page.wait_for_timeout(300)
    page.select_option("#rv-viewmode", "top")
    page.wait_for_timeout(300)
    assert errors == []


def test_a_game_controller_in_rviz_publishes_joy(graph: dict[str, Any], browser_page: Any) -> None:
    page = browser_page
    page.add_init_script(
        "(() => { const pad = { id: 'Fake Pad', index: 0, connected: true, mapping: 'standard',"
        " axes: [0, -1, 0, 0], buttons: Array.from({ length: 4 }, (_, i) => ({ pressed: i === 1, value: i === 1 ? 1 : 0 })),"
        " timestamp: 0 }; navigator.getGamepads = () => [pad]; })();"
    )
    joys: list[Any] = []
    graph["peer"].subscriber("/joy", get_message_class("sensor_msgs/Joy"), joys.append)
    _open(page, graph["url"])
    page.wait_for_function("document.body.dataset.gamepad === 'Fake Pad'", timeout=10000)
    msg = wait_until(lambda: next((m for m in list(joys) if len(m.axes) == 4), None), what="a Joy from rviz")
    assert list(msg.buttons) == [0, 1, 0, 0] and msg.axes[1] == pytest.approx(1.0)  # up is +1, as joy_node
    assert msg.header.frame_id == "browser_gamepad"
