"""ROS 1's ``image_geometry`` (Python): camera models built from ``sensor_msgs/CameraInfo``.

Vision course code projects detections with ``PinholeCameraModel`` (``project3dToPixel``,
``projectPixelTo3dRay``, ``rectifyPoint``) and measures depth with ``StereoCameraModel``; see
:mod:`image_geometry.cameramodels`.
"""

from .cameramodels import PinholeCameraModel, StereoCameraModel

__all__ = ["PinholeCameraModel", "StereoCameraModel"]
