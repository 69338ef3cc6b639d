#!/usr/bin/env python3
"""Node 1 of the assignment: publishes the student's NAME (String) on name_listener."""

import rospy
from std_msgs.msg import String

if __name__ == "__main__":
    rospy.init_node("name_publisher")
    name = rospy.get_param("~name", "Ada")
    pub = rospy.Publisher("name_listener", String, queue_size=10)
    rate = rospy.Rate(5)
    while not rospy.is_shutdown():
        pub.publish(name)
        rate.sleep()
