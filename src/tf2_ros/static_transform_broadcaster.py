"""``tf2_ros.static_transform_broadcaster``, ROS 1's module path (the classes live in the package, :mod:`tf2_ros`)."""

from tf2_ros import StaticTransformBroadcaster, _lazy_messages

__all__ = ["StaticTransformBroadcaster", "TFMessage", "TransformStamped"]  # noqa: F822 (loaded by __getattr__)

# the message classes load on first use
__getattr__, __dir__ = _lazy_messages(__name__, ("TFMessage", "TransformStamped"))
