"""What ``rs_rgbd.launch`` runs beside the camera: image_proc's colour rectification and
depth_image_proc's ``point_cloud_xyzrgb`` (an OpenNI-style ``depth_registered/points``).

ROS 1 loads both as nodelets (rgbd_launch's ``rgb.launch.xml`` and depth_image_proc); here they are
plain nodes with the same topics, so the launch file gives the topics realsense2_camera users read:

* ``rosrun image_proc image_proc`` (in the camera's ``color`` namespace): ``image_raw`` +
  ``camera_info`` -> ``image_color``, ``image_mono``, ``image_rect_color`` and ``image_rect``
  (undistorted with the CameraInfo's K, D, R, P; a camera with no distortion passes through).
* ``rosrun depth_image_proc point_cloud_xyzrgb``: ``rgb/image_rect_color``, ``rgb/camera_info`` and
  ``depth_registered/image_rect`` (16UC1 millimetres or 32FC1 metres, registered to the colour
  camera) matched by ApproximateTime (``~queue_size`` 5, ``~exact_sync`` false) ->
  ``depth_registered/points``: organised (image height x width), x y z rgb float32 at 0, 4, 8, 16 in a
  32-byte point, NaN where the depth has no reading, as depth_image_proc lays it out.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ninjemys.idl.loader import get_message_class
from ninjemys.node.run import run_node

#: colour encodings depth_image_proc reads, and where red, green and blue are in a pixel
COLOUR_OFFSETS = {"rgb8": (0, 1, 2, 3), "rgba8": (0, 1, 2, 4), "bgr8": (2, 1, 0, 3), "bgra8": (2, 1, 0, 4)}


def image_array(msg: Any) -> np.ndarray:
    """An Image's pixels as (height, width[, channels]) without a copy where the rows are packed."""
    channels = {"mono8": 1, "8UC1": 1, "16UC1": 1, "mono16": 1, "32FC1": 1}.get(msg.encoding)
    dtype = {"16UC1": "<u2", "mono16": "<u2", "32FC1": "<f4"}.get(msg.encoding, "u1")
    if channels is None:
        if msg.encoding not in COLOUR_OFFSETS:
            raise ValueError(
                f"encoding '{msg.encoding}' is not one of mono8, 16UC1, 32FC1, {', '.join(COLOUR_OFFSETS)}"
            )
        channels = COLOUR_OFFSETS[msg.encoding][3]
    size = np.dtype(dtype).itemsize * channels
    flat = np.frombuffer(msg.data, dtype=np.uint8)
    if msg.step < msg.width * size or len(flat) < msg.step * msg.height:
        raise ValueError(
            f"{msg.width}x{msg.height} {msg.encoding} needs step >= {msg.width * size} and "
            f"{msg.width * size * msg.height} bytes; got step {msg.step}, {len(flat)} bytes"
        )
    rows = flat[: msg.step * msg.height].reshape(msg.height, msg.step)[:, : msg.width * size]
    pixels = rows.copy().view(dtype) if dtype != "u1" else rows
    return (
        pixels.reshape(msg.height, msg.width, channels)
        if channels > 1
        else pixels.reshape(msg.height, msg.width)
    )


def xyzrgb_points(depth: np.ndarray, colour: np.ndarray, encoding: str, k: tuple[float, ...]) -> np.ndarray:
    """depth_image_proc's cloud: (H*W, 32) bytes, x y z in metres in the colour optical frame (from
    pixel (u, v) and the colour camera's K), rgb packed B, G, R, 0; NaN x y z where depth is 0/NaN.
    A colour image an integer multiple of the depth's size is sampled every n-th pixel, as there."""
    h, w = depth.shape
    ch, cw = colour.shape[:2]
    if ch % h or cw % w or ch // h != cw // w:
        raise ValueError(f"depth resolution {w}x{h} does not match RGB resolution {cw}x{ch}")
    step = ch // h
    fx, cx, fy, cy = k[0], k[2], k[4], k[5]
    z = depth.astype(np.float32) * np.float32(0.001) if depth.dtype == np.uint16 else depth.astype(np.float32)
    invalid = ~np.isfinite(z) | (z == 0)
    u = np.arange(w, dtype=np.float32)[None, :] * step
    v = np.arange(h, dtype=np.float32)[:, None] * step
    x = (u - np.float32(cx)) * z / np.float32(fx)
    y = (v - np.float32(cy)) * z / np.float32(fy)
    out = np.zeros((h * w, 32), np.uint8)
    xyz = np.stack([x, y, z], axis=-1).reshape(-1, 3).astype(np.float32)
    xyz[invalid.reshape(-1)] = np.nan
    out[:, :12] = xyz.view(np.uint8).reshape(-1, 12)
    r, g, b, _ = COLOUR_OFFSETS[encoding]
    px = colour[::step, ::step].reshape(h * w, -1)
    out[:, 16], out[:, 17], out[:, 18] = px[:, b], px[:, g], px[:, r]
    return out


def rectify(image: np.ndarray, info: Any) -> np.ndarray:
    """image_proc's rectification: undistort with K, D, R, P (bilinear); no distortion: the image."""
    if not any(info.D) and list(info.R) in ([], [1, 0, 0, 0, 1, 0, 0, 0, 1]):
        return image
    import cv2

    k = np.array(info.K, np.float64).reshape(3, 3)
    r = np.array(info.R, np.float64).reshape(3, 3)
    p = np.array(info.P, np.float64).reshape(3, 4)
    maps = cv2.initUndistortRectifyMap(
        k, np.array(info.D, np.float64), r, p, (info.width, info.height), cv2.CV_32FC1
    )
    return cv2.remap(image, maps[0], maps[1], cv2.INTER_LINEAR)


def _image(cls: Any, header: Any, pixels: np.ndarray, encoding: str) -> Any:
    msg = cls()
    msg.header = header
    msg.height, msg.width = pixels.shape[0], pixels.shape[1]
    msg.encoding = encoding
    msg.step = msg.width * (pixels.shape[2] if pixels.ndim == 3 else 1)
    msg.data = np.ascontiguousarray(pixels).reshape(-1)
    return msg


def image_proc_main(argv: list[str] | None = None) -> int:
    """``rosrun image_proc image_proc``: colour and mono, raw and rectified, from a colour camera."""
    Image = get_message_class("sensor_msgs/Image")  # noqa: N806 - ROS names
    CameraInfo = get_message_class("sensor_msgs/CameraInfo")  # noqa: N806

    def build(node: Any) -> int:
        from ninjemys.message_filters import Subscriber, TimeSynchronizer

        pubs = {
            k: node.publisher(k, Image, queue_size=1)
            for k in ("image_color", "image_mono", "image_rect_color", "image_rect")
        }

        def on_frame(img: Any, info: Any) -> None:
            try:
                pixels = image_array(img)
            except ValueError as exc:
                node.log.error("image_raw: %s", exc)
                return
            if img.encoding not in COLOUR_OFFSETS:
                node.log.error("image_raw: %s is not a colour image (rgb8, bgr8, rgba8, bgra8)", img.encoding)
                return
            r, g, b, _ = COLOUR_OFFSETS[img.encoding]
            colour = pixels[..., [r, g, b]]
            mono = (0.299 * colour[..., 0] + 0.587 * colour[..., 1] + 0.114 * colour[..., 2] + 0.5).astype(
                np.uint8
            )
            outputs = {"image_color": (colour, "rgb8"), "image_mono": (mono, "mono8")}
            for key, (src, enc) in {
                "image_rect_color": outputs["image_color"],
                "image_rect": outputs["image_mono"],
            }.items():
                if pubs[key].get_num_connections():
                    pubs[key].publish(_image(Image, img.header, rectify(src, info), enc))
            for key, (src, enc) in outputs.items():
                if pubs[key].get_num_connections():
                    pubs[key].publish(_image(Image, img.header, src, enc))

        sync = TimeSynchronizer(
            [Subscriber(node, "image_raw", Image), Subscriber(node, "camera_info", CameraInfo)], 5
        )
        sync.registerCallback(on_frame)
        return 0

    return run_node("image_proc", argv, build)


def point_cloud_xyzrgb_main(argv: list[str] | None = None) -> int:
    """depth_image_proc/point_cloud_xyzrgb as a node (see the module docstring)."""
    Image = get_message_class("sensor_msgs/Image")  # noqa: N806 - ROS names
    CameraInfo = get_message_class("sensor_msgs/CameraInfo")  # noqa: N806
    PointCloud2 = get_message_class("sensor_msgs/PointCloud2")  # noqa: N806
    PointField = get_message_class("sensor_msgs/PointField")  # noqa: N806

    def build(node: Any) -> int:
        from ninjemys.message_filters import ApproximateTimeSynchronizer, Subscriber, TimeSynchronizer

        queue = int(node.get_param("~queue_size", 5))
        exact = bool(node.get_param("~exact_sync", False))
        pub = node.publisher("depth_registered/points", PointCloud2, queue_size=1)
        fields = [
            PointField(name=n, offset=o, datatype=7, count=1)
            for n, o in (("x", 0), ("y", 4), ("z", 8), ("rgb", 16))
        ]

        def on_frame(depth: Any, colour: Any, info: Any) -> None:
            try:
                points = xyzrgb_points(
                    image_array(depth), image_array(colour), colour.encoding, tuple(info.K)
                )
            except (ValueError, KeyError) as exc:
                node.log.error("point_cloud_xyzrgb: %s", exc)
                return
            cloud = PointCloud2(header=depth.header, height=depth.height, width=depth.width, fields=fields)
            cloud.header.frame_id = colour.header.frame_id  # registered: the colour camera's frame
            cloud.is_bigendian, cloud.point_step, cloud.row_step = False, 32, 32 * depth.width
            cloud.is_dense = False
            cloud.data = points.reshape(-1)
            pub.publish(cloud)

        subs = [
            Subscriber(node, "depth_registered/image_rect", Image),
            Subscriber(node, "rgb/image_rect_color", Image),
            Subscriber(node, "rgb/camera_info", CameraInfo),
        ]
        # C++'s ApproximateTime has no slop: a tenth of a second pairs a camera's frames (30 Hz and up)
        sync = TimeSynchronizer(subs, queue) if exact else ApproximateTimeSynchronizer(subs, queue, 0.1)
        sync.registerCallback(on_frame)
        return 0

    return run_node("point_cloud_xyzrgb", argv, build)
