"""Every rviz display class on a live graph: each reports (and draws) what its topic carries."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from rviz_helpers import M, tf_message, transform
from web_helpers import wait_until

from ninjemys.master.core import MasterThread
from ninjemys.node import Node
from ninjemys.rostime import Duration
from ninjemys.web.rviz import Rviz

pytestmark = pytest.mark.browser

URDF = """<robot name="bot">
  <link name="base_link"><visual><geometry><box size="0.4 0.3 0.1"/></geometry>
    <material name="blue"><color rgba="0 0 1 1"/></material></visual></link>
  <link name="wheel"><visual><geometry><cylinder radius="0.05" length="0.02"/></geometry></visual></link>
  <link name="mast"><visual><geometry><sphere radius="0.05"/></geometry></visual></link>
  <joint name="wheel_joint" type="continuous"><parent link="base_link"/><child link="wheel"/>
    <origin xyz="0 0.15 0" rpy="-1.5708 0 0"/></joint>
  <joint name="mast_joint" type="fixed"><parent link="base_link"/><child link="mast"/><origin xyz="0 0 0.3"/></joint>
</robot>"""

DISPLAYS = [
    ("rviz/TF", "TF", ""),
    ("rviz/RobotModel", "RobotModel", "robot_description"),
    ("rviz/PointCloud2", "Cloud", "/cloud"),
    ("rviz/Path", "Path", "/path"),
    ("rviz/Pose", "Pose", "/pose"),
    ("rviz/PoseArray", "PoseArray", "/poses"),
    ("rviz/PoseWithCovariance", "PWC", "/pwc"),
    ("rviz/Odometry", "Odometry", "/odom"),
    ("rviz/MarkerArray", "Markers", "/markers"),
    ("rviz/Marker", "Marker", "/marker"),
    ("rviz/Image", "Image", "/image"),
    ("rviz/Polygon", "Footprint", "/footprint"),
]


def _config() -> str:
    lines = ["Visualization Manager:", "  Displays:"]
    for cls, name, topic in DISPLAYS:
        key = {"rviz/RobotModel": "Robot Description", "rviz/Image": "Image Topic"}.get(cls, "Topic")
        if cls.startswith("rviz/Marker"):
            key = "Marker Topic"
        lines += [f"    - Class: {cls}", f"      Name: {name}", "      Enabled: true"]
        if topic:
            lines.append(f"      {key}: {topic}")
    lines += ["  Global Options:", "    Fixed Frame: map"]
    return "\n".join(lines) + "\n"


@pytest.fixture
def live(tmp_path: Path) -> Iterator[dict[str, Any]]:
    config = tmp_path / "all.rviz"
    config.write_text(_config())
    with MasterThread() as uri:
        peer = Node("rviz_displays_peer", anonymous=True, master_uri=uri)
        peer.set_param("/robot_description", URDF)
        rviz = Rviz(uri, str(config), update_period=0.2)
        try:
            yield {"peer": peer, "url": rviz.start()}
        finally:
            rviz.stop()
            peer.shutdown("test over")


def _latched(peer: Node, topic: str, type_name: str, msg: Any) -> Any:
    pub = peer.publisher(topic, M(type_name), queue_size=1, latch=True)
    pub.publish(msg)
    return pub


def _publish_everything(peer: Node) -> list[Any]:
    keep = []
    keep.append(
        _latched(
            peer,
            "/tf_static",
            "tf2_msgs/TFMessage",
            tf_message(transform("map", "odom", 0, 0), transform("odom", "base_link", 1.0, 0.0)),
        )
    )
    n = 1000
    xyz = np.zeros((n, 3), dtype="<f4")
    xyz[:, 0] = np.linspace(0, 1, n)
    cloud = M("sensor_msgs/PointCloud2")(height=1, width=n, point_step=12, row_step=12 * n, is_dense=True)
    cloud.header.frame_id = "base_link"
    cloud.fields = [
        M("sensor_msgs/PointField")(name=c, offset=4 * i, datatype=7, count=1) for i, c in enumerate("xyz")
    ]
    cloud.data = xyz.tobytes()
    keep.append(_latched(peer, "/cloud", "sensor_msgs/PointCloud2", cloud))

    def pose_stamped(x: float, y: float) -> Any:
        p = M("geometry_msgs/PoseStamped")()
        p.header.frame_id = "map"
        p.pose.position.x, p.pose.position.y = x, y
        p.pose.orientation.w = 1.0
        return p

    path = M("nav_msgs/Path")(poses=[pose_stamped(i * 0.1, 0) for i in range(12)])
    path.header.frame_id = "map"
    keep.append(_latched(peer, "/path", "nav_msgs/Path", path))
    keep.append(_latched(peer, "/pose", "geometry_msgs/PoseStamped", pose_stamped(1, 1)))
    poses = M("geometry_msgs/PoseArray")(poses=[pose_stamped(i, -1).pose for i in range(5)])
    poses.header.frame_id = "map"
    keep.append(_latched(peer, "/poses", "geometry_msgs/PoseArray", poses))
    pwc = M("geometry_msgs/PoseWithCovarianceStamped")()
    pwc.header.frame_id = "map"
    pwc.pose.pose.orientation.w = 1.0
    cov = [0.0] * 36
    cov[0], cov[7] = 0.25, 0.04  # sigma 0.5 m along x, 0.2 m along y
    pwc.pose.covariance = cov
    keep.append(_latched(peer, "/pwc", "geometry_msgs/PoseWithCovarianceStamped", pwc))
    odom = M("nav_msgs/Odometry")(child_frame_id="base_link")
    odom.header.frame_id = "odom"
    odom.pose.pose.orientation.w = 1.0
    keep.append(_latched(peer, "/odom", "nav_msgs/Odometry", odom))
    markers = []
    for i, kind in enumerate([0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 11]):
        mk = M("visualization_msgs/Marker")(ns="all", id=i, type=kind, action=0, text=f"marker {i}")
        mk.header.frame_id = "base_link"
        mk.pose.position.x = i * 0.5
        mk.pose.orientation.w = 1.0
        mk.scale.x = mk.scale.y = mk.scale.z = 0.2
        mk.color.g = mk.color.a = 1.0
        mk.points = [M("geometry_msgs/Point")(x=0, y=0, z=0), M("geometry_msgs/Point")(x=0.2, y=0, z=0)]
        mk.points.append(M("geometry_msgs/Point")(x=0, y=0.2, z=0))
        markers.append(mk)
    keep.append(
        _latched(
            peer,
            "/markers",
            "visualization_msgs/MarkerArray",
            M("visualization_msgs/MarkerArray")(markers=markers),
        )
    )
    bad = M("visualization_msgs/Marker")(ns="bad", id=1, type=10, action=0)  # a mesh without a file: said so
    bad.header.frame_id = "map"
    bad.pose.orientation.w = 1.0
    bad.lifetime = Duration(0, 0)
    keep.append(_latched(peer, "/marker", "visualization_msgs/Marker", bad))
    image = M("sensor_msgs/Image")(height=3, width=4, encoding="rgb8", step=12)
    image.data = bytes([255, 0, 0] * 6 + [0, 0, 255] * 6)  # top half red, bottom half blue
    keep.append(_latched(peer, "/image", "sensor_msgs/Image", image))
    fp = M("geometry_msgs/PolygonStamped")()
    fp.header.frame_id = "base_link"
    fp.polygon.points = [
        M("geometry_msgs/Point32")(x=x, y=y) for x, y in ((0.2, 0.2), (0.2, -0.2), (-0.2, -0.2), (-0.2, 0.2))
    ]
    keep.append(_latched(peer, "/footprint", "geometry_msgs/PolygonStamped", fp))
    return keep


def test_every_display_shows_its_topic(live: dict[str, Any], browser_page: Any) -> None:
    keep = _publish_everything(live["peer"])
    page = browser_page
    page.goto(live["url"] + "?view=top&scale=80")
    page.wait_for_function("window.rviz && window.rviz.ready", timeout=20000)

    def status(name: str) -> str:
        return page.locator(f'.rv-display[data-name="{name}"] .rv-status').inner_text()

    expected = {
        "TF": "3 frames",
        "RobotModel": "3 links from /robot_description",
        "Cloud": "1000 points in [base_link]",
        "Path": "12 poses",
        "PoseArray": "5 poses",
        "PWC": "95% ellipse 2.45 × 0.98 m",
        "Odometry": "1 arrows",
        "Markers": "11 markers",
        "Image": "4×3 rgb8",
        "Footprint": "receiving geometry_msgs/PolygonStamped",
        "Pose": "receiving geometry_msgs/PoseStamped",
        "Marker": "MESH_RESOURCE marker without a mesh_resource",
    }
    for name, text in expected.items():
        wait_until(lambda n=name, t=text: t in status(n), what=f"{name}: {text!r} (has {status(name)!r})")
    # no display is in error except the mesh marker without a file, which says why
    errors = page.locator('.rv-display[data-level="error"]').evaluate_all(
        "els => els.map(e => e.dataset.name)"
    )
    assert errors == ["Marker"]
    # frame names and marker text are labels in the page
    labels = page.locator("#rv-labels span").all_inner_texts()
    assert {"map", "odom", "base_link", "marker 9"} <= set(labels)
    # the image panel holds the image's pixels
    rgb = page.evaluate(
        "(() => { const c = document.querySelector('#rv-images canvas'); const d = c.getContext('2d');"
        " return [Array.from(d.getImageData(0, 0, 1, 1).data), Array.from(d.getImageData(0, 2, 1, 1).data)]; })()"
    )
    assert rgb == [[255, 0, 0, 255], [0, 0, 255, 255]]
    # robot model links without tf come from their joints: the mast sits 0.3 m above base_link at (1, 0)
    mast = page.evaluate(
        "(() => { const d = rviz.displays.find(d => d.cfg.name === 'RobotModel'); const p = d.linkPose('mast');"
        " return p.t.map(v => Math.round(v * 100) / 100); })()"
    )
    assert mast == [1.0, 0.0, 0.3]
    del keep
