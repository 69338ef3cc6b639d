"""``tf2_ros.buffer_interface``, ROS 1's module path (the classes live in the package, :mod:`tf2_ros`)."""

from std_msgs.msg import Header
from tf2_ros import (
    BufferInterface,
    ConvertRegistration,
    NotImplementedException,
    Stamped,
    TransformRegistration,
    TypeException,
    convert,
)

__all__ = [
    "BufferInterface",
    "ConvertRegistration",
    "Header",
    "NotImplementedException",
    "Stamped",
    "TransformRegistration",
    "TypeException",
    "convert",
]
