#!/usr/bin/env python3
"""Logs each Reading with its time stamp."""

import rospy
from basic_comms.msg import Reading


def callback(msg):
    rospy.loginfo("reading %.1f at %d.%09d", msg.value, msg.header.stamp.secs, msg.header.stamp.nsecs)


if __name__ == "__main__":
    rospy.init_node("reading_listener")
    rospy.Subscriber("reading", Reading, callback)
    rospy.spin()
