#!/usr/bin/env python3
# Activity "Moving a PuzzleBot": drive a square with 1 m sides, open loop, measuring distance and
# angle from the wheel speeds on wl and wr:
#   d = r (wr + wl) / 2 dt        theta = r (wr - wl) / l dt        dt from rospy.get_time()
import math

import rospy
from geometry_msgs.msg import Twist
from std_msgs.msg import Float32

r = 0.05  # wheel radius (m)
l = 0.18  # distance between the wheels (m)  # noqa: E741 - the course names it l
wl = 0.0
wr = 0.0


def wl_callback(msg):
    global wl
    wl = msg.data


def wr_callback(msg):
    global wr
    wr = msg.data


def move(pub, rate, linear, angular, goal, measure):
    """Publish the command until the measured quantity (from the wheels) reaches the goal."""
    done = 0.0
    last = rospy.get_time()
    while not rospy.is_shutdown() and done < goal:
        msg = Twist()
        msg.linear.x = linear
        msg.angular.z = angular
        pub.publish(msg)
        rate.sleep()
        now = rospy.get_time()
        dt = now - last
        last = now
        done += measure(dt)
    pub.publish(Twist())
    rospy.sleep(0.2)  # let the robot stop before the next leg
    return done


if __name__ == "__main__":
    rospy.init_node("square")
    side = rospy.get_param("~side", 1.0)
    speed = rospy.get_param("~speed", 0.2)
    turn_speed = rospy.get_param("~turn_speed", 0.5)
    rospy.Subscriber("wl", Float32, wl_callback)
    rospy.Subscriber("wr", Float32, wr_callback)
    pub = rospy.Publisher("cmd_vel", Twist, queue_size=10)
    rate = rospy.Rate(50)
    while rospy.get_time() == 0:  # simulated time starts with the first /clock
        rospy.sleep(0.01)

    x = y = theta = 0.0  # dead reckoning, for the final report
    for side_number in range(4):
        d = move(pub, rate, speed, 0.0, side, lambda dt: r * (wr + wl) / 2 * dt)
        x += d * math.cos(theta)
        y += d * math.sin(theta)
        theta += move(pub, rate, 0.0, turn_speed, math.pi / 2, lambda dt: r * (wr - wl) / l * dt)
        rospy.loginfo("side %d done", side_number + 1)
    rospy.loginfo(
        "square done: the wheels say x=%.3f y=%.3f theta=%.3f",
        x,
        y,
        math.atan2(math.sin(theta), math.cos(theta)),
    )
