#!/usr/bin/env python3
"""Print where ``carrot`` is as seen from ``laser``, once a second (the tf2 tutorials' listener)."""

import rospy
import tf2_ros
from tf.transformations import euler_from_quaternion


def main():
    rospy.init_node("frame_listener")
    buffer = tf2_ros.Buffer()
    tf2_ros.TransformListener(buffer)
    rate = rospy.Rate(1)
    while not rospy.is_shutdown():
        try:
            t = buffer.lookup_transform("laser", "carrot", rospy.Time(0), rospy.Duration(1.0))
        except (tf2_ros.LookupException, tf2_ros.ConnectivityException, tf2_ros.ExtrapolationException) as e:
            rospy.logwarn("no transform yet: %s", e)
        else:
            p, q = t.transform.translation, t.transform.rotation
            yaw = euler_from_quaternion((q.x, q.y, q.z, q.w))[2]
            rospy.loginfo("carrot in laser: x=%.2f y=%.2f yaw=%.2f", p.x, p.y, yaw)
        rate.sleep()


if __name__ == "__main__":
    try:
        main()
    except rospy.ROSInterruptException:
        pass
