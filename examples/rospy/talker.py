#!/usr/bin/env python3
"""Publish a greeting on the 'chatter' topic ten times a second (run: python3 talker.py)."""

import rospy
from std_msgs.msg import String


def talk():
    chatter = rospy.Publisher("chatter", String, queue_size=10)
    rospy.init_node("talker", anonymous=True)
    loop = rospy.Rate(10)  # Hz
    count = 0
    while not rospy.is_shutdown():
        greeting = "greetings from ninjemys #%d at %s" % (count, rospy.get_time())
        rospy.loginfo(greeting)
        chatter.publish(greeting)
        count += 1
        loop.sleep()


if __name__ == "__main__":
    try:
        talk()
    except rospy.ROSInterruptException:
        pass
