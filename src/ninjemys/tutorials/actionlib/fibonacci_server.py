"""actionlib_tutorials fibonacci_server: the ``fibonacci`` action, one Fibonacci number per second.

The node is ``fibonacci`` and its action is named after it (``/fibonacci``). Each goal of order ``n``
builds the sequence from the seeds 0, 1, publishing it as feedback after every step and returning it
as the result; a preempt request stops it between steps.
"""

from __future__ import annotations

import sys
from typing import Any

from ninjemys.tutorials import node_main


class FibonacciServer:
    def __init__(self, name: str) -> None:
        import actionlib
        from actionlib_tutorials.msg import FibonacciAction

        self.action_name = name
        self.server = actionlib.SimpleActionServer(
            name, FibonacciAction, execute_cb=self.execute, auto_start=False
        )
        self.server.start()

    def execute(self, goal: Any) -> None:
        import rospy
        from actionlib_tutorials.msg import FibonacciFeedback, FibonacciResult

        rate = rospy.Rate(1)
        feedback = FibonacciFeedback(sequence=[0, 1])
        rospy.loginfo(
            "%s: Executing, creating fibonacci sequence of order %i with seeds %i, %i",
            self.action_name,
            goal.order,
            feedback.sequence[0],
            feedback.sequence[1],
        )
        for i in range(1, goal.order):
            if self.server.is_preempt_requested() or rospy.is_shutdown():
                rospy.loginfo("%s: Preempted", self.action_name)
                self.server.set_preempted()
                return
            feedback.sequence.append(feedback.sequence[i] + feedback.sequence[i - 1])
            self.server.publish_feedback(feedback)
            rate.sleep()
        rospy.loginfo("%s: Succeeded", self.action_name)
        self.server.set_succeeded(FibonacciResult(sequence=feedback.sequence))


@node_main
def main(argv: list[str] | None = None) -> int:
    import rospy

    if argv is not None:
        sys.argv[1:] = argv
    rospy.init_node("fibonacci")
    FibonacciServer(rospy.get_name())
    rospy.spin()
    return 0


if __name__ == "__main__":
    sys.exit(main())
