"""``tf2_ros.buffer``, ROS 1's module path (the classes live in the package, :mod:`tf2_ros`)."""

from tf2_ros import Buffer

__all__ = ["Buffer"]
