"""``tf2_ros.transform_broadcaster``, ROS 1's module path (the classes live in the package, :mod:`tf2_ros`)."""

from geometry_msgs.msg import TransformStamped
from tf2_msgs.msg import TFMessage
from tf2_ros import TransformBroadcaster

__all__ = ["TFMessage", "TransformBroadcaster", "TransformStamped"]
