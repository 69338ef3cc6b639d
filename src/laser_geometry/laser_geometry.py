"""``laser_geometry.laser_geometry.LaserProjection`` (ROS 1's module path), from the numpy core."""

from ninjemys.laser_geometry import LaserProjection
from sensor_msgs.msg import PointCloud2

__all__ = ["LaserProjection", "PointCloud2"]
