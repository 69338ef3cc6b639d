"""ROS 1's ``tf2_geometry_msgs``: importing it registers the geometry_msgs stamped types with
``tf2_ros.Buffer.transform()``; the names are those of :mod:`tf2_geometry_msgs.tf2_geometry_msgs`."""

from tf2_geometry_msgs.tf2_geometry_msgs import *  # noqa: F403
from tf2_geometry_msgs.tf2_geometry_msgs import __all__  # noqa: F401
