"""``tf.TransformBroadcaster``: tf's legacy ``sendTransform(translation, rotation, time, child, parent)``."""

from __future__ import annotations

from typing import Any

import tf2_ros
from ninjemys.tf2.buffer import to_ns


class TransformBroadcaster:
    """Publishes on ``/tf`` through tf2_ros (needs ``rospy.init_node`` first)."""

    def __init__(self, queue_size: int = 100) -> None:
        self.tf2_broadcaster = tf2_ros.TransformBroadcaster(queue_size)

    def sendTransform(self, translation: Any, rotation: Any, time: Any, child: str, parent: str) -> None:  # noqa: N802
        """Broadcast ``child`` -> ``parent``: translation (x, y, z), rotation quaternion (x, y, z, w)."""
        x, y, z = (float(v) for v in translation[:3])
        qx, qy, qz, qw = (float(v) for v in rotation[:4])
        self.tf2_broadcaster.send_items([(parent, child, to_ns(time), x, y, z, qx, qy, qz, qw)])

    def sendTransformMessage(self, transform: Any) -> None:  # noqa: N802
        """Broadcast a ``geometry_msgs/TransformStamped``."""
        self.tf2_broadcaster.sendTransform([transform])
