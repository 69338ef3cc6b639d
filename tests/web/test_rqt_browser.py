"""The rqt family in headless chromium: each tool shows what its topic carries, on real nodes."""

from __future__ import annotations

import math
import subprocess
import threading
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest

from ninjemys.actionlib.simple_server import SimpleActionServer
from ninjemys.bag.api import Bag
from ninjemys.dynamic_reconfigure.generator import render_module, run_cfg
from ninjemys.dynamic_reconfigure.server import ReconfigureServer
from ninjemys.idl.loader import get_message_class
from ninjemys.idl.loader import get_service_class as get_message_class_srv
from ninjemys.master.core import MasterThread
from ninjemys.node import Node
from ninjemys.rostime import Time
from ninjemys.testing import ROS1_PYTHON, ros1_env, wait_until
from ninjemys.tools.rosout import Rosout
from ninjemys.web.rqt import Rqt, tool_url

pytestmark = pytest.mark.browser

M = get_message_class


class Graph:
    """A master, a peer node to publish with, and rqt apps started on demand (stopped at the end)."""

    def __init__(self, uri: str) -> None:
        self.uri = uri
        self.peer = Node("rqt_test_peer", anonymous=True, master_uri=uri)
        self.apps: list[Rqt] = []
        self._stop = threading.Event()
        self._threads: list[threading.Thread] = []

    def rqt(self, bags: list[str] | None = None) -> str:
        app = Rqt(self.uri, bags=bags, update_period=0.2)
        self.apps.append(app)
        return app.start()

    def every(self, period: float, fn: Callable[[int], None]) -> None:
        """Call ``fn(k)`` every ``period`` seconds until the test ends."""

        def loop() -> None:
            k = 0
            while not self._stop.wait(period):
                fn(k)
                k += 1

        t = threading.Thread(target=loop, daemon=True)
        t.start()
        self._threads.append(t)

    def close(self) -> None:
        self._stop.set()
        for t in self._threads:
            t.join(2.0)
        for app in self.apps:
            app.stop()
        self.peer.shutdown("test over")


@pytest.fixture
def graph() -> Iterator[Graph]:
    with MasterThread() as uri:
        g = Graph(uri)
        try:
            yield g
        finally:
            g.close()


def _open(page: Any, url: str) -> None:
    page.goto(url)
    page.wait_for_function("window.rqt && window.rqt.ready && window.rqt.ros.connected", timeout=20000)


def test_plot_follows_a_published_sine_and_names_a_non_numeric_field(graph: Graph, browser_page: Any) -> None:
    pub = graph.peer.publisher("/wave", M("geometry_msgs/PointStamped"), queue_size=10)

    def publish(k: int) -> None:
        msg = M("geometry_msgs/PointStamped")()
        msg.header.stamp = Time(1000 + k // 50, (k % 50) * 20_000_000)
        msg.header.frame_id = "sine"
        msg.point.x = k * 0.1
        msg.point.y = math.sin(k * 0.1)
        pub.publish(msg)

    graph.every(0.02, publish)
    base = graph.rqt()
    url = tool_url(base, "plot", [("topic", "/wave/point/x"), ("topic", "/wave/point/y")])
    page = browser_page
    _open(page, url)
    data = wait_until(
        lambda: (
            (d := page.evaluate("window.rqt.tools.plot.data()"))
            and len(d["/wave/point/y"]) >= 60
            and len(d["/wave/point/x"]) >= 60
            and d
        ),
        what="60 samples of each series",
    )
    xs = dict(map(tuple, data["/wave/point/x"]))
    pairs = [(xs[t], y) for t, y in data["/wave/point/y"] if t in xs]
    assert len(pairs) >= 60
    for x, y in pairs:
        assert y == pytest.approx(math.sin(x), abs=1e-9)
    assert min(y for _, y in pairs) < -0.9 and max(y for _, y in pairs) > 0.9
    # the chart drew something: the plot canvas is not blank
    assert (
        page.evaluate(
            """() => { const c = document.querySelector('#pane-plot canvas');
        const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
        let n = 0; for (let i = 3; i < d.length; i += 4) if (d[i]) n++; return n; }"""
        )
        > 100
    )

    # the topic monitor: rate and last value of the same topic
    page.click('#rqt-tabs button[data-tool="topic"]')
    page.check('.topic-table tr[data-topic="/wave"] input[type=checkbox]')
    wait_until(
        lambda: float(page.inner_text('.topic-table tr[data-topic="/wave"] .hz') or 0) > 10,
        what="/wave's rate",
    )
    assert '"frame_id": "sine"' in page.inner_text(".topic-value")
    assert "B/s" in page.inner_text('.topic-table tr[data-topic="/wave"] .bw')
    page.click('#rqt-tabs button[data-tool="plot"]')

    # a string field: one line in the page, and the other series keep coming
    page.fill(".plot-input", "/wave/header/frame_id")
    page.press(".plot-input", "Enter")
    page.wait_for_selector('.plot-series-row[data-spec="/wave/header/frame_id"] .plot-error', timeout=10000)
    text = page.inner_text('.plot-series-row[data-spec="/wave/header/frame_id"] .plot-error')
    assert "/wave/header/frame_id is a string, not a numeric field" in text
    before = len(page.evaluate("window.rqt.tools.plot.data()")["/wave/point/y"])
    wait_until(
        lambda: len(page.evaluate("window.rqt.tools.plot.data()")["/wave/point/y"]) > before + 10,
        what="more samples after the bad field",
    )


@pytest.mark.ros1
def test_console_lists_a_rospy_nodes_logwarn(graph: Graph, browser_page: Any) -> None:
    rosout = Rosout(graph.uri, None)
    script = (
        "import rospy\nrospy.init_node('warner')\nr = rospy.Rate(5)\n"
        "while not rospy.is_shutdown():\n    rospy.logwarn('low battery: %d%%', 12)\n"
        "    rospy.loginfo('all fine')\n    r.sleep()\n"
    )
    proc = subprocess.Popen(
        [ROS1_PYTHON, "-c", script],
        env=ros1_env(graph.uri),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    try:
        page = browser_page
        _open(page, tool_url(graph.rqt(), "console"))
        row = '.console-table tr[data-node="/warner"]'
        page.wait_for_selector(f"{row} >> text=low battery: 12%", timeout=20000)
        warn = page.locator(f"{row}:has-text('low battery')").first
        assert warn.locator(".sev").inner_text() == "Warn"
        # severity filter: without Warn only the info lines stay
        page.uncheck('input[data-level="Warn"]')
        wait_until(lambda: page.locator(f"{row}:has-text('low battery')").count() == 0, what="warn hidden")
        assert page.locator(f"{row}:has-text('all fine')").count() > 0
        page.check('input[data-level="Warn"]')
        # save: the shown messages as rqt_console's columns
        with page.expect_download() as download:
            page.click(".console-save")
        saved = Path(download.value.path()).read_text()
        assert saved.startswith("message;severity;node;stamp;topics;location\n")
        assert '"low battery: 12%";"Warn";"/warner";' in saved
        # a bad regex is named in the page; a good one filters
        page.fill(".console-regex", "battery(")
        page.wait_for_selector("#pane-console .rq-msgs >> text=invalid regular expression", timeout=5000)
        page.fill(".console-regex", "^all")
        wait_until(lambda: page.locator(f"{row}:has-text('low battery')").count() == 0, what="regex filter")
        assert page.locator(f"{row}:has-text('all fine')").count() > 0
    finally:
        proc.terminate()
        proc.wait(10)
        rosout.stop()


def _bag(path: Path) -> None:
    image = M("sensor_msgs/Image")(height=2, width=2, encoding="rgb8", step=6, data=bytes([255, 0, 0] * 4))
    with Bag(str(path), "w") as bag:
        for i in range(20):
            bag.write(
                "/odom_x", M("std_msgs/Float64")(data=float(i)), Time(100 + i // 2, (i % 2) * 500_000_000)
            )
        for i in range(3):
            bag.write("/camera/image", image, Time(100 + 4 * i, 0))


def test_bag_timeline_shows_topics_ticks_thumbnails_and_plays(
    graph: Graph, browser_page: Any, tmp_path: Path
) -> None:
    path = tmp_path / "run.bag"
    _bag(path)
    received: list[float] = []
    graph.peer.subscriber("/odom_x", M("std_msgs/Float64"), lambda m: received.append(m.data))
    page = browser_page
    _open(page, tool_url(graph.rqt([str(path)]), "bag"))
    page.wait_for_selector('.bag-row[data-topic="/odom_x"]', timeout=10000)
    rows = page.eval_on_selector_all(
        ".bag-row",
        "rs => rs.map(r => [r.dataset.topic, +r.dataset.count, +r.querySelector('canvas').dataset.ticks])",
    )
    assert rows == [["/camera/image", 3, 3], ["/odom_x", 20, 20]]
    # thumbnails show the image's red pixels
    wait_until(
        lambda: page.locator('.bag-thumbs[data-topic="/camera/image"] canvas').count() == 3, what="thumbs"
    )
    pixel = page.evaluate(
        "() => Array.from(document.querySelector('.bag-thumbs canvas').getContext('2d').getImageData(1, 1, 1, 1).data)"
    )
    assert pixel == [255, 0, 0, 255]
    # the message under the cursor, then a plot of a field over the bag
    page.click('.bag-row[data-topic="/odom_x"] .bag-name')
    page.wait_for_selector(".bag-message >> text=/odom_x @ 100.000000000", timeout=5000)
    # scrub: a click half way along the timeline shows the last message before that time
    canvas = page.locator('.bag-row[data-topic="/odom_x"] canvas')
    box = canvas.bounding_box()
    assert box is not None
    canvas.click(position={"x": box["width"] / 2, "y": 10})
    page.wait_for_selector(".bag-message >> text=/odom_x @ 104.500000000", timeout=5000)
    page.fill(".bag-plot-input", "/odom_x/data")
    page.click(".bag-plot-button")
    page.wait_for_selector('.bag-plot[data-points="20"]', timeout=5000)
    # play at 20x: the bag's messages reach a subscriber
    page.fill(".bag-speed", "20")
    page.click(".bag-play")  # playback waits for this subscriber to connect to its new publisher
    wait_until(lambda: len(received) >= 5, what="played messages")
    assert received == sorted(received)


def test_bag_that_does_not_parse_is_named_in_the_page(
    graph: Graph, browser_page: Any, tmp_path: Path
) -> None:
    bad = tmp_path / "broken.bag"
    bad.write_bytes(b"not a bag at all\n")
    page = browser_page
    _open(page, tool_url(graph.rqt([str(bad)]), "bag"))
    page.wait_for_selector("#pane-bag .rq-msgs >> text=not a bag file", timeout=10000)
    # the page keeps working: another tab opens and lists topics
    page.click('#rqt-tabs button[data-tool="topic"]')
    page.wait_for_selector('.topic-table tr[data-topic="/rosout"]', timeout=10000)


def test_image_view_shows_the_published_pixels(graph: Graph, browser_page: Any) -> None:
    pub = graph.peer.publisher("/camera/rgb", M("sensor_msgs/Image"), queue_size=1, latch=True)
    # 3x2 bgr8: row 0 blue, green, red; row 1 white, black, grey (step padded to 12)
    rows = [[(255, 0, 0), (0, 255, 0), (0, 0, 255)], [(255, 255, 255), (0, 0, 0), (128, 128, 128)]]
    data = b"".join(bytes([c for px in row for c in px]) + b"\0\0\0" for row in rows)
    pub.publish(M("sensor_msgs/Image")(height=2, width=3, encoding="bgr8", step=12, data=data))
    depth = graph.peer.publisher("/camera/depth", M("sensor_msgs/Image"), queue_size=1, latch=True)
    import struct

    depth.publish(
        M("sensor_msgs/Image")(height=1, width=2, encoding="32FC1", step=8, data=struct.pack("<2f", 1.0, 3.0))
    )
    page = browser_page
    _open(page, tool_url(graph.rqt(), "image_view", [("topic", "/camera/rgb")]))
    page.wait_for_function("document.getElementById('iv-canvas').width === 3", timeout=10000)
    pixels = page.evaluate(
        "() => Array.from(document.getElementById('iv-canvas').getContext('2d').getImageData(0, 0, 3, 2).data)"
    )
    got = [tuple(pixels[i : i + 3]) for i in range(0, len(pixels), 4)]
    assert got == [(0, 0, 255), (0, 255, 0), (255, 0, 0), (255, 255, 255), (0, 0, 0), (128, 128, 128)]
    # the chooser lists both; a float depth image is drawn from its min (black) to its max (white)
    page.wait_for_selector('.iv-topic option[value="/camera/depth"]', state="attached", timeout=10000)
    page.select_option(".iv-topic", "/camera/depth")
    page.wait_for_function("document.getElementById('iv-canvas').width === 2", timeout=10000)
    pixels = page.evaluate(
        "() => Array.from(document.getElementById('iv-canvas').getContext('2d').getImageData(0, 0, 2, 1).data)"
    )
    assert pixels == [0, 0, 0, 255, 255, 255, 255, 255]
    # a CompressedImage (png): decoded by the browser
    packed = graph.peer.publisher("/camera/png", M("sensor_msgs/CompressedImage"), queue_size=1, latch=True)
    packed.publish(
        M("sensor_msgs/CompressedImage")(
            format="rgb8; png compressed bgr8", data=_png_rgb(4, 1, (10, 200, 30))
        )
    )
    page.wait_for_selector('.iv-topic option[value="/camera/png"]', state="attached", timeout=10000)
    page.select_option(".iv-topic", "/camera/png")
    page.wait_for_function("document.getElementById('iv-canvas').width === 4", timeout=10000)
    pixels = page.evaluate(
        "() => Array.from(document.getElementById('iv-canvas').getContext('2d').getImageData(3, 0, 1, 1).data)"
    )
    assert pixels == [10, 200, 30, 255]
    # a JPEG as image_transport's compressed publisher writes it ("rgb8; jpeg compressed bgr8")
    import numpy as np

    from ninjemys.cv_bridge import CvBridge
    from ninjemys.image_transport import encode

    flat = np.zeros((8, 16, 3), np.uint8)
    flat[:] = (200, 40, 60)
    jpeg = graph.peer.publisher("/camera/jpeg", M("sensor_msgs/CompressedImage"), queue_size=1, latch=True)
    jpeg.publish(encode(CvBridge().cv2_to_imgmsg(flat, "rgb8")))
    page.wait_for_selector('.iv-topic option[value="/camera/jpeg"]', state="attached", timeout=10000)
    page.select_option(".iv-topic", "/camera/jpeg")
    page.wait_for_function("document.getElementById('iv-canvas').width === 16", timeout=10000)
    pixels = page.evaluate(
        "() => Array.from(document.getElementById('iv-canvas').getContext('2d').getImageData(5, 4, 1, 1).data)"
    )
    assert max(abs(a - b) for a, b in zip(pixels, [200, 40, 60, 255], strict=True)) <= 6, pixels
    assert "rgb8; jpeg compressed bgr8" in page.inner_text(".iv-info")


def _png_rgb(width: int, height: int, rgb: tuple[int, int, int]) -> bytes:
    """A PNG of one colour (8-bit RGB, no filter)."""
    import struct
    import zlib

    def chunk(kind: bytes, body: bytes) -> bytes:
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))

    rows = b"".join(b"\0" + bytes(rgb) * width for _ in range(height))
    header = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    return (
        b"\x89PNG\r\n\x1a\n"
        + chunk(b"IHDR", header)
        + chunk(b"IDAT", zlib.compress(rows))
        + chunk(b"IEND", b"")
    )


CFG = """\
#!/usr/bin/env python
PACKAGE = "rqt_demo"
from dynamic_reconfigure.parameter_generator_catkin import *
gen = ParameterGenerator()
gen.add("int_param", int_t, 0, "An Integer parameter", 50, 0, 100)
gen.add("bool_param", bool_t, 0, "A Boolean parameter", True)
size_enum = gen.enum([gen.const("Small", int_t, 0, "small"), gen.const("Large", int_t, 1, "large")], "size")
gen.add("size", int_t, 1, "A size", 0, 0, 1, edit_method=size_enum)
exit(gen.generate(PACKAGE, "rqt_demo_node", "Demo"))
"""


def test_reconfigure_sets_a_parameter_on_a_running_server(
    graph: Graph, browser_page: Any, tmp_path: Path
) -> None:
    import importlib.util

    cfg = tmp_path / "Demo.cfg"
    cfg.write_text(CFG)
    (gen,) = run_cfg(cfg, "rqt_demo")
    module_path = tmp_path / "DemoConfig.py"
    module_path.write_text(render_module(gen))
    spec = importlib.util.spec_from_file_location("DemoConfig", module_path)
    assert spec is not None and spec.loader is not None
    config_type = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(config_type)
    node = Node("demo_server", master_uri=graph.uri)
    seen: list[dict] = []

    def callback(config: Any, level: int) -> Any:
        seen.append(dict(config))
        return config

    try:
        ReconfigureServer(node, config_type, callback)
        page = browser_page
        _open(page, tool_url(graph.rqt(), "reconfigure", [("node", "/demo_server")]))
        number = '.rc-param[data-param="int_param"] .rc-number'
        page.wait_for_function(f"document.querySelector('{number}')?.value === '50'", timeout=15000)
        page.fill(number, "77")
        page.press(number, "Enter")
        wait_until(lambda: seen and seen[-1]["int_param"] == 77, what="int_param set to 77")
        assert node.get_param("/demo_server/int_param") == 77
        page.select_option('.rc-param[data-param="size"] .rc-enum', "1")
        wait_until(lambda: seen[-1]["size"] == 1, what="size set to Large")
        page.uncheck('.rc-param[data-param="bool_param"] .rc-bool')
        wait_until(lambda: seen[-1]["bool_param"] is False, what="bool_param cleared")
        # not a number: a message in the page, nothing sent
        count = len(seen)
        page.fill(number, "")
        page.press(number, "Enter")
        page.wait_for_selector("#pane-reconfigure .rq-msgs >> text=is not an integer", timeout=5000)
        assert len(seen) == count
    finally:
        node.shutdown("test over")


def test_axclient_drives_a_fibonacci_server(graph: Graph, browser_page: Any) -> None:
    action = M("actionlib_tutorials/FibonacciAction")
    node = Node("fibonacci", master_uri=graph.uri)

    def execute(goal: Any) -> None:
        seq = [0, 1]
        for _ in range(1, goal.order):
            if server.is_preempt_requested():
                server.set_preempted()
                return
            seq.append(seq[-1] + seq[-2])
            server.publish_feedback(M("actionlib_tutorials/FibonacciFeedback")(sequence=seq))
            time.sleep(0.05 if goal.order < 10 else 0.5)
        server.set_succeeded(M("actionlib_tutorials/FibonacciResult")(sequence=seq))

    server = SimpleActionServer(node, "fibonacci", action, execute_cb=execute, auto_start=False)
    server.start()
    try:
        page = browser_page
        _open(page, tool_url(graph.rqt(), "axclient", [("action", "/fibonacci")]))
        page.wait_for_selector(".ax-send:not([disabled])", timeout=15000)
        assert '"order": 0' in page.input_value(".ax-goal")
        page.fill(".ax-goal", '{"order": 6}')
        page.click(".ax-send")
        page.wait_for_selector('.ax-status[data-status="SUCCEEDED"]', timeout=15000)
        assert "[\n    0,\n    1,\n    1,\n    2,\n    3,\n    5,\n    8\n  ]" in page.inner_text(
            ".ax-result"
        )
        assert "8" in page.inner_text(".ax-feedback")
        # a long goal, cancelled while it runs
        page.fill(".ax-goal", '{"order": 40}')
        page.click(".ax-send")
        page.wait_for_selector('.ax-status[data-status="ACTIVE"]', timeout=15000)
        page.click(".ax-cancel")
        page.wait_for_selector('.ax-status[data-status="PREEMPTED"]', timeout=15000)
        # a goal that is not JSON: a message, the page keeps working
        page.fill(".ax-goal", "{order: 6")
        page.click(".ax-send")
        page.wait_for_selector("#pane-axclient .rq-msgs >> text=goal is not valid JSON", timeout=5000)
    finally:
        node.shutdown("test over")


def test_tf_tree_shows_frames_with_rates(graph: Graph, browser_page: Any) -> None:
    from rviz_helpers import tf_message, transform

    static = graph.peer.publisher("/tf_static", M("tf2_msgs/TFMessage"), queue_size=1, latch=True)
    static.publish(tf_message(transform("map", "odom", 0, 0)))
    tf = graph.peer.publisher("/tf", M("tf2_msgs/TFMessage"), queue_size=10)
    graph.every(0.05, lambda _k: tf.publish(tf_message(transform("odom", "base_link", 1, 0))))
    page = browser_page
    _open(page, tool_url(graph.rqt(), "tf_tree"))
    page.wait_for_selector(
        'li[data-frame="map"] li[data-frame="odom"] li[data-frame="base_link"]', timeout=15000
    )
    wait_until(lambda: "Hz" in page.inner_text('li[data-frame="base_link"] > .meta'), what="base_link's rate")
    assert "static" in page.inner_text('li[data-frame="odom"] > .meta')


def test_plot_names_a_topic_that_disappears_and_picks_it_up_again(graph: Graph, browser_page: Any) -> None:
    cls = M("std_msgs/Float64")
    holder = {"pub": graph.peer.publisher("/flaky", cls, queue_size=10)}
    graph.every(0.05, lambda k: holder["pub"] and holder["pub"].publish(cls(data=float(k))))
    page = browser_page
    _open(page, tool_url(graph.rqt(), "plot", [("topic", "/flaky/data")]))
    samples = lambda: len(page.evaluate("window.rqt.tools.plot.data()")["/flaky/data"])  # noqa: E731
    wait_until(lambda: samples() > 5, what="first samples")
    pub, holder["pub"] = holder["pub"], None
    pub.unregister()
    error = '.plot-series-row[data-spec="/flaky/data"] .plot-error'
    page.wait_for_selector(f"{error} >> text=not published any more", timeout=15000)
    holder["pub"] = graph.peer.publisher("/flaky", cls, queue_size=10)
    page.wait_for_selector(error, state="detached", timeout=15000)
    count = samples()
    wait_until(lambda: samples() > count + 5, what="samples after the topic came back")


def test_logger_level_publisher_and_service_caller(graph: Graph, browser_page: Any) -> None:
    got: list[str] = []
    graph.peer.subscriber("/typed", M("std_msgs/String"), lambda m: got.append(m.data))
    peer = graph.peer.name
    page = browser_page
    _open(page, tool_url(graph.rqt(), "logger_level"))
    page.wait_for_selector(f'.ll-node option[value="{peer}"]', state="attached", timeout=15000)
    page.select_option(".ll-node", peer)
    page.wait_for_selector('.ll-logger option[value="rosout"]', state="attached", timeout=10000)
    page.select_option(".ll-logger", "rosout")
    page.select_option(".ll-level", "debug")
    page.wait_for_selector("#pane-logger_level .rq-msgs >> text=rosout set to debug", timeout=10000)
    proxy = graph.peer.service_proxy(f"{peer}/get_loggers", get_message_class_srv("roscpp/GetLoggers"))
    levels = {lg.name: lg.level for lg in proxy.call().loggers}
    assert levels["rosout"] == "debug"

    # message publisher: fields from the type's defaults, edited, published
    page.click('#rqt-tabs button[data-tool="publisher"]')
    page.fill(".pub-topic", "/typed")
    page.fill(".pub-type", "std_msgs/String")
    page.click("text=load fields")
    page.wait_for_function("document.querySelector('.pub-message').value.includes('\"data\": \"\"')")
    page.fill(".pub-message", '{"data": "from the page"}')
    time.sleep(0.5)
    for _ in range(20):  # until the subscriber has connected to the page's publisher
        page.click(".pub-once")
        if got:
            break
        time.sleep(0.3)
    wait_until(lambda: "from the page" in got, what="the published message")
    page.fill(".pub-type", "std_msgs/Nope")
    page.click(".pub-once")
    page.wait_for_selector("#pane-publisher .rq-msgs >> text=std_msgs/Nope", timeout=5000)

    # service caller: the request's fields, the response shown
    page.click('#rqt-tabs button[data-tool="service_caller"]')
    page.wait_for_selector(f'.sc-service option[value="{peer}/get_loggers"]', state="attached", timeout=10000)
    page.select_option(".sc-service", f"{peer}/get_loggers")
    page.click(".sc-call")
    wait_until(lambda: '"name": "rosout"' in page.inner_text(".sc-response"), what="the response")
    page.select_option(".sc-service", f"{peer}/set_logger_level")
    page.fill(".sc-request", '{"logger": "rosout", "level": "loud"}')
    page.click(".sc-call")
    page.wait_for_selector("#pane-service_caller .rq-msgs >> text=loud", timeout=10000)
