"""``roslaunch realsense2_camera rs_rgbd.launch``: the camera with image_proc's rectified colour and
depth_image_proc's registered XYZRGB cloud, on the topics and with the arguments realsense2_camera's
launch file has; the cloud and rectification functions against hand-worked values and OpenCV."""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np
import pytest

from ninjemys.drivers.rgbd_proc import image_array, rectify, xyzrgb_points
from ninjemys.idl.loader import get_message_class
from ninjemys.launch.xml import load_launch
from ninjemys.packages.discovery import find_package
from ninjemys.testing import run_master

Image = get_message_class("sensor_msgs/Image")
CameraInfo = get_message_class("sensor_msgs/CameraInfo")
PointCloud2 = get_message_class("sensor_msgs/PointCloud2")
K = (100.0, 0.0, 1.0, 0.0, 100.0, 0.5, 0.0, 0.0, 1.0)


def test_xyzrgb_points_are_depth_image_procs_layout() -> None:
    depth = np.array([[1000, 0, 2000], [500, 1500, 65535]], np.uint16)  # mm; 0: no reading
    colour = np.arange(2 * 3 * 3, dtype=np.uint8).reshape(2, 3, 3)  # rgb8
    rows = xyzrgb_points(depth, colour, "rgb8", K)
    assert rows.shape == (6, 32)
    xyz = rows[:, :12].copy().view(np.float32).reshape(6, 3)
    # pixel (u=0, v=0) at 1 m: x = (0 - 1) * 1 / 100, y = (0 - 0.5) * 1 / 100
    assert xyz[0] == pytest.approx([-0.01, -0.005, 1.0])
    assert all(math.isnan(v) for v in xyz[1])  # no depth: NaN, the point kept (organised cloud)
    assert xyz[5] == pytest.approx([(2 - 1) * 65.535 / 100, 0.5 * 65.535 / 100, 65.535])
    assert rows[4, 16:20].tolist() == [14, 13, 12, 0]  # B, G, R, 0 of pixel (1, 1) = (12, 13, 14)
    bgr = xyzrgb_points(depth, colour[..., ::-1].copy(), "bgr8", K)
    assert bgr[4, 16:20].tolist() == [14, 13, 12, 0]
    metres = xyzrgb_points(depth.astype(np.float32) / 1000, colour, "rgb8", K)
    assert np.array_equal(metres[:, 12:], rows[:, 12:])
    double = np.repeat(np.repeat(colour, 2, axis=0), 2, axis=1)  # colour twice the depth's size
    assert xyzrgb_points(depth, double, "rgb8", K)[4, 16:19].tolist() == double[2, 2, ::-1].tolist()
    with pytest.raises(ValueError, match="depth resolution 3x2 does not match RGB resolution 4x2"):
        xyzrgb_points(depth, np.zeros((2, 4, 3), np.uint8), "rgb8", K)


def test_rectify_passes_an_undistorted_camera_through_and_undistorts_as_opencv() -> None:
    cv2 = pytest.importorskip("cv2")
    img = (np.arange(48 * 64 * 3) % 251).astype(np.uint8).reshape(48, 64, 3)
    info = CameraInfo(width=64, height=48, K=[50, 0, 32, 0, 50, 24, 0, 0, 1], D=[0.0] * 5)
    info.R = [1, 0, 0, 0, 1, 0, 0, 0, 1]
    info.P = [50, 0, 32, 0, 0, 50, 24, 0, 0, 0, 1, 0]
    assert rectify(img, info) is img
    info.D = [-0.2, 0.05, 0.0, 0.0, 0.0]
    k = np.array(info.K, float).reshape(3, 3)
    m1, m2 = cv2.initUndistortRectifyMap(k, np.array(info.D), np.eye(3), k, (64, 48), cv2.CV_32FC1)
    assert np.array_equal(rectify(img, info), cv2.remap(img, m1, m2, cv2.INTER_LINEAR))


def test_image_array_reads_padded_rows_and_refuses_short_data() -> None:
    msg = Image(height=2, width=2, encoding="16UC1", step=6, data=bytes([1, 0, 2, 0, 9, 9, 3, 0, 4, 0, 9, 9]))
    assert image_array(msg).tolist() == [[1, 2], [3, 4]]
    msg.data = bytes(5)
    with pytest.raises(ValueError, match="got step 6, 5 bytes"):
        image_array(msg)


def test_rs_rgbd_launch_has_realsense2_cameras_arguments_and_topics() -> None:
    launch = find_package("realsense2_camera") / "launch" / "rs_rgbd.launch"
    plan = load_launch([launch], env=dict(os.environ))
    names = {n.namespace.rstrip("/") + "/" + n.name: n for n in plan.nodes}
    assert set(names) == {
        "/camera/realsense2_camera",
        "/camera/color/color_rectify_color",
        "/camera/points_xyzrgb_hw_registered",
    }, set(names)
    cloud = names["/camera/points_xyzrgb_hw_registered"]
    assert (cloud.package, cloud.type) == ("depth_image_proc", "point_cloud_xyzrgb")
    assert dict(cloud.remap_args) == {
        "rgb/image_rect_color": "color/image_rect_color",
        "rgb/camera_info": "color/camera_info",
        "depth_registered/image_rect": "aligned_depth_to_color/image_raw",
        "depth_registered/points": "depth_registered/points",
    }
    params = plan.params
    assert params.get("/camera/realsense2_camera/align_depth") in (True, "True", "true"), params
    sw = load_launch([launch], argv=["align_depth:=false", "camera:=cam"], env=dict(os.environ))
    sw_names = {n.namespace.rstrip("/") + "/" + n.name: n for n in sw.nodes}
    assert "/cam/points_xyzrgb_sw_registered" in sw_names
    assert dict(sw_names["/cam/points_xyzrgb_sw_registered"].remap_args)["depth_registered/points"] == (
        "depth_registered/points"
    )
    # the real file's arguments, each accepted (serial_no, json_file_path, fps and sizes, filters ...)
    real_args = [
        "serial_no:=123",
        "json_file_path:=/x.json",
        "color_fps:=15",
        "depth_width:=640",
        "enable_gyro:=true",
        "filters:=spatial",
        "tf_publish_rate:=5",
        "external_manager:=false",
        "infra_width:=640",
    ]
    load_launch([launch], argv=real_args, env=dict(os.environ))


def _publish_frame(node, pubs, stamp) -> None:  # noqa: ANN001
    colour = np.zeros((4, 6, 3), np.uint8)
    colour[..., 0] = 200  # red
    depth = np.full((4, 6), 1500, np.uint16)
    info = CameraInfo(width=6, height=4, K=[10, 0, 3, 0, 10, 2, 0, 0, 1], D=[0.0] * 5)
    info.R = [1, 0, 0, 0, 1, 0, 0, 0, 1]
    info.P = [10, 0, 3, 0, 0, 10, 2, 0, 0, 0, 1, 0]
    for msg in (info,):
        msg.header.stamp, msg.header.frame_id = stamp, "camera_color_optical_frame"
    img = Image(height=4, width=6, encoding="rgb8", step=18, data=colour.tobytes())
    img.header.stamp, img.header.frame_id = stamp, "camera_color_optical_frame"
    d = Image(height=4, width=6, encoding="16UC1", step=12, data=depth.tobytes())
    d.header.stamp, d.header.frame_id = stamp, "camera_aligned_depth_to_color_frame"
    pubs["raw"].publish(img)
    pubs["info"].publish(info)
    pubs["aligned"].publish(d)


def test_image_proc_and_point_cloud_xyzrgb_nodes_give_the_registered_cloud(tmp_path: Path) -> None:
    import subprocess
    import threading

    from ninjemys.node import Node
    from ninjemys.packages.shipped import shipped_executable
    from ninjemys.rostime import Time

    with run_master() as uri:
        env = dict(os.environ, ROS_MASTER_URI=uri, ROS_HOME=str(tmp_path), ROS_LOG_DIR=str(tmp_path))
        remaps = [
            "__ns:=/camera",
            "rgb/image_rect_color:=color/image_rect_color",
            "rgb/camera_info:=color/camera_info",
            "depth_registered/image_rect:=aligned_depth_to_color/image_raw",
        ]
        commands = [
            shipped_executable("image_proc", "image_proc").command(["__ns:=/camera/color"]),
            shipped_executable("depth_image_proc", "point_cloud_xyzrgb").command(remaps),
        ]
        out = subprocess.PIPE
        procs = [
            subprocess.Popen(c, env=env, stdout=out, stderr=subprocess.STDOUT, text=True) for c in commands
        ]
        node = Node("rgbd_test", master_uri=uri)
        try:
            got: list = []
            done = threading.Event()
            node.subscriber(
                "/camera/depth_registered/points", PointCloud2, lambda m: (got.append(m), done.set())
            )
            pubs = {
                "raw": node.publisher("/camera/color/image_raw", Image, queue_size=5),
                "info": node.publisher("/camera/color/camera_info", CameraInfo, queue_size=5),
                "aligned": node.publisher("/camera/aligned_depth_to_color/image_raw", Image, queue_size=5),
            }
            for i in range(600):  # until both nodes are connected and a cloud comes back
                _publish_frame(node, pubs, Time(100, i * 1000))
                if done.wait(0.1):
                    break
            assert got, "no cloud on /camera/depth_registered/points"
            cloud = got[0]
            assert (cloud.height, cloud.width, cloud.point_step, cloud.is_dense) == (4, 6, 32, False)
            assert [(f.name, f.offset) for f in cloud.fields] == [("x", 0), ("y", 4), ("z", 8), ("rgb", 16)]
            assert cloud.header.frame_id == "camera_color_optical_frame"
            rows = np.frombuffer(bytes(cloud.data), np.uint8).reshape(-1, 32)
            assert rows[:, :12].copy().view(np.float32)[0].tolist() == pytest.approx([-0.45, -0.3, 1.5])
            assert rows[0, 16:20].tolist() == [0, 0, 200, 0]
        finally:
            node.shutdown("test done")
            for p in procs:
                p.terminate()
            for p in procs:
                out, _ = p.communicate(timeout=20)
                assert "Traceback" not in out, out
