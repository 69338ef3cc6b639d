"""``tf2_ros.buffer_interface``, ROS 1's module path (the classes live in the package, :mod:`tf2_ros`)."""

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
    "NotImplementedException",
    "Stamped",
    "TransformRegistration",
    "TypeException",
    "convert",
]
