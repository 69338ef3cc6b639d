#!/usr/bin/env python3
"""Broadcast a frame ``carrot`` circling ``base_link`` at 10 Hz, and a static ``laser`` on ``base_link``
(the tf2 tutorials' broadcaster, with both kinds of broadcaster)."""

import math

import rospy
import tf2_ros
from geometry_msgs.msg import TransformStamped
from tf.transformations import quaternion_from_euler


def stamped(parent, child, x, y, yaw, stamp):
    t = TransformStamped()
    t.header.stamp = stamp
    t.header.frame_id = parent
    t.child_frame_id = child
    t.transform.translation.x = x
    t.transform.translation.y = y
    q = quaternion_from_euler(0, 0, yaw)
    t.transform.rotation.x, t.transform.rotation.y, t.transform.rotation.z, t.transform.rotation.w = q
    return t


def main():
    rospy.init_node("frame_broadcaster")
    tf2_ros.StaticTransformBroadcaster().sendTransform(
        stamped("base_link", "laser", 0.2, 0.0, 0.0, rospy.Time(0))
    )
    broadcaster = tf2_ros.TransformBroadcaster()
    rate = rospy.Rate(10)
    while not rospy.is_shutdown():
        a = rospy.get_time()
        broadcaster.sendTransform(
            stamped("base_link", "carrot", math.cos(a), math.sin(a), a, rospy.Time.now())
        )
        rate.sleep()


if __name__ == "__main__":
    try:
        main()
    except rospy.ROSInterruptException:
        pass
