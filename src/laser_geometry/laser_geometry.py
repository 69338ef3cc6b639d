"""``laser_geometry.laser_geometry.LaserProjection`` (ROS 1's module path), from the numpy core."""

from ninjemys.laser_geometry import LaserProjection

__all__ = ["LaserProjection"]
