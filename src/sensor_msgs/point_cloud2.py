"""ROS 1's ``sensor_msgs.point_cloud2``: ``read_points``, ``read_points_list``, ``create_cloud`` and
``create_cloud_xyz32`` for ``sensor_msgs/PointCloud2``; the code is :mod:`ninjemys.laser_geometry.point_cloud2`."""

from __future__ import annotations

from typing import Any

from ninjemys.laser_geometry.point_cloud2 import DATATYPES as _DATATYPES  # noqa: F401 - ROS 1's private name
from ninjemys.laser_geometry.point_cloud2 import (
    create_cloud,
    create_cloud_xyz32,
    read_points,
    read_points_list,
    struct_format,
)
from sensor_msgs.msg import PointCloud2, PointField

__all__ = [
    "PointCloud2",
    "PointField",
    "create_cloud",
    "create_cloud_xyz32",
    "read_points",
    "read_points_list",
]


def _get_struct_fmt(is_bigendian: bool, fields: Any, field_names: Any = None) -> str:
    """ROS 1's name for the ``struct`` format of one point (some programs call it)."""
    return struct_format(is_bigendian, fields, field_names)
