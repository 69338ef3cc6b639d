"""The simulator's messages, built from simulation state: pure functions, no node, no publishing.

Each builder takes a stamp, the frame names and the numbers, and returns a ROS message object, so
the node decides only *when* and *where* to publish and these can be tested on their own. Frame and
topic names come from the robot's :class:`~ninjemys.sim.robot_model.RobotModel` (our PuzzleBot's
defaults, or what a description's Gazebo plugins say).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from ninjemys.idl.loader import get_message_class
from ninjemys.rostime import Time
from ninjemys.sim.robot_model import CameraSpec, ImuSpec, LaserSpec, RobotModel
from ninjemys.sim.simcore import scan_angles
from ninjemys.tf2.math import Quaternion, quaternion_from_rpy, quaternion_from_yaw

#: a planar pose (x, y, yaw) and a planar twist (v, w)
Pose2D = tuple[float, float, float]
Twist2D = tuple[float, float]

TransformStamped: Any = get_message_class("geometry_msgs/TransformStamped")
JointState: Any = get_message_class("sensor_msgs/JointState")
Odometry: Any = get_message_class("nav_msgs/Odometry")
LaserScan: Any = get_message_class("sensor_msgs/LaserScan")
Image: Any = get_message_class("sensor_msgs/Image")
CameraInfo: Any = get_message_class("sensor_msgs/CameraInfo")
Imu: Any = get_message_class("sensor_msgs/Imu")

#: camera_link -> optical frame: z forward, x right, y down (rpy -pi/2, 0, -pi/2, as camera drivers publish)
OPTICAL_RPY = (-math.pi / 2, 0.0, -math.pi / 2)


def stamp_of(steps: int, dt: float) -> Time:
    """Sim time after ``steps`` steps of ``dt``: whole steps, so stamps never drift."""
    ns = round(steps * dt * 1e9)
    return Time(ns // 1_000_000_000, ns % 1_000_000_000)


def transform(
    stamp: Time,
    parent: str,
    child: str,
    xyz: tuple[float, float, float],
    quaternion: tuple[float, float, float, float],
) -> Any:
    t = TransformStamped()
    t.header.stamp = stamp
    t.header.frame_id = parent
    t.child_frame_id = child
    t.transform.translation.x, t.transform.translation.y, t.transform.translation.z = xyz
    q = t.transform.rotation
    q.x, q.y, q.z, q.w = quaternion
    return t


def transform_into(
    t: Any, stamp: Time, xyz: tuple[float, float, float], quaternion: tuple[float, float, float, float]
) -> Any:
    """``t`` (made by :func:`transform`, same frames) at a new stamp and pose: the odometry's
    transform goes out at 100 Hz, its nested message is refreshed in place (see :func:`odometry_into`)."""
    t.header.stamp = stamp
    tr = t.transform.translation
    tr.x, tr.y, tr.z = xyz
    q = t.transform.rotation
    q.x, q.y, q.z, q.w = quaternion
    return t


def static_transforms(model: RobotModel, prefix: str, stamp: Time) -> list[Any]:
    """base frame -> each sensor's frame, and the camera's link -> the optical frames its images name."""
    base = model.drive.base_frame
    pairs: list[tuple[str, str, tuple[float, float, float], tuple[float, float, float]]] = []
    for spec in (model.laser, model.camera, model.imu):
        if spec is not None:
            pairs.append((base, spec.pose.frame, spec.pose.xyz, spec.pose.rpy))
    cam = model.camera
    if cam is not None:
        children = [cam.frame] + ([cam.depth_frame] if cam.depth_topic else [])
        for child in dict.fromkeys(children):  # one transform per frame (a colour-only camera: one)
            if child != cam.pose.frame:
                pairs.append((cam.pose.frame, child, (0.0, 0.0, 0.0), OPTICAL_RPY))
    return [
        transform(stamp, prefix + parent, prefix + child, xyz, quaternion_from_rpy(*rpy))
        for parent, child, xyz, rpy in pairs
    ]


def _covariance(diagonal: Sequence[float]) -> list[float]:
    out = [0.0] * 36
    for i, v in enumerate(diagonal):
        out[i * 7] = v
    return out


def odometry(
    stamp: Time,
    frame: str,
    child: str,
    pose: tuple[float, float, float],
    twist: tuple[float, float],
    alpha: tuple[float, float, float, float] | None = None,
) -> Any:
    """nav_msgs/Odometry at (x, y, yaw) moving at (v, w); ``alpha`` (amcl's noise) sets the
    covariance of an odometry estimate, None gives ground truth (no covariance)."""
    msg = Odometry()
    msg.header.frame_id = frame
    msg.child_frame_id = child
    odometry_into(msg, stamp, pose, twist)
    if alpha is not None:
        a1, _a2, a3, _a4 = alpha
        var_xy = 1e-4 + a3 * 0.01
        var_yaw = 1e-4 + a1 * 0.01
        msg.pose.covariance = _covariance((var_xy, var_xy, 1e6, 1e6, 1e6, var_yaw))
        msg.twist.covariance = msg.pose.covariance
    return msg


def odometry_into(
    msg: Any, stamp: Time, pose: Pose2D, twist: Twist2D, quaternion: Quaternion | None = None
) -> Any:
    """``msg`` (made by :func:`odometry`, same frames and covariance) at a new stamp, pose and twist
    (``quaternion``: the pose's yaw as a quaternion, when the caller has it already for /tf).

    A robot's odometry goes out at 100 Hz: its nested message (ten objects) is built once and
    refreshed in place, which publishing allows (a message is serialized when published)."""
    msg.header.stamp = stamp
    p = msg.pose.pose
    p.position.x, p.position.y = pose[0], pose[1]
    o = p.orientation
    o.x, o.y, o.z, o.w = quaternion_from_yaw(pose[2]) if quaternion is None else quaternion
    msg.twist.twist.linear.x = twist[0]
    msg.twist.twist.angular.z = twist[1]
    return msg


def joint_state(stamp: Time, names: list[str], positions: list[float], velocities: list[float]) -> Any:
    js = JointState()
    js.header.stamp = stamp
    js.name = names
    js.position = positions
    js.velocity = velocities
    return js


def joint_state_into(js: Any, stamp: Time, positions: list[float], velocities: list[float]) -> Any:
    """``js`` (made by :func:`joint_state`, same joints) at a new stamp, positions and velocities."""
    js.header.stamp = stamp
    js.position = positions
    js.velocity = velocities
    return js


def laser_scan(stamp: Time, frame: str, spec: LaserSpec, ranges: np.ndarray) -> Any:
    amin, amax, inc = scan_angles(spec)
    msg = LaserScan()
    msg.header.stamp = stamp
    msg.header.frame_id = frame
    msg.angle_min = amin
    msg.angle_max = amax
    msg.angle_increment = inc
    msg.time_increment = 0.0  # every ray at once, as Gazebo's instantaneous scan
    msg.scan_time = 0.0 if spec.gazebo_fields else 1.0 / spec.rate
    msg.range_min = spec.range_min
    msg.range_max = spec.range_max
    msg.ranges = ranges
    msg.intensities = np.zeros(len(ranges), np.float32) if spec.gazebo_fields else []
    return msg


def imu(stamp: Time, frame: str, spec: ImuSpec, reading: tuple[float, float, float, float]) -> Any:
    """sensor_msgs/Imu from (yaw, yaw rate, ax, ay); gravity on z, as a level IMU at rest reads."""
    yaw, wz, ax, ay = reading
    msg = Imu()
    msg.header.stamp = stamp
    msg.header.frame_id = frame
    o = msg.orientation
    o.x, o.y, o.z, o.w = quaternion_from_yaw(yaw)
    msg.angular_velocity.z = wz
    msg.linear_acceleration.x, msg.linear_acceleration.y, msg.linear_acceleration.z = ax, ay, 9.80665
    g, a = max(spec.gyro_noise**2, 1e-9), max(spec.accel_noise**2, 1e-9)
    msg.orientation_covariance = [1e-4, 0, 0, 0, 1e-4, 0, 0, 0, 1e-4]
    msg.angular_velocity_covariance = [g, 0, 0, 0, g, 0, 0, 0, g]
    msg.linear_acceleration_covariance = [a, 0, 0, 0, a, 0, 0, 0, a]
    return msg


def rgb_image(stamp: Time, frame: str, rgb: np.ndarray, img: Any = None) -> Any:
    """rgb8; ``img``: the Image to fill (a publisher's loan, whose data ``rgb`` was drawn into)."""
    if img is None:
        img = Image()
    img.header.stamp = stamp
    img.header.frame_id = frame
    img.height, img.width = rgb.shape[0], rgb.shape[1]
    img.encoding = "rgb8"
    img.is_bigendian = 0
    img.step = rgb.shape[1] * 3
    img.data = rgb.reshape(-1)  # a view: uint8[] fields take numpy arrays without a copy
    return img


def depth_image(stamp: Time, frame: str, depth: np.ndarray, d: Any = None) -> Any:
    """16UC1 in millimetres, as RGB-D drivers publish ``depth/image_rect_raw``; ``d``: the Image to
    fill (a publisher's loan, whose data ``depth`` was drawn into)."""
    if d is None:
        d = Image()
    d.header.stamp = stamp
    d.header.frame_id = frame
    d.height, d.width = depth.shape[0], depth.shape[1]
    d.encoding = "16UC1"
    d.is_bigendian = 0
    d.step = depth.shape[1] * 2
    d.data = depth.astype("<u2", copy=False).view(np.uint8).reshape(-1)
    return d


def camera_info(
    stamp: Time, frame: str, spec: CameraSpec, intrinsics: tuple[float, float, float, float]
) -> Any:
    fx, fy, cx, cy = intrinsics
    info = CameraInfo()
    info.header.stamp = stamp
    info.header.frame_id = frame
    info.height, info.width = spec.height, spec.width
    info.distortion_model = "plumb_bob"
    info.D = [0.0, 0.0, 0.0, 0.0, 0.0]
    info.K = [fx, 0.0, cx, 0.0, fy, cy, 0.0, 0.0, 1.0]
    info.R = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]
    info.P = [fx, 0.0, cx, -fx * spec.hack_baseline, 0.0, fy, cy, 0.0, 0.0, 0.0, 1.0, 0.0]
    return info
