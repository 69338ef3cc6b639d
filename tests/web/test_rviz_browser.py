"""rviz in headless chromium: each display draws what its topic carries, in the fixed frame."""

from __future__ import annotations

import math
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from rviz_helpers import M, grid, scan, screenshot_rgb, tf_message, top_view_url, transform
from web_helpers import wait_until

from ninjemys.master.core import MasterThread
from ninjemys.node import Node
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
