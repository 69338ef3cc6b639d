#!/usr/bin/env python3
"""The activity, modified to publish the custom message: a stamped, slowly rising value."""

import rospy
from basic_comms.msg import Reading

if __name__ == "__main__":
    pub = rospy.Publisher("reading", Reading, queue_size=10)
    rospy.init_node("reading_talker")
    rate = rospy.Rate(10)
    value = 0.0
    while not rospy.is_shutdown():
        msg = Reading()
        msg.header.stamp = rospy.Time.now()
        msg.header.frame_id = "sensor"
        msg.value = value
        pub.publish(msg)
        value += 0.5
        rate.sleep()
