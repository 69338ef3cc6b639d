"""``tf2_ros.buffer``, ROS 1's module path (the classes live in the package, :mod:`tf2_ros`)."""

from tf2_msgs.srv import FrameGraph, FrameGraphResponse
from tf2_ros import DEFAULT_CAN_TRANSFORM_POLLING_SCALE, Buffer

__all__ = ["DEFAULT_CAN_TRANSFORM_POLLING_SCALE", "Buffer", "FrameGraph", "FrameGraphResponse"]
