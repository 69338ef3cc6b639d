"""``tf2_ros.buffer_interface``, ROS 1's module path (the classes live in the package, :mod:`tf2_ros`)."""

from tf2_ros import (
    BufferInterface,
    ConvertRegistration,
    NotImplementedException,
    Stamped,
    TransformRegistration,
    TypeException,
    _lazy_messages,
    convert,
)

__all__ = [
    "BufferInterface",
    "ConvertRegistration",
    "Header",  # noqa: F822 (loaded by __getattr__)
    "NotImplementedException",
    "Stamped",
    "TransformRegistration",
    "TypeException",
    "convert",
]

# the message classes load on first use
__getattr__, __dir__ = _lazy_messages(__name__, ("Header",))
