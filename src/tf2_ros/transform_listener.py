"""``tf2_ros.transform_listener``, ROS 1's module path (the classes live in the package, :mod:`tf2_ros`)."""

from tf2_msgs.msg import TFMessage
from tf2_ros import TransformListener

__all__ = ["TFMessage", "TransformListener"]
