"""Debian's real action servers (run under /usr/bin/python3) for TwoInts. Prints ``READY`` once started.

``simple NS``: a SimpleActionServer; a goal with ``a == -1`` runs until preempted, any other goal
succeeds at once with ``a + b``.
``hold NS``: an ActionServer that accepts every goal and keeps it until it is cancelled.
``plain NS``: an ActionServer that accepts and succeeds each goal in its goal callback. (Real
SimpleActionServer's execute loop can miss the wake-up of a goal that arrives while it finishes the
previous one and then sleeps 0.1 s: a fast client is held to about 30 goals/s by that, not by the
protocol.)
"""

import sys

import actionlib
import rospy
from actionlib.msg import TwoIntsAction, TwoIntsResult


def simple(ns):
    def execute(goal):
        if goal.a == -1:
            rate = rospy.Rate(100)
            while not server.is_preempt_requested() and not rospy.is_shutdown():
                rate.sleep()
            server.set_preempted(TwoIntsResult(sum=-1), "preempted by request")
            return
        server.set_succeeded(TwoIntsResult(sum=goal.a + goal.b))

    server = actionlib.SimpleActionServer(ns, TwoIntsAction, execute, auto_start=False)
    server.start()
    return server


def plain(ns):
    def on_goal(handle):
        handle.set_accepted()
        goal = handle.get_goal()
        handle.set_succeeded(TwoIntsResult(sum=goal.a + goal.b))

    server = actionlib.ActionServer(ns, TwoIntsAction, on_goal, auto_start=False)
    server.start()
    return server


def hold(ns):
    server = actionlib.ActionServer(
        ns,
        TwoIntsAction,
        lambda handle: handle.set_accepted(),
        lambda handle: handle.set_canceled(None, "cancelled"),
        auto_start=False,
    )
    server.start()
    return server


def main():
    rospy.init_node("real_server", anonymous=True)
    kind, ns = sys.argv[1], sys.argv[2]
    server = {"simple": simple, "plain": plain, "hold": hold}[kind](ns)
    print("READY", flush=True)
    rospy.spin()
    return server


if __name__ == "__main__":
    main()
