"""realsense2_camera on a recording of synthetic frames (librealsense's recorder over a software device):
rs_from_file.launch publishes the named topics with the recording's pixels, depth, intrinsics, the
aligned depth, the point cloud and the static transforms; without pyrealsense2 the node says so in one line."""

from __future__ import annotations

import math
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest

from ninjemys import testing
from ninjemys.drivers.realsense_msgs import Intrinsics, camera_info_fields, point_cloud, stream_transforms
from ninjemys.idl.loader import get_message_class
from ninjemys.node import Node

from .conftest import Rig
from .realsense_recording import BASELINE_M, BOX_MM, FX, WALL_MM, H, W, write_recording

Image = get_message_class("sensor_msgs/Image")
CameraInfo = get_message_class("sensor_msgs/CameraInfo")
PointCloud2 = get_message_class("sensor_msgs/PointCloud2")
TFMessage = get_message_class("tf2_msgs/TFMessage")


# -- the message arithmetic on its own -------------------------------------------------------------


def test_camera_info_from_intrinsics() -> None:
    f = camera_info_fields(Intrinsics(640, 480, 600.0, 601.0, 320.5, 240.5), "camera_color_optical_frame")
    assert f["K"] == [600.0, 0.0, 320.5, 0.0, 601.0, 240.5, 0.0, 0.0, 1.0]
    assert f["P"] == [600.0, 0.0, 320.5, 0.0, 0.0, 601.0, 240.5, 0.0, 0.0, 0.0, 1.0, 0.0]
    assert f["distortion_model"] == "plumb_bob" and len(f["D"]) == 5
    assert len(camera_info_fields(Intrinsics(1, 1, 1, 1, 0, 0, "equidistant", (0.1,) * 5), "x")["D"]) == 4


def test_static_transforms_turn_optical_extrinsics_into_body_axes() -> None:
    identity = [1.0, 0, 0, 0, 1.0, 0, 0, 0, 1.0]
    link, optical = stream_transforms("camera_link", "camera_color_frame", "camera_color_optical_frame",
                                      identity, [0.015, 0.0, 0.0])  # fmt: skip
    # 15 mm along the optical x (right) is 15 mm along the body -y
    assert link.translation == pytest.approx((0.0, -0.015, 0.0))
    assert link.rotation == pytest.approx((0.0, 0.0, 0.0, 1.0))
    assert optical.rotation == pytest.approx((-0.5, 0.5, -0.5, 0.5))
    assert (optical.parent, optical.child) == ("camera_color_frame", "camera_color_optical_frame")
    # a camera yawed 90 degrees about the optical y axis (down) is yawed -90 degrees about body z
    ry = [0.0, 0, -1.0, 0, 1.0, 0, 1.0, 0, 0.0]  # column-major
    q = stream_transforms("b", "f", "o", ry, [0, 0, 0])[0].rotation
    assert (
        abs(q[2]) == pytest.approx(math.sqrt(0.5)) and q[0] == pytest.approx(0) and q[1] == pytest.approx(0)
    )


def test_point_cloud_layout_colour_and_validity() -> None:
    vertices = np.array([[0, 0, 1.0], [0.1, 0, 2.0], [0, 0, 0.0], [0.2, 0, 3.0]], np.float32)
    uv = np.array([[0.0, 0.0], [0.99, 0.99], [0.5, 0.5], [1.5, 0.5]], np.float32)
    tex = np.zeros((2, 2, 3), np.uint8)
    tex[0, 0] = (10, 20, 30)
    tex[1, 1] = (40, 50, 60)
    cloud = point_cloud(vertices, uv, tex)
    assert cloud.point_step == 20 and cloud.fields == [("x", 0), ("y", 4), ("z", 8), ("rgb", 16)]
    assert (cloud.width, cloud.height, cloud.is_dense) == (2, 1, True)  # no depth, no texture: dropped
    rows = np.frombuffer(cloud.data, np.uint8).reshape(-1, 20)
    assert rows[0, 16:19].tolist() == [30, 20, 10] and rows[1, 16:19].tolist() == [60, 50, 40]  # B, G, R
    kept = point_cloud(vertices, uv, tex, allow_no_texture_points=True)
    assert kept.width == 3
    ordered = point_cloud(vertices, uv, tex, ordered=True, shape=(2, 2))
    assert (ordered.width, ordered.height, ordered.is_dense) == (2, 2, False)
    plain = point_cloud(vertices, None, None)
    assert (plain.point_step, plain.width) == (16, 3)


# -- the node on a recording -------------------------------------------------------------------------


class Last:
    def __init__(self) -> None:
        self.msgs: dict[str, list] = {}
        self.cond = threading.Condition()

    def cb(self, key: str):  # noqa: ANN201
        def on(msg) -> None:  # noqa: ANN001
            with self.cond:
                self.msgs.setdefault(key, []).append(msg)
                self.cond.notify_all()

        return on

    def wait(self, keys: list[str], timeout: float = 30.0) -> None:
        deadline = time.monotonic() + timeout
        with self.cond:
            while not all(self.msgs.get(k) for k in keys) or not self.paired("depth", "depth_info"):
                left = deadline - time.monotonic()
                if left <= 0:
                    missing = [k for k in keys if not self.msgs.get(k)]
                    raise AssertionError(f"nothing on {missing}, or no depth image with its camera_info")
                self.cond.wait(left)

    def paired(self, image: str, info: str) -> list[tuple]:
        """(image, info) pairs of one frame: the two topics are separate connections, so the newest
        message of each can belong to different frames when the launch is stopped between them."""
        infos = {m.header.stamp: m for m in self.msgs.get(info, [])}
        return [(m, infos[m.header.stamp]) for m in self.msgs.get(image, []) if m.header.stamp in infos]


@pytest.fixture(scope="module")
def recording(tmp_path_factory: pytest.TempPathFactory) -> Path:
    pytest.importorskip("pyrealsense2")
    return write_recording(tmp_path_factory.mktemp("rs") / "synthetic", frames=150)


def test_rs_from_file_launch_publishes_the_recording(recording: Path, tmp_path: Path) -> None:
    env = dict(os.environ, ROS_HOME=str(tmp_path), ROS_LOG_DIR=str(tmp_path))
    with testing.run_master(env=env) as uri:
        env["ROS_MASTER_URI"] = uri
        node = Node("rs_test", master_uri=uri)
        got = Last()
        topics = {
            "color": ("/camera/color/image_raw", Image),
            "color_info": ("/camera/color/camera_info", CameraInfo),
            "depth": ("/camera/depth/image_rect_raw", Image),
            "depth_info": ("/camera/depth/camera_info", CameraInfo),
            "aligned": ("/camera/aligned_depth_to_color/image_raw", Image),
            "points": ("/camera/depth/color/points", PointCloud2),
            "tf_static": ("/tf_static", TFMessage),
        }
        for key, (topic, cls) in topics.items():
            node.subscriber(topic, cls, got.cb(key))
        launch = subprocess.Popen(
            [testing.ninjemys_bin("roslaunch"), "realsense2_camera", "rs_from_file.launch",
             f"rosbag_filename:={recording}", "align_depth:=true", "enable_pointcloud:=true"],
            env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, start_new_session=True, text=True,
        )  # fmt: skip
        try:
            got.wait(list(topics), timeout=60)
        finally:
            os.killpg(launch.pid, signal.SIGINT)
            try:
                out, _ = launch.communicate(timeout=20)
            except subprocess.TimeoutExpired:
                testing.kill_tree(launch)
                out, _ = launch.communicate()
            node.shutdown()
        assert f"publish topics from rosbag file: {recording}" in out, out

        color = got.msgs["color"][-1]
        assert (color.width, color.height, color.encoding, color.step) == (W, H, "rgb8", W * 3)
        assert color.header.frame_id == "camera_color_optical_frame"
        pixels = np.frombuffer(bytes(color.data), np.uint8).reshape(H, W, 3)
        assert pixels[H // 2, 2].tolist() == [220, 10, 10] and pixels[H // 2, W - 2].tolist() == [0, 0, 200]

        depth, info = got.paired("depth", "depth_info")[-1]
        assert (depth.encoding, depth.header.frame_id) == ("16UC1", "camera_depth_optical_frame")
        mm = np.frombuffer(bytes(depth.data), "<u2").reshape(H, W)
        assert mm[H // 2, 2] == BOX_MM and WALL_MM <= mm[H // 2, W - 2] < WALL_MM + 150
        assert list(info.K) == pytest.approx([FX, 0, W / 2, 0, FX, H / 2, 0, 0, 1])
        assert info.header.stamp == depth.header.stamp and info.header.frame_id == depth.header.frame_id
        assert abs(depth.header.stamp.to_sec() - time.time()) < 600  # the recording's system-clock stamps

        aligned = got.msgs["aligned"][-1]
        assert aligned.header.frame_id == "camera_color_optical_frame"
        amm = np.frombuffer(bytes(aligned.data), "<u2").reshape(H, W)
        # reprojected 15 mm sideways: the box's edge moves by fx * 0.015 / 1.0 = 0.75 px at most
        assert amm[H // 2, 4] == BOX_MM and WALL_MM <= amm[H // 2, W - 4] < WALL_MM + 150

        cloud = got.msgs["points"][-1]
        assert cloud.header.frame_id == "camera_color_optical_frame"  # aligned: in the colour frame
        assert [f.name for f in cloud.fields] == ["x", "y", "z", "rgb"] and cloud.point_step == 20
        xyz = np.frombuffer(bytes(cloud.data), np.uint8).reshape(-1, 20)[:, :12].copy().view(np.float32)
        assert cloud.width > 0.9 * W * H and cloud.height == 1
        depths_mm = set(np.round(xyz[:, 2].astype(np.float64) * 1000).astype(int).tolist())
        assert depths_mm <= {BOX_MM, *range(WALL_MM, WALL_MM + 160)}, sorted(depths_mm)[:10]

        frames = {
            (t.header.frame_id, t.child_frame_id): t for m in got.msgs["tf_static"] for t in m.transforms
        }
        assert ("camera_link", "camera_depth_frame") in frames
        assert ("camera_depth_frame", "camera_depth_optical_frame") in frames
        color_link = frames[("camera_link", "camera_color_frame")].transform.translation
        # the colour camera is 15 mm to the right (optical +x) of depth: body -y; extrinsics are to the base
        assert (color_link.x, abs(color_link.y), color_link.z) == pytest.approx(
            (0.0, BASELINE_M, 0.0), abs=1e-6
        )
        assert ("camera_link", "camera_aligned_depth_to_color_frame") in frames


def test_without_pyrealsense2_the_node_says_so_in_one_line(tmp_path: Path) -> None:
    blocker = tmp_path / "pyrealsense2"
    blocker.mkdir()
    (blocker / "__init__.py").write_text("raise ImportError('not here')\n")
    env = dict(os.environ, PYTHONPATH=str(tmp_path), ROS_MASTER_URI="http://localhost:1/")
    done = subprocess.run(
        [sys.executable, "-m", "ninjemys.packages.run_shipped", "realsense2_camera", "realsense2_camera_node"],
        env=env, capture_output=True, text=True, timeout=60,
    )  # fmt: skip
    assert done.returncode == 1
    assert done.stderr.strip().splitlines() == [
        "realsense2_camera: pyrealsense2 is not installed (pip install pyrealsense2): no RealSense camera can be read"
    ]


def test_without_a_camera_the_node_says_so_as_realsense2_camera_and_gives_up_when_told(rig: Rig) -> None:
    """No device on the machine (CI has none): realsense2_camera's warning each ``reconnect_timeout``,
    and ``wait_for_device_timeout`` ends the wait with its error, no traceback."""
    rs = pytest.importorskip("pyrealsense2")
    if len(rs.context().query_devices()):
        pytest.skip("a RealSense camera is attached to this machine")
    proc = rig.shipped(
        "realsense2_camera",
        "realsense2_camera_node",
        "_wait_for_device_timeout:=1.5",
        "_reconnect_timeout:=0.5",
    )
    out = rig.exit_output(proc)
    assert "No RealSense devices were found!" in out, out
    assert "wait for device timeout of 1.5 secs expired" in out, out
