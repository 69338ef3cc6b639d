"""The turtlesim page in headless chromium: the turtle and its trail after a cmd_vel sequence."""

from __future__ import annotations

import os
import subprocess
import time
import urllib.request

import numpy as np
import pytest
from pngdecode import decode_png

from ninjemys.sim.render import png_bytes
from ninjemys.sim.world import CENTER, DEFAULT_BACKGROUND, DEFAULT_PEN, PIXELS_PER_METER, WORLD_SIZE
from ninjemys.testing import free_port, ninjemys_bin, run_master, wait_until

pytestmark = pytest.mark.browser


def test_png_decoder_reads_our_encoder() -> None:
    img = np.zeros((7, 5, 3), dtype=np.uint8)
    img[2, 3] = (1, 2, 3)
    assert (decode_png(png_bytes(img)) == img).all()


@pytest.fixture
def web_turtlesim(tmp_path):  # type: ignore[no-untyped-def]
    with run_master() as uri:
        port = free_port()
        log = open(tmp_path / "turtlesim.log", "wb")
        proc = subprocess.Popen(
            [ninjemys_bin("turtlesim_node"), "--port", str(port)],
            env=dict(os.environ, ROS_MASTER_URI=uri, PYTHONUNBUFFERED="1"),
            stdout=log,
            stderr=subprocess.STDOUT,
            stdin=subprocess.DEVNULL,
        )
        try:
            wait_until(
                lambda: b"turtlesim view:" in (tmp_path / "turtlesim.log").read_bytes(), what="view URL"
            )
            yield uri, f"http://localhost:{port}/"
        finally:
            proc.terminate()
            try:
                proc.wait(5)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()
            log.close()


def _near(pixel: np.ndarray, color: np.ndarray, tol: int = 16) -> bool:
    """Colour match with room for the canvas' antialiasing at stroke edges."""
    return bool((np.abs(pixel.astype(int) - color) <= tol).all())


def _pixel(x: float, y: float) -> tuple[int, int]:
    return round((WORLD_SIZE - y) * PIXELS_PER_METER), round(x * PIXELS_PER_METER)


def test_turtle_and_trail_show_in_the_page(web_turtlesim, browser_page) -> None:  # type: ignore[no-untyped-def]
    from geometry_msgs.msg import Twist
    from ninjemys.node import Node
    from turtlesim.srv import SetPen

    master, url = web_turtlesim
    page = browser_page
    page.goto(url + "turtlesim")
    page.wait_for_function("document.body.dataset.turtles === 'turtle1'", timeout=20000)
    node = Node("driver", anonymous=True, master_uri=master)
    try:
        pub = node.publisher("/turtle1/cmd_vel", Twist, queue_size=1)
        wait_until(lambda: pub.get_num_connections() > 0, what="turtlesim to subscribe")
        cmd = Twist()
        cmd.linear.x = 2.0
        pub.publish(cmd)  # 2 units to the right, then the command times out
        page.wait_for_function(
            "document.getElementById('turtle-list').textContent.includes('x=7.54')", timeout=20000
        )
        # lift the pen and drive up: that stretch must leave no trail
        node.wait_for_service("/turtle1/set_pen", timeout=10)
        node.service_proxy("/turtle1/set_pen", SetPen)(SetPen._request_class(off=1))
        cmd = Twist()
        cmd.angular.z = 1.5707963
        pub.publish(cmd)
        time.sleep(1.3)
        cmd = Twist()
        cmd.linear.x = 2.0
        pub.publish(cmd)
        page.wait_for_function(
            "document.getElementById('turtle-list').textContent.includes('y=7.54')", timeout=20000
        )
        time.sleep(0.3)  # let the last animation frame land
        box = page.locator("canvas#turtlesim").bounding_box()
        clip = {"x": round(box["x"]), "y": round(box["y"]), "width": 500, "height": 500}
        shot = decode_png(page.screenshot(clip=clip))
    finally:
        node.shutdown("test over")
    assert shot.shape[:2] == (500, 500)
    pen, bg = np.array(DEFAULT_PEN), np.array(DEFAULT_BACKGROUND)
    # trail: pen colour along y = CENTER between the start and the first stop (clear of the turtle bodies)
    for x in (CENTER + 0.6, CENTER + 1.0, CENTER + 1.4):
        assert _near(shot[_pixel(x, CENTER)], pen), f"no trail at x={x}"
    # pen off: background along the second leg
    for y in (CENTER + 0.6, CENTER + 1.0, CENTER + 1.4):
        assert _near(shot[_pixel(CENTER + 2.0, y)], bg, tol=0), f"trail with the pen off at y={y}"
    # the turtle is drawn at its final pose (not background there)
    assert not _near(shot[_pixel(CENTER + 2.0, CENTER + 2.0)], bg)
    # the server's own rendering agrees: the snapshot has the trail and no pen-off stroke
    snap = decode_png(urllib.request.urlopen(url + "api/turtlesim/snapshot.png", timeout=5).read())
    assert (snap[_pixel(CENTER + 1.0, CENTER)] == pen).all()
    assert (snap[_pixel(CENTER + 2.0, CENTER + 1.0)] == bg).all()
