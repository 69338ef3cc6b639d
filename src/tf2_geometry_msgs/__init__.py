"""ROS 1's ``tf2_geometry_msgs``: importing it registers the geometry_msgs stamped types with
``tf2_ros.Buffer.transform()``; the conversions live in :mod:`ninjemys.tf2.geometry`."""

from __future__ import annotations

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

__all__ = [
    "do_transform_point",
    "do_transform_pose",
    "do_transform_pose_stamped",
    "do_transform_pose_with_covariance_stamped",
    "do_transform_vector3",
    "do_transform_wrench",
]
