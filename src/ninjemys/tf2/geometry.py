"""tf2_geometry_msgs' conversions: geometry_msgs stamped types through a ``TransformStamped``.

Each ``do_transform_*`` returns a new message whose header is the transform's (target frame, the
lookup's stamp), as ROS 1's tf2_geometry_msgs does; the math is :mod:`ninjemys.tf2.math` on tuples
(ROS 1 goes through PyKDL).
"""

from __future__ import annotations

from typing import Any

from ninjemys.idl.loader import get_message_class
from ninjemys.tf2 import math as tfm
from ninjemys.tf2.buffer import transform_tuple


def _cls(name: str) -> Any:
    return get_message_class(f"geometry_msgs/{name}")


def _header(transform: Any) -> Any:
    h = transform.header
    return get_message_class("std_msgs/Header")(h.seq, h.stamp, h.frame_id)


def _point(t: tuple, p: Any) -> tuple[float, float, float]:
    return tfm.transform_point(t, p.x, p.y, p.z)


def _pose(t: tuple, pose: Any) -> Any:
    """A ``geometry_msgs/Pose`` moved by the 7-tuple ``t``."""
    o = pose.orientation
    q = tfm.quaternion_multiply((t[3], t[4], t[5], t[6]), (o.x, o.y, o.z, o.w))
    x, y, z = _point(t, pose.position)
    return _cls("Pose")(_cls("Point")(x, y, z), _cls("Quaternion")(*q))


def do_transform_point(point: Any, transform: Any) -> Any:
    """``geometry_msgs/PointStamped`` into the transform's target frame."""
    x, y, z = _point(transform_tuple(transform.transform), point.point)
    return _cls("PointStamped")(_header(transform), _cls("Point")(x, y, z))


def do_transform_vector3(vector3: Any, transform: Any) -> Any:
    """``geometry_msgs/Vector3Stamped``: rotated only (a direction has no position)."""
    t = transform_tuple(transform.transform)
    v = vector3.vector
    x, y, z = tfm.rotate_vector(t[3], t[4], t[5], t[6], v.x, v.y, v.z)
    return _cls("Vector3Stamped")(_header(transform), _cls("Vector3")(x, y, z))


def do_transform_pose_stamped(pose: Any, transform: Any) -> Any:
    """``geometry_msgs/PoseStamped`` into the transform's target frame."""
    return _cls("PoseStamped")(_header(transform), _pose(transform_tuple(transform.transform), pose.pose))


def do_transform_pose(pose: Any, transform: Any) -> Any:
    """A ``Pose`` (returns a Pose, as newer geometry2 does) or a ``PoseStamped`` (returns a PoseStamped,
    as Noetic's 0.7.x tf2_geometry_msgs does)."""
    if hasattr(pose, "header"):
        return do_transform_pose_stamped(pose, transform)
    return _pose(transform_tuple(transform.transform), pose)


def do_transform_pose_with_covariance_stamped(pose: Any, transform: Any) -> Any:
    """``geometry_msgs/PoseWithCovarianceStamped``: the pose moved, the 6x6 covariance rotated."""
    import numpy as np

    t = transform_tuple(transform.transform)
    moved = _pose(t, pose.pose.pose)
    qx, qy, qz, qw = t[3], t[4], t[5], t[6]
    r = np.array(
        [
            [1 - 2 * (qy * qy + qz * qz), 2 * (qx * qy - qz * qw), 2 * (qx * qz + qy * qw)],
            [2 * (qx * qy + qz * qw), 1 - 2 * (qx * qx + qz * qz), 2 * (qy * qz - qx * qw)],
            [2 * (qx * qz - qy * qw), 2 * (qy * qz + qx * qw), 1 - 2 * (qx * qx + qy * qy)],
        ]
    )
    big = np.zeros((6, 6))
    big[:3, :3] = r
    big[3:, 3:] = r
    cov = big @ np.asarray(pose.pose.covariance, dtype=float).reshape(6, 6) @ big.T
    inner = _cls("PoseWithCovariance")(moved, [float(v) for v in cov.ravel()])
    return _cls("PoseWithCovarianceStamped")(_header(transform), inner)


def do_transform_wrench(wrench: Any, transform: Any) -> Any:
    """``geometry_msgs/WrenchStamped``: force and torque rotated (ROS 1's tf2_geometry_msgs does the same)."""
    t = transform_tuple(transform.transform)
    f = wrench.wrench.force
    m = wrench.wrench.torque
    force = _cls("Vector3")(*tfm.rotate_vector(t[3], t[4], t[5], t[6], f.x, f.y, f.z))
    torque = _cls("Vector3")(*tfm.rotate_vector(t[3], t[4], t[5], t[6], m.x, m.y, m.z))
    return _cls("WrenchStamped")(_header(transform), _cls("Wrench")(force, torque))


def register(registration: Any, conversions: Any) -> None:
    """Register the stamped types with tf2_ros's registries (what ``import tf2_geometry_msgs`` does)."""
    for name, fn in (
        ("PointStamped", do_transform_point),
        ("Vector3Stamped", do_transform_vector3),
        ("PoseStamped", do_transform_pose_stamped),
        ("PoseWithCovarianceStamped", do_transform_pose_with_covariance_stamped),
        ("WrenchStamped", do_transform_wrench),
    ):
        cls = _cls(name)
        registration.add(cls, fn)
        conversions.add_to_msg(cls, _same)
        conversions.add_from_msg(cls, _same)


def _same(msg: Any) -> Any:
    return msg


__all__ = [
    "do_transform_point",
    "do_transform_vector3",
    "do_transform_pose",
    "do_transform_pose_stamped",
    "do_transform_pose_with_covariance_stamped",
    "do_transform_wrench",
    "register",
]
