"""rviz's Image display with the compressed transport: ``Transport Hint: compressed`` (and an Image
Topic ending in /compressed) subscribe to sensor_msgs/CompressedImage; the browser decodes the JPEG
and PNG and draws their pixels."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from rviz_helpers import M

from ninjemys.cv_bridge import CvBridge
from ninjemys.image_transport import CompressionParams, encode
from ninjemys.master.core import MasterThread
from ninjemys.node import Node
from ninjemys.testing import wait_until
from ninjemys.web.rviz import Rviz

pytestmark = pytest.mark.browser

CONFIG = """Visualization Manager:
  Displays:
    - Class: rviz/Image
      Name: JpegCam
      Enabled: true
      Image Topic: /cam/image_raw
      Transport Hint: compressed
    - Class: rviz/Image
      Name: PngCam
      Enabled: true
      Image Topic: /png/image_raw/compressed
  Global Options:
    Fixed Frame: map
"""


def _picture() -> np.ndarray:
    """16x8 rgb: top half red, bottom half blue (flat areas survive JPEG within a few levels)."""
    arr = np.zeros((8, 16, 3), np.uint8)
    arr[:4] = (255, 0, 0)
    arr[4:] = (0, 0, 255)
    return arr


@pytest.fixture
def live(tmp_path: Path) -> Iterator[dict[str, Any]]:
    config = tmp_path / "cams.rviz"
    config.write_text(CONFIG)
    with MasterThread() as uri:
        peer = Node("rviz_compressed_peer", anonymous=True, master_uri=uri)
        rviz = Rviz(uri, str(config), update_period=0.2)
        try:
            yield {"peer": peer, "url": rviz.start()}
        finally:
            rviz.stop()
            peer.shutdown("test over")


def test_compressed_images_are_decoded_and_drawn(live: dict[str, Any], browser_page: Any) -> None:
    peer = live["peer"]
    img = CvBridge().cv2_to_imgmsg(_picture(), "rgb8")
    keep = []
    for topic, params in (
        ("/cam/image_raw/compressed", CompressionParams("jpeg", 95)),
        ("/png/image_raw/compressed", CompressionParams("png")),
    ):
        pub = peer.publisher(topic, M("sensor_msgs/CompressedImage"), queue_size=1, latch=True)
        pub.publish(encode(img, params))
        keep.append(pub)
    page = browser_page
    page.goto(live["url"] + "?view=top")
    page.wait_for_function("window.rviz && window.rviz.ready", timeout=20000)

    def status(name: str) -> str:
        return page.locator(f'.rv-display[data-name="{name}"] .rv-status').inner_text()

    for name, text in (
        ("JpegCam", "16×8 rgb8; jpeg compressed bgr8"),
        ("PngCam", "16×8 rgb8; png compressed bgr8"),
    ):
        wait_until(lambda n=name, t=text: t in status(n), what=f"{name}: {text!r} (has {status(name)!r})")
    pixels = page.evaluate(
        "(() => Array.from(document.querySelectorAll('#rv-images canvas')).map(c => { const d = c.getContext('2d');"
        " return [Array.from(d.getImageData(2, 1, 1, 1).data), Array.from(d.getImageData(2, 6, 1, 1).data)]; }))()"
    )
    jpeg, png = pixels
    assert png == [[255, 0, 0, 255], [0, 0, 255, 255]]
    for got, want in zip(jpeg, ([255, 0, 0, 255], [0, 0, 255, 255]), strict=True):
        assert max(abs(a - b) for a, b in zip(got, want, strict=True)) <= 8, jpeg
    captions = page.locator("#rv-images figcaption").all_inner_texts()
    assert captions == ["JpegCam: /cam/image_raw/compressed", "PngCam: /png/image_raw/compressed"]
    del keep
