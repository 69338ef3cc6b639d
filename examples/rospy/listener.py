#!/usr/bin/env python3
"""Print every message heard on the 'chatter' topic (run: python3 listener.py)."""

import rospy
from std_msgs.msg import String


def on_message(msg):
    rospy.loginfo(rospy.get_caller_id() + " heard: %s", msg.data)


def listen():
    rospy.init_node("listener", anonymous=True)
    rospy.Subscriber("chatter", String, on_message)
    # keep the process alive until Ctrl-C or rosnode kill
    rospy.spin()


if __name__ == "__main__":
    listen()
