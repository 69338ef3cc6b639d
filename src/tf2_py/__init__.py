"""ROS 1's ``tf2_py`` (the buffer core's Python names) over :mod:`ninjemys.tf2`."""

from __future__ import annotations

from typing import Any

from ninjemys.tf2.buffer import Buffer as _Buffer
from ninjemys.tf2.errors import (
    ConnectivityException,
    ExtrapolationException,
    InvalidArgumentException,
    LookupException,
    TimeoutException,
    TransformException,
)


class BufferCore(_Buffer):
    """``tf2_py.BufferCore(cache_time=rospy.Duration(10))``: set_transform, lookup_transform_core, ..."""

    def __init__(self, cache_time: Any = None) -> None:
        super().__init__(cache_time)

    def set_transform(self, transform: Any, authority: str = "default_authority") -> None:
        """Insert a ``TransformStamped``; a bad one is reported in one line and dropped (None either way,
        as ROS 1's C++ method returns)."""
        _Buffer.set_transform(self, transform, authority)

    def set_transform_static(self, transform: Any, authority: str = "default_authority") -> None:
        """Insert a ``TransformStamped`` that holds for all time (None, as in ROS 1)."""
        _Buffer.set_transform_static(self, transform, authority)


__all__ = [
    "BufferCore",
    "ConnectivityException",
    "ExtrapolationException",
    "InvalidArgumentException",
    "LookupException",
    "TimeoutException",
    "TransformException",
]
