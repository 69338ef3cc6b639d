"""ROS 1's ``cv_bridge``: ``from cv_bridge import CvBridge, CvBridgeError`` (numpy arrays; OpenCV optional),
and the helpers ``getCvType`` and ``cvtColorForDisplay`` of ``cv_bridge.boost.cv_bridge_boost``."""

from cv_bridge.boost.cv_bridge_boost import cvtColorForDisplay, getCvType
from cv_bridge.core import CvBridge, CvBridgeError

__all__ = ["CvBridge", "CvBridgeError", "cvtColorForDisplay", "getCvType"]
