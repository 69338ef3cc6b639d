#!/usr/bin/env python3
"""Both at once: listen on 'chatter' and republish a reply on 'chatter_2' at 10 Hz."""

import rospy
from std_msgs.msg import String

last_heard = ["nothing yet"]


def on_message(msg):
    last_heard[0] = msg.data
    rospy.loginfo(rospy.get_caller_id() + " heard from the talker: %s", msg.data)


def relay():
    rospy.init_node("talker_listener", anonymous=True)
    rospy.Subscriber("chatter", String, on_message)
    replies = rospy.Publisher("chatter_2", String, queue_size=10)
    loop = rospy.Rate(10)  # Hz
    while not rospy.is_shutdown():
        reply = "relayed at %s, last heard: %s" % (rospy.get_time(), last_heard[0])
        rospy.loginfo(reply)
        replies.publish(reply)
        loop.sleep()


if __name__ == "__main__":
    try:
        relay()
    except rospy.ROSInterruptException:
        pass
