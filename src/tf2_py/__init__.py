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


__all__ = [
    "BufferCore",
    "ConnectivityException",
    "ExtrapolationException",
    "InvalidArgumentException",
    "LookupException",
    "TimeoutException",
    "TransformException",
]
