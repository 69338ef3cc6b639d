#!/usr/bin/env python3
# Activity "Moving a PuzzleBot": drive in a straight line, open loop, measuring the distance from the
# wheel speeds the robot publishes on wl and wr:  d = r (wr + wl) / 2 dt,  dt from rospy.get_time().
import rospy
from geometry_msgs.msg import Twist
from std_msgs.msg import Float32

r = 0.05  # wheel radius (m)
wl = 0.0
wr = 0.0


def wl_callback(msg):
    global wl
    wl = msg.data


def wr_callback(msg):
    global wr
    wr = msg.data


if __name__ == "__main__":
    rospy.init_node("straight_line")
    distance = rospy.get_param("~distance", 1.0)
    speed = rospy.get_param("~speed", 0.2)
    rospy.Subscriber("wl", Float32, wl_callback)
    rospy.Subscriber("wr", Float32, wr_callback)
    pub = rospy.Publisher("cmd_vel", Twist, queue_size=10)
    rate = rospy.Rate(50)
    while rospy.get_time() == 0:  # simulated time starts with the first /clock
        rospy.sleep(0.01)

    d = 0.0
    last = rospy.get_time()
    while not rospy.is_shutdown() and d < distance:
        msg = Twist()
        msg.linear.x = speed
        pub.publish(msg)
        rate.sleep()
        now = rospy.get_time()
        dt = now - last
        last = now
        d += r * (wr + wl) / 2 * dt
    pub.publish(Twist())
    rospy.loginfo("straight line done: %.3f m by the wheels", d)
