"""ROS 1's ``cv_bridge``: ``from cv_bridge import CvBridge, CvBridgeError`` (numpy arrays; OpenCV optional)."""

from ninjemys.cv_bridge import CvBridge, CvBridgeError

__all__ = ["CvBridge", "CvBridgeError"]
