"""``tf2_geometry_msgs.tf2_geometry_msgs`` (ROS 1's module path): the conversions, and their registration
with ``tf2_ros.Buffer.transform()`` when imported; the code lives in :mod:`ninjemys.tf2.geometry`."""

from __future__ import annotations

from typing import Any

from geometry_msgs.msg import PointStamped, PoseStamped, Vector3Stamped, WrenchStamped
from ninjemys.tf2.buffer import ConvertRegistration, TransformRegistration
from ninjemys.tf2.geometry import (
    do_transform_point,
    do_transform_pose,
    do_transform_pose_stamped,
    do_transform_pose_with_covariance_stamped,
    do_transform_vector3,
    do_transform_wrench,
    register,
)

register(TransformRegistration(), ConvertRegistration())


def to_msg_msg(msg: Any) -> Any:
    """A stamped geometry_msgs message is its own message form (the ``to_msg`` conversion)."""
    return msg


def from_msg_msg(msg: Any) -> Any:
    """The ``from_msg`` conversion of a stamped geometry_msgs message: the message itself."""
    return msg


__all__ = [
    "PointStamped",
    "PoseStamped",
    "Vector3Stamped",
    "WrenchStamped",
    "do_transform_point",
    "do_transform_pose",
    "do_transform_pose_stamped",
    "do_transform_pose_with_covariance_stamped",
    "do_transform_vector3",
    "do_transform_wrench",
    "from_msg_msg",
    "to_msg_msg",
]
