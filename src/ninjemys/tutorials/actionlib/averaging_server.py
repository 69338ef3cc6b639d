"""actionlib_tutorials averaging_server: mean and standard deviation of ``/random_number`` samples.

A goal asks for ``samples`` numbers; every number received while the goal is active updates the
running mean and standard deviation, sent as feedback. After more than ``samples`` numbers the goal
ends: succeeded when the mean is at least 5, aborted otherwise (the tutorial's rule). It uses the
goal/preempt callbacks of SimpleActionServer rather than an execute callback.
"""

from __future__ import annotations

import math
import sys
from typing import Any

from ninjemys.tutorials import node_main


class AveragingServer:
    def __init__(self, name: str) -> None:
        import actionlib
        import rospy
        from actionlib_tutorials.msg import AveragingAction
        from std_msgs.msg import Float32

        self.action_name = name
        self.samples = 0
        self.count = 0
        self.total = 0.0
        self.total_sq = 0.0
        self.server = actionlib.SimpleActionServer(name, AveragingAction, auto_start=False)
        self.server.register_goal_callback(self.on_goal)
        self.server.register_preempt_callback(self.on_preempt)
        self.subscriber = rospy.Subscriber("/random_number", Float32, self.on_number)
        self.server.start()

    def on_goal(self) -> None:
        self.count = 0
        self.total = 0.0
        self.total_sq = 0.0
        goal = self.server.accept_new_goal()
        self.samples = goal.samples if goal is not None else 0

    def on_preempt(self) -> None:
        import rospy

        rospy.loginfo("%s: Preempted", self.action_name)
        self.server.set_preempted()

    def on_number(self, msg: Any) -> None:
        import rospy
        from actionlib_tutorials.msg import AveragingFeedback, AveragingResult

        if not self.server.is_active():
            return
        self.count += 1
        self.total += msg.data
        self.total_sq += msg.data * msg.data
        mean = self.total / self.count
        std_dev = math.sqrt(math.fabs(self.total_sq / self.count - mean * mean))
        self.server.publish_feedback(
            AveragingFeedback(sample=self.count, data=msg.data, mean=mean, std_dev=std_dev)
        )
        if self.count > self.samples:
            result = AveragingResult(mean=mean, std_dev=std_dev)
            if mean < 5.0:
                rospy.loginfo("%s: Aborted", self.action_name)
                self.server.set_aborted(result)
            else:
                rospy.loginfo("%s: Succeeded", self.action_name)
                self.server.set_succeeded(result)


@node_main
def main(argv: list[str] | None = None) -> int:
    import rospy

    if argv is not None:
        sys.argv[1:] = argv
    rospy.init_node("averaging")
    AveragingServer(rospy.get_name())
    rospy.spin()
    return 0


if __name__ == "__main__":
    sys.exit(main())
