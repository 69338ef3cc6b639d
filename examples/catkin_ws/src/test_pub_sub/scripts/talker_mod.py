#!/usr/bin/env python3
"""A talker whose greeting comes from the command line (the launch file passes it with args=)."""

import sys

import rospy
from std_msgs.msg import String


def talker(greeting):
    pub = rospy.Publisher("chatter", String, queue_size=10)
    rospy.init_node("talker", anonymous=True)
    rate = rospy.Rate(10)
    while not rospy.is_shutdown():
        hello_str = ": {}".format(greeting)
        rospy.loginfo(hello_str)
        pub.publish(hello_str)
        rate.sleep()


if __name__ == "__main__":
    try:
        talker(rospy.myargv(argv=sys.argv)[1])
    except rospy.ROSInterruptException:
        pass
