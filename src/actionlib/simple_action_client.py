"""``actionlib.simple_action_client``: SimpleActionClient and SimpleGoalState (ROS 1's API)."""

from __future__ import annotations

from actionlib import _process
from actionlib.action_client import ActionClient, CommState, get_name_of_constant
from actionlib_msgs.msg import GoalStatus
from ninjemys.actionlib import simple_client as _core
from ninjemys.actionlib.states import SimpleGoalState

TYPE_CHECKING = False
if TYPE_CHECKING:
    from typing import Any

__all__ = [
    "ActionClient",
    "CommState",
    "GoalStatus",
    "SimpleActionClient",
    "SimpleGoalState",
    "get_name_of_constant",
]


class SimpleActionClient(_core.SimpleActionClient):
    """``SimpleActionClient(ns, ActionSpec)`` on the node of ``rospy.init_node``.

    Timeouts (``wait_for_server``, ``wait_for_result``, ``send_goal_and_wait``) take a
    ``rospy.Duration`` or seconds; zero means wait forever, as in ROS 1.
    """

    def __init__(self, ns: str, ActionSpec: Any) -> None:  # noqa: N803 - ROS 1's signature
        super().__init__(_process.node(), ns, ActionSpec)
