#!/usr/bin/env python3
"""Node 3 of the assignment: subscribes to both topics and prints "Student NAME has roll number: N"."""

import rospy
from std_msgs.msg import Int32, String

latest = {"name": None, "roll": None}


def report():
    if latest["name"] is not None and latest["roll"] is not None:
        rospy.loginfo("Student %s has roll number: %d", latest["name"], latest["roll"])


def on_name(msg):
    latest["name"] = msg.data
    report()


def on_roll(msg):
    latest["roll"] = msg.data
    report()


if __name__ == "__main__":
    rospy.init_node("combiner")
    rospy.Subscriber("name_listener", String, on_name)
    rospy.Subscriber("roll_listener", Int32, on_roll)
    rospy.spin()
