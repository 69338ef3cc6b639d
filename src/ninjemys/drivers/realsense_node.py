"""``roslaunch realsense2_camera rs_camera.launch``: an Intel RealSense D400 on ROS, as realsense2_camera.

Built on ``pyrealsense2`` (``pip install pyrealsense2``; x86_64 wheels on PyPI, see docs/drivers.md).
Live devices are found by ``~serial_no`` (else the first one); ``~rosbag_filename`` plays a recording
(librealsense's ``.bag``, or the ``.db3`` its recorder writes since 2.57) through pyrealsense2's
playback instead, which is how the driver is tested without a camera.

Topics, relative to the node's namespace (``camera`` in rs_camera.launch), each published only while
someone listens, as ROS 1 does: ``color/image_raw`` (rgb8) and ``depth/image_rect_raw`` (16UC1, or
rgb8 with the ``colorizer`` filter) with their ``camera_info``; ``aligned_depth_to_color/image_raw``
and its ``camera_info`` (``~align_depth``); ``depth/color/points`` (``~enable_pointcloud`` or the
``pointcloud`` filter; ``~ordered_pc``, ``~allow_no_texture_points``); the latched
``extrinsics/depth_to_color``; ``infra1``/``infra2`` when enabled and present. Static transforms from
``~base_frame_id`` (``camera_link``) to each stream's frame and optical frame (``~publish_tf``; on
``/tf`` at ``~tf_publish_rate`` when it is positive). ``~filters``: decimation, disparity, spatial,
temporal, hole_filling, hdr_merge, colorizer, pointcloud, applied in realsense2_camera's order.
``~clip_distance`` (m) zeroes farther depth. Services: ``enable`` (std_srvs/SetBool) and
``~device_info``.
"""

from __future__ import annotations

import sys
import time
from dataclasses import dataclass
from typing import Any

import numpy as np

from ninjemys.drivers.realsense_msgs import (
    Intrinsics,
    StaticTransform,
    camera_info_fields,
    clip_depth,
    point_cloud,
    stream_transforms,
)
from ninjemys.idl.loader import get_message_class, get_service_class
from ninjemys.node.run import run_node
from ninjemys.rostime import Time


def _msg(type_name: str) -> Any:
    """A message class, typed loosely: its fields are generated at run time."""
    return get_message_class(type_name)


def _srv(type_name: str) -> Any:
    """A service class, typed loosely: its parts are generated at run time."""
    return get_service_class(type_name)


NOT_INSTALLED = "realsense2_camera: pyrealsense2 is not installed (pip install pyrealsense2): no RealSense camera can be read"
KNOWN_FILTERS = (
    "colorizer",
    "disparity",
    "spatial",
    "temporal",
    "hole_filling",
    "decimation",
    "pointcloud",
    "hdr_merge",
)
_WAIT_MS = 200  # one wait for frames; the loop looks at shutdown in between


@dataclass
class StreamConfig:
    """One stream as the parameters ask for it (``name`` as in the topics: depth, color, infra1...)."""

    name: str
    enabled: bool
    width: int
    height: int
    fps: int
    frame_id: str
    optical_frame_id: str


class RealSenseCamera:
    """The node's state: parameters, publishers, the pipeline and the filters."""

    def __init__(self, node: Any, rs: Any) -> None:
        self.node, self.rs, self.log = node, rs, node.log
        p = lambda key, default: node.get_param(f"~{key}", default)  # noqa: E731
        self.serial_no = str(p("serial_no", ""))
        self.rosbag_filename = str(p("rosbag_filename", ""))
        self.align_depth = bool(p("align_depth", False))
        self.ordered_pc = bool(p("ordered_pc", False))
        self.allow_no_texture_points = bool(p("allow_no_texture_points", False))
        self.publish_tf = bool(p("publish_tf", True))
        self.tf_publish_rate = float(p("tf_publish_rate", 0.0))
        self.clip_distance = float(p("clip_distance", -1.0))
        self.reconnect_timeout = float(p("reconnect_timeout", 6.0))
        self.wait_for_device_timeout = float(p("wait_for_device_timeout", -1.0))
        self.base_frame_id = str(p("base_frame_id", "camera_link"))
        self.filters = [f.strip() for f in str(p("filters", "")).split(",") if f.strip()]
        self.pointcloud = bool(p("enable_pointcloud", False)) or "pointcloud" in self.filters
        self.texture = str(p("pointcloud_texture_stream", "RS2_STREAM_COLOR"))
        self.streams = {
            name: StreamConfig(
                name,
                bool(p(f"enable_{name}", name in ("depth", "color"))),
                # 0 or -1 (rs_camera.launch's default): whatever the device or the recording offers
                max(0, int(p(f"{'infra' if name.startswith('infra') else name}_width", 640))),
                max(0, int(p(f"{'infra' if name.startswith('infra') else name}_height", 480))),
                max(0, int(p(f"{'infra' if name.startswith('infra') else name}_fps", 30))),
                str(p(f"{name}_frame_id", f"camera_{name}_frame")),
                str(p(f"{name}_optical_frame_id", f"camera_{name}_optical_frame")),
            )
            for name in ("depth", "color", "infra1", "infra2")
        }
        if bool(p("enable_infra", False)):
            self.streams["infra1"].enabled = self.streams["infra2"].enabled = True
        self.aligned_frame_id = str(
            p("aligned_depth_to_color_frame_id", "camera_aligned_depth_to_color_frame")
        )
        self.Image = _msg("sensor_msgs/Image")
        self.CameraInfo = _msg("sensor_msgs/CameraInfo")
        self.seq: dict[str, int] = {}
        self.streaming = True
        self.pipeline: Any = None
        self.device: Any = None
        self.pubs: dict[str, Any] = {}
        self.first_stamp: tuple[float, float] | None = None  # (ros time, camera ms) for hardware clocks

    # -- set-up -----------------------------------------------------------------------------------

    def check_filters(self) -> bool:
        unknown = [f for f in self.filters if f not in KNOWN_FILTERS]
        if unknown:
            self.log.error("Unknown Filter: %s", unknown[0])
            return False
        return True

    def open(self) -> bool:
        """Start the pipeline on the recording or a live device; False to give up (logged)."""
        rs = self.rs
        self.pipeline = rs.pipeline()
        config = rs.config()
        if self.rosbag_filename:
            self.log.info("publish topics from rosbag file: %s", self.rosbag_filename)
            try:
                config.enable_device_from_file(self.rosbag_filename, False)
                config.enable_all_streams()
                profile = self.pipeline.start(config)
            except RuntimeError as exc:
                self.log.error("An exception has been thrown: %s", exc)
                return False
            self.device = profile.get_device()
            playback = self.device.as_playback()
            playback.set_real_time(True)
            return True
        device = self._wait_for_device()
        if device is None:
            return False
        self.device = device
        config.enable_device(device.get_info(rs.camera_info.serial_number))
        formats = {
            "depth": rs.format.z16,
            "color": rs.format.rgb8,
            "infra1": rs.format.y8,
            "infra2": rs.format.y8,
        }
        kinds = {"depth": (rs.stream.depth, 0), "color": (rs.stream.color, 0), "infra1": (rs.stream.infrared, 1),
                 "infra2": (rs.stream.infrared, 2)}  # fmt: skip
        for name, s in self.streams.items():
            if s.enabled:
                kind, index = kinds[name]
                config.enable_stream(kind, index, s.width, s.height, formats[name], s.fps)
        try:
            self.pipeline.start(config)
        except RuntimeError as exc:
            self.log.error("An exception has been thrown: %s", exc)
            return False
        return True

    def _wait_for_device(self) -> Any:
        rs = self.rs
        first = time.monotonic()
        while not self.node.is_shutdown:
            devices = list(rs.context().query_devices())
            wanted = [
                d
                for d in devices
                if not self.serial_no or d.get_info(rs.camera_info.serial_number) == self.serial_no
            ]
            if wanted:
                d = wanted[0]
                self.log.info(
                    "Device with serial number %s was found.", d.get_info(rs.camera_info.serial_number)
                )
                return d
            if not devices:
                self.log.warn("No RealSense devices were found!")
            else:
                self.log.error(
                    "The requested device with serial number %s is NOT found. Will Try again.", self.serial_no
                )
            wait = self.reconnect_timeout
            if self.wait_for_device_timeout > 0:
                left = self.wait_for_device_timeout - (time.monotonic() - first)
                if left < 0:
                    self.log.error("wait for device timeout of %g secs expired", self.wait_for_device_timeout)
                    return None
                wait = min(wait, left)
            self.node.wait_for_shutdown(wait)
        return None

    def advertise(self, present: set[str]) -> None:
        """Publishers for the streams that are both enabled and delivered, as ROS 1 advertises."""
        n = self.node
        for name in ("depth", "color", "infra1", "infra2"):
            if self.streams[name].enabled and name in present:
                topic = f"{name}/image_rect_raw" if name != "color" else "color/image_raw"
                self.pubs[name] = n.publisher(topic, self.Image, queue_size=1)
                self.pubs[f"{name}_info"] = n.publisher(f"{name}/camera_info", self.CameraInfo, queue_size=1)
        if self.align_depth and {"depth", "color"} <= present:
            self.pubs["aligned"] = n.publisher("aligned_depth_to_color/image_raw", self.Image, queue_size=1)
            self.pubs["aligned_info"] = n.publisher(
                "aligned_depth_to_color/camera_info", self.CameraInfo, queue_size=1
            )
        if self.pointcloud and "depth" in present:
            self.pubs["points"] = n.publisher(
                "depth/color/points", _msg("sensor_msgs/PointCloud2"), queue_size=1
            )
        SetBool = _srv("std_srvs/SetBool")
        n.service("enable", SetBool, self._enable)
        n.service("~device_info", _srv("realsense2_camera/DeviceInfo"), self._device_info)

    def _enable(self, req: Any) -> Any:
        self.streaming = bool(req.data)
        self.log.info("toggling sensor : %s", "ON" if self.streaming else "OFF")
        return _srv("std_srvs/SetBool")._response_class(success=True, message="")

    def _device_info(self, _req: Any) -> Any:
        rs, d = self.rs, self.device
        resp = _srv("realsense2_camera/DeviceInfo")._response_class()

        def info(key: Any) -> str:
            return str(d.get_info(key)) if d.supports(key) else ""

        resp.device_name = info(rs.camera_info.name)
        resp.serial_number = info(rs.camera_info.serial_number)
        resp.firmware_version = info(rs.camera_info.firmware_version)
        resp.usb_type_descriptor = info(rs.camera_info.usb_type_descriptor)
        resp.firmware_update_id = info(rs.camera_info.firmware_update_id)
        resp.sensors = ",".join(s.get_info(rs.camera_info.name) for s in d.query_sensors())
        return resp

    def publish_static(self, profiles: dict[str, Any]) -> None:
        """Static transforms and the depth -> colour extrinsics, once the streams' profiles are known."""
        base = profiles.get("depth") or next(iter(profiles.values()))
        transforms: list[StaticTransform] = []
        for name, profile in profiles.items():
            s = self.streams[name]
            try:
                ex = profile.get_extrinsics_to(base)
                rotation, translation = list(ex.rotation), list(ex.translation)
            except RuntimeError as exc:
                self.log.warn("(%s, 0) -> (depth, 0): %s : using unity as default.", name, exc)
                rotation, translation = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0], [0.0, 0.0, 0.0]
            aligned = self.aligned_frame_id if (self.align_depth and name == "color") else None
            transforms += stream_transforms(
                self.base_frame_id, s.frame_id, s.optical_frame_id, rotation, translation, aligned
            )
        if "depth" in profiles and "color" in profiles:
            Extrinsics = _msg("realsense2_camera/Extrinsics")
            pub = self.node.publisher("extrinsics/depth_to_color", Extrinsics, queue_size=1, latch=True)
            msg = Extrinsics()
            msg.header.frame_id = "depth_to_color_extrinsics"
            try:
                ex = profiles["depth"].get_extrinsics_to(profiles["color"])
                msg.rotation, msg.translation = list(ex.rotation), list(ex.translation)
            except RuntimeError:
                msg.rotation, msg.translation = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0], [0.0, 0.0, 0.0]
            pub.publish(msg)
        if not self.publish_tf or not transforms:
            return
        TFMessage = _msg("tf2_msgs/TFMessage")
        TransformStamped = _msg("geometry_msgs/TransformStamped")
        msgs = []
        for t in transforms:
            m = TransformStamped()
            m.header.stamp = self.node.now()
            m.header.frame_id, m.child_frame_id = t.parent, t.child
            m.transform.translation.x, m.transform.translation.y, m.transform.translation.z = t.translation
            r = m.transform.rotation
            r.x, r.y, r.z, r.w = t.rotation
            msgs.append(m)
        if self.tf_publish_rate > 0:
            self.log.warn("Publishing dynamic camera transforms (/tf) at %g Hz", self.tf_publish_rate)
            tf = self.node.publisher("/tf", TFMessage, queue_size=100)

            def tick(_event: Any) -> None:
                now = self.node.now()
                for m in msgs:
                    m.header.stamp = now
                tf.publish(TFMessage(transforms=msgs))

            self.node.timer(1.0 / self.tf_publish_rate, tick)
        else:
            self.node.publisher("/tf_static", TFMessage, queue_size=100, latch=True).publish(
                TFMessage(transforms=msgs)
            )

    # -- frames -----------------------------------------------------------------------------------

    def run(self) -> int:
        rs = self.rs
        if not self.check_filters() or not self.open():
            return 1
        names = {(rs.stream.depth, 0): "depth", (rs.stream.color, 0): "color", (rs.stream.infrared, 1): "infra1",
                 (rs.stream.infrared, 2): "infra2"}  # fmt: skip
        profiles: dict[str, Any] = {}
        for profile in self.pipeline.get_active_profile().get_streams():
            name = names.get((profile.stream_type(), profile.stream_index()))
            if name is None and profile.stream_type() == rs.stream.infrared:
                name = "infra1"
            if name and self.streams[name].enabled:
                profiles[name] = profile
        self.advertise(set(profiles))
        self.publish_static(profiles)
        chain = self._filters()
        colorizer = rs.colorizer() if "colorizer" in self.filters else None
        align = rs.align(rs.stream.color) if self.align_depth else None
        pc = rs.pointcloud() if self.pointcloud else None
        depth_scale = self._depth_scale()
        ended = False
        while not self.node.is_shutdown:
            try:
                frames = self.pipeline.wait_for_frames(_WAIT_MS)
            except RuntimeError:
                if self.rosbag_filename and not ended and self._playback_stopped():
                    self.log.info("Reached the end of %s.", self.rosbag_filename)
                    ended = True
                continue
            if self.streaming:
                self._publish_frameset(frames, chain, colorizer, align, pc, depth_scale)
        self.pipeline.stop()
        return 0

    def _playback_stopped(self) -> bool:
        try:
            return self.device.as_playback().current_status() == self.rs.playback_status.stopped
        except RuntimeError:
            return True

    def _depth_scale(self) -> float:
        for sensor in self.device.query_sensors():
            if sensor.is_depth_sensor():
                return float(sensor.as_depth_sensor().get_depth_scale())
        return 0.001

    def _filters(self) -> list[Any]:
        """The depth filters in realsense2_camera's order: decimation, hdr_merge, disparity, the listed
        ones as given, back from disparity (colorizer, alignment and the cloud come after)."""
        rs = self.rs
        middle = [{"spatial": rs.spatial_filter, "temporal": rs.temporal_filter, "hole_filling": rs.hole_filling_filter}[f]()
                  for f in self.filters if f in ("spatial", "temporal", "hole_filling")]  # fmt: skip
        chain: list[Any] = []
        if "decimation" in self.filters:
            chain.append(rs.decimation_filter())
        if "hdr_merge" in self.filters:
            chain += [rs.sequence_id_filter(), rs.hdr_merge()]
        if "disparity" in self.filters:
            chain.append(rs.disparity_transform(True))
        chain += middle
        if "disparity" in self.filters:
            chain.append(rs.disparity_transform(False))
        for f in self.filters:
            self.log.info("Add Filter: %s", f)
        return chain

    def _stamp(self, frame: Any) -> Time:
        rs = self.rs
        ms = frame.get_timestamp()
        if frame.get_frame_timestamp_domain() == rs.timestamp_domain.hardware_clock:
            if self.first_stamp is None:
                self.log.warn("frame's time domain is HARDWARE_CLOCK. Timestamps may reset periodically.")
                self.first_stamp = (self.node.now().to_sec(), ms)
            return Time.from_sec(self.first_stamp[0] + (ms - self.first_stamp[1]) / 1000.0)
        return Time.from_sec(ms / 1000.0)

    def _wanted(self, key: str) -> bool:
        pub, info = self.pubs.get(key), self.pubs.get(f"{key}_info")
        return bool((pub and pub.get_num_connections()) or (info and info.get_num_connections()))

    def _publish_frameset(
        self, frames: Any, chain: list[Any], colorizer: Any, align: Any, pc: Any, scale: float
    ) -> None:
        stamp = self._stamp(frames)
        depth = frames.get_depth_frame()
        if depth and self.clip_distance > 0:
            data = np.asanyarray(depth.get_data())
            np.copyto(data, clip_depth(data, self.clip_distance, scale))  # in place, as ROS 1 clips the frame
        for block in chain:  # processing blocks take the frameset and work on its depth frame
            frames = block.process(frames).as_frameset()
        depth = frames.get_depth_frame()
        color = frames.get_color_frame()
        if color and self._wanted("color"):
            self._image("color", color, "rgb8", stamp)
        for name in ("infra1", "infra2"):
            if name in self.pubs and self._wanted(name):
                infra = frames.get_infrared_frame(1 if name == "infra1" else 2)
                if infra:
                    self._image(name, infra, "mono8", stamp)
        aligned = align.process(frames).get_depth_frame() if (depth and color and align is not None) else None
        if depth and self._wanted("depth"):
            out = colorizer.process(depth) if colorizer else depth
            self._image("depth", out, "rgb8" if colorizer else "16UC1", stamp)
        if aligned and self._wanted("aligned"):
            out = colorizer.process(aligned) if colorizer else aligned
            self._image("aligned", out, "rgb8" if colorizer else "16UC1", stamp, info_of=color)
        points_pub = self.pubs.get("points")
        if depth and pc is not None and points_pub is not None and points_pub.get_num_connections():
            source = aligned or depth
            texture = color if (color and self.texture != "RS2_STREAM_ANY") else None
            if texture is not None:
                pc.map_to(texture)
            points = pc.calculate(source)
            vertices = np.asanyarray(points.get_vertices()).view(np.float32).reshape(-1, 3)
            uv = (
                np.asanyarray(points.get_texture_coordinates()).view(np.float32).reshape(-1, 2)
                if texture
                else None
            )
            tex = np.asanyarray(texture.get_data()) if texture else None
            vp = source.get_profile().as_video_stream_profile()
            cloud = point_cloud(vertices, uv, tex, ordered=self.ordered_pc,
                                allow_no_texture_points=self.allow_no_texture_points,
                                shape=(vp.height(), vp.width()))  # fmt: skip
            self._publish_cloud(cloud, stamp, self.streams["color" if aligned else "depth"].optical_frame_id)

    def _image(self, key: str, frame: Any, encoding: str, stamp: Time, info_of: Any = None) -> None:
        """Image and camera_info; ``info_of`` is the colour frame whose intrinsics and optical frame an
        aligned depth image takes."""
        vf = frame.as_video_frame()
        data = np.asanyarray(vf.get_data())
        height, width = vf.get_height(), vf.get_width()
        bpp = vf.get_bytes_per_pixel()
        frame_id = self.streams["color" if info_of is not None else key].optical_frame_id
        self.seq[key] = self.seq.get(key, 0) + 1
        img = self.Image()
        img.header.seq = self.seq[key]
        img.header.stamp = stamp
        img.header.frame_id = frame_id
        img.height, img.width, img.encoding = height, width, encoding
        img.is_bigendian = 0
        img.step = width * bpp
        img.data = np.ascontiguousarray(data).view(np.uint8).reshape(-1)
        self.pubs[key].publish(img)
        i = (info_of or frame).get_profile().as_video_stream_profile().get_intrinsics()
        model = "equidistant" if i.model == self.rs.distortion.kannala_brandt4 else "plumb_bob"
        fields = camera_info_fields(
            Intrinsics(i.width, i.height, i.fx, i.fy, i.ppx, i.ppy, model, tuple(i.coeffs)), frame_id
        )
        info = self.CameraInfo()
        info.header.seq = self.seq[key]
        info.header.stamp = stamp
        info.header.frame_id = fields.pop("frame_id")
        for name, value in fields.items():
            setattr(info, name, value)
        self.pubs[f"{key}_info"].publish(info)

    def _publish_cloud(self, cloud: Any, stamp: Time, frame_id: str) -> None:
        PointCloud2 = _msg("sensor_msgs/PointCloud2")
        PointField = _msg("sensor_msgs/PointField")
        msg = PointCloud2()
        msg.header.stamp = stamp
        msg.header.frame_id = frame_id
        msg.height, msg.width = cloud.height, cloud.width
        msg.fields = [
            PointField(name=name, offset=offset, datatype=PointField.FLOAT32, count=1)
            for name, offset in cloud.fields
        ]
        msg.is_bigendian = False
        msg.point_step = cloud.point_step
        msg.row_step = cloud.point_step * cloud.width
        msg.data = cloud.data
        msg.is_dense = cloud.is_dense
        self.pubs["points"].publish(msg)


def main(argv: list[str] | None = None) -> int:
    """``rosrun realsense2_camera realsense2_camera_node`` (and the node of rs_camera.launch)."""
    try:
        import pyrealsense2 as rs  # type: ignore[import-untyped]  # noqa: PLC0415 - optional, untyped
    except ImportError:
        print(NOT_INSTALLED, file=sys.stderr)
        return 1

    def build(node: Any) -> int:
        node.log.info("RealSense ROS v2.3.2 (ninjemys)")
        node.log.info("Running with LibRealSense v%s", getattr(rs, "__version__", "?"))
        return RealSenseCamera(node, rs).run()

    return run_node("realsense2_camera", argv, build)
