"""``tf2_ros.buffer``, ROS 1's module path (the classes live in the package, :mod:`tf2_ros`)."""

from tf2_ros import DEFAULT_CAN_TRANSFORM_POLLING_SCALE, Buffer, _lazy_messages

__all__ = ["DEFAULT_CAN_TRANSFORM_POLLING_SCALE", "Buffer", "FrameGraph", "FrameGraphResponse"]  # noqa: F822 (loaded by __getattr__)

# the message classes load on first use
__getattr__, __dir__ = _lazy_messages(__name__, ("FrameGraph", "FrameGraphResponse"))
