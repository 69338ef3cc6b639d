"""``tf2_ros.transform_broadcaster``, ROS 1's module path (the classes live in the package, :mod:`tf2_ros`)."""

from tf2_ros import TransformBroadcaster

__all__ = ["TransformBroadcaster"]
