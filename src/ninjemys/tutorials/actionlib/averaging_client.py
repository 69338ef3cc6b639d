"""actionlib_tutorials averaging_client: ask ``averaging`` for the statistics of 100 samples.

Node ``test_averaging``; waits for the server, sends the goal, waits up to 30 s and reports the final
state ("Action finished: SUCCEEDED" or "ABORTED", the mean decides) like the tutorial's client.
"""

from __future__ import annotations

import sys

from ninjemys.tutorials import node_main
from ninjemys.tutorials.actionlib.fibonacci_client import _status_name


@node_main
def main(argv: list[str] | None = None) -> int:
    import actionlib
    import rospy
    from actionlib_tutorials.msg import AveragingAction, AveragingGoal

    if argv is not None:
        sys.argv[1:] = argv
    rospy.init_node("test_averaging")
    client = actionlib.SimpleActionClient("averaging", AveragingAction)
    rospy.loginfo("Waiting for action server to start.")
    if not client.wait_for_server():
        return 1
    rospy.loginfo("Action server started, sending goal.")
    client.send_goal(AveragingGoal(samples=100))
    if client.wait_for_result(rospy.Duration(30.0)):
        rospy.loginfo("Action finished: %s", _status_name(client.get_state()))
    else:
        rospy.loginfo("Action did not finish before the time out.")
    return 0


if __name__ == "__main__":
    sys.exit(main())
