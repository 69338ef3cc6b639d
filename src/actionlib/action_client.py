"""``actionlib.action_client``: ActionClient, ClientGoalHandle, CommState, TerminalState (ROS 1's API)."""

from __future__ import annotations

from actionlib import _process
from actionlib.exceptions import ActionException
from actionlib_msgs.msg import GoalID, GoalStatus, GoalStatusArray
from ninjemys.actionlib import client as _core
from ninjemys.actionlib.client import ClientGoalHandle, CommStateMachine
from ninjemys.actionlib.states import CommState, TerminalState, _name_of
from std_msgs.msg import Header

TYPE_CHECKING = False
if TYPE_CHECKING:
    from typing import Any

__all__ = [
    "INVALID_TRANSITION",
    "NO_TRANSITION",
    "ActionClient",
    "ActionException",
    "ClientGoalHandle",
    "CommState",
    "CommStateMachine",
    "GoalID",
    "GoalManager",
    "GoalStatus",
    "GoalStatusArray",
    "Header",
    "TerminalState",
    "get_name_of_constant",
]


#: ROS 1's markers in its transition table: the status changes nothing / cannot happen in this state
NO_TRANSITION = -1
INVALID_TRANSITION = -2


def get_name_of_constant(C: type, n: int) -> str:  # noqa: N803 - ROS 1's signature
    """The name of the integer constant ``n`` in class ``C`` (``NO_SUCH_STATE_<n>`` if none)."""
    return _name_of(C, n)


# ROS 1 gives the message class a to_string too: GoalStatus.to_string(3) == "SUCCEEDED"
GoalStatus.to_string = classmethod(get_name_of_constant)


class ActionClient(_core.ActionClient):
    """``ActionClient(ns, ActionSpec)`` on the node of ``rospy.init_node``."""

    def __init__(self, ns: str, ActionSpec: Any) -> None:  # noqa: N803 - ROS 1's signature
        super().__init__(_process.node(), ns, ActionSpec)


class GoalManager:
    """ROS 1's goal bookkeeping class; ours lives inside ActionClient, so this only names the types."""

    def __init__(self, ActionSpec: Any) -> None:  # noqa: N803 - ROS 1's signature
        from ninjemys.actionlib.common import ActionTypes

        types = ActionTypes.of(ActionSpec)
        self.ActionSpec = ActionSpec
        self.ActionGoal = types.action_goal
        self.ActionResult = types.action_result
        self.ActionFeedback = types.action_feedback
