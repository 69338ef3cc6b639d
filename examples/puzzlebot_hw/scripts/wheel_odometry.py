#!/usr/bin/env python3
"""Dead reckoning from the motor board's wheel speeds, as the course teaches it.

Subscribes ``wl`` and ``wr`` (std_msgs/Float32, wheel angular speeds in rad/s, published by the
Arduino through rosserial), integrates the unicycle model at ``~rate`` Hz and publishes
``odom`` (nav_msgs/Odometry) and the ``odom -> base_link`` transform.

Parameters: ``~wheel_radius`` (0.05 m), ``~wheel_base`` (0.19 m, between the wheels), ``~rate`` (50 Hz),
``~odom_frame`` (odom), ``~base_frame`` (base_link).
"""

import math

import rospy
import tf2_ros
from geometry_msgs.msg import TransformStamped
from nav_msgs.msg import Odometry
from std_msgs.msg import Float32


class WheelOdometry:
    def __init__(self):
        self.r = rospy.get_param("~wheel_radius", 0.05)
        self.l = rospy.get_param("~wheel_base", 0.19)
        self.odom_frame = rospy.get_param("~odom_frame", "odom")
        self.base_frame = rospy.get_param("~base_frame", "base_link")
        self.wl = self.wr = 0.0
        self.x = self.y = self.theta = 0.0
        self.pub = rospy.Publisher("odom", Odometry, queue_size=10)
        self.tf = tf2_ros.TransformBroadcaster()
        rospy.Subscriber("wl", Float32, self.on_wl)
        rospy.Subscriber("wr", Float32, self.on_wr)
        self.last = rospy.Time.now()

    def on_wl(self, msg):
        self.wl = msg.data

    def on_wr(self, msg):
        self.wr = msg.data

    def step(self):
        now = rospy.Time.now()
        dt = (now - self.last).to_sec()
        self.last = now
        v = self.r * (self.wr + self.wl) / 2.0
        w = self.r * (self.wr - self.wl) / self.l
        self.x += v * math.cos(self.theta) * dt
        self.y += v * math.sin(self.theta) * dt
        self.theta = math.atan2(math.sin(self.theta + w * dt), math.cos(self.theta + w * dt))
        qz, qw = math.sin(self.theta / 2.0), math.cos(self.theta / 2.0)
        odom = Odometry()
        odom.header.stamp = now
        odom.header.frame_id = self.odom_frame
        odom.child_frame_id = self.base_frame
        odom.pose.pose.position.x, odom.pose.pose.position.y = self.x, self.y
        odom.pose.pose.orientation.z, odom.pose.pose.orientation.w = qz, qw
        odom.twist.twist.linear.x, odom.twist.twist.angular.z = v, w
        self.pub.publish(odom)
        t = TransformStamped()
        t.header.stamp = now
        t.header.frame_id = self.odom_frame
        t.child_frame_id = self.base_frame
        t.transform.translation.x, t.transform.translation.y = self.x, self.y
        t.transform.rotation.z, t.transform.rotation.w = qz, qw
        self.tf.sendTransform(t)


if __name__ == "__main__":
    rospy.init_node("wheel_odometry")
    node = WheelOdometry()
    rate = rospy.Rate(rospy.get_param("~rate", 50.0))
    while not rospy.is_shutdown():
        node.step()
        rate.sleep()
