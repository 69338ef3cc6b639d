#!/usr/bin/env python3
"""Node 2 of the assignment: publishes the ROLL NUMBER (Int32) on roll_listener."""

import rospy
from std_msgs.msg import Int32

if __name__ == "__main__":
    rospy.init_node("roll_publisher")
    roll = int(rospy.get_param("~roll", 42))
    pub = rospy.Publisher("roll_listener", Int32, queue_size=10)
    rate = rospy.Rate(5)
    while not rospy.is_shutdown():
        pub.publish(roll)
        rate.sleep()
