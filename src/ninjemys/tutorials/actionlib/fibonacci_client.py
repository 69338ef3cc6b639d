"""actionlib_tutorials fibonacci_client: send the ``fibonacci`` action a goal of order 20.

``fibonacci_client`` reports like the tutorial's C++ client (node ``test_fibonacci``: "Action finished:
SUCCEEDED" after at most 30 s); ``fibonacci_client.py`` like its Python one (node
``fibonacci_client_py``: waits for the result and prints ``Result: 0, 1, 1, 2, ...``).
"""

from __future__ import annotations

import sys

from ninjemys.tutorials import node_main


def _status_name(state: int) -> str:
    from actionlib_msgs.msg import GoalStatus

    for name in ("PENDING", "ACTIVE", "RECALLED", "REJECTED", "PREEMPTED", "ABORTED", "SUCCEEDED", "LOST"):
        if getattr(GoalStatus, name) == state:
            return name
    return str(state)


@node_main
def main(argv: list[str] | None = None) -> int:
    """The C++ tutorial client's behaviour."""
    import actionlib
    import rospy
    from actionlib_tutorials.msg import FibonacciAction, FibonacciGoal

    if argv is not None:
        sys.argv[1:] = argv
    rospy.init_node("test_fibonacci")
    client = actionlib.SimpleActionClient("fibonacci", FibonacciAction)
    rospy.loginfo("Waiting for action server to start.")
    if not client.wait_for_server():
        return 1  # shut down while waiting
    rospy.loginfo("Action server started, sending goal.")
    client.send_goal(FibonacciGoal(order=20))
    if client.wait_for_result(rospy.Duration(30.0)):
        rospy.loginfo("Action finished: %s", _status_name(client.get_state()))
    else:
        rospy.loginfo("Action did not finish before the time out.")
    return 0


@node_main
def main_py(argv: list[str] | None = None) -> int:
    """The Python tutorial client's behaviour."""
    import actionlib
    import rospy
    from actionlib_tutorials.msg import FibonacciAction, FibonacciGoal

    if argv is not None:
        sys.argv[1:] = argv
    try:
        rospy.init_node("fibonacci_client_py")
        client = actionlib.SimpleActionClient("fibonacci", FibonacciAction)
        client.wait_for_server()
        client.send_goal(FibonacciGoal(order=20))
        client.wait_for_result()
        result = client.get_result()
        if result is None:
            raise rospy.ROSInterruptException("no result")
        print("Result:", ", ".join(str(n) for n in result.sequence))
    except rospy.ROSInterruptException:
        print("program interrupted before completion", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
