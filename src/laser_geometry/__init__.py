"""ROS 1's ``laser_geometry`` package: ``from laser_geometry import LaserProjection``."""

from laser_geometry.laser_geometry import LaserProjection

__all__ = ["LaserProjection"]
