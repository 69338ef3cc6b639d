"""``cv_bridge.core`` (ROS 1's module path for the same classes)."""

from ninjemys.cv_bridge import CvBridge, CvBridgeError

__all__ = ["CvBridge", "CvBridgeError"]
