"""``actionlib.action_server``: ActionServer (ROS 1's API) on the node of ``rospy.init_node``."""

from __future__ import annotations

from collections.abc import Callable

from actionlib import _process
from actionlib.exceptions import ActionException
from actionlib.goal_id_generator import GoalIDGenerator
from actionlib.handle_tracker_deleter import HandleTrackerDeleter
from actionlib.server_goal_handle import ServerGoalHandle
from actionlib.status_tracker import StatusTracker
from actionlib_msgs.msg import GoalID, GoalStatus, GoalStatusArray
from ninjemys.actionlib import server as _core

TYPE_CHECKING = False
if TYPE_CHECKING:
    from typing import Any

__all__ = [
    "ActionException",
    "ActionServer",
    "GoalID",
    "GoalIDGenerator",
    "GoalStatus",
    "GoalStatusArray",
    "HandleTrackerDeleter",
    "ServerGoalHandle",
    "StatusTracker",
    "nop_cb",
]


def nop_cb(goal_handle: ServerGoalHandle) -> None:
    """The default cancel callback: nothing (the user polls the goal's status)."""


class ActionServer(_core.ActionServer):
    """``ActionServer(ns, ActionSpec, goal_cb, cancel_cb=nop_cb, auto_start=True)``."""

    def __init__(
        self,
        ns: str,
        ActionSpec: Any,  # noqa: N803 - ROS 1's signature
        goal_cb: Callable[[ServerGoalHandle], Any],
        cancel_cb: Callable[[ServerGoalHandle], Any] = nop_cb,
        auto_start: bool = True,
    ) -> None:
        super().__init__(
            _process.node(),
            ns,
            ActionSpec,
            goal_cb,
            cancel_cb,
            auto_start,
        )

    # ROS 1's internal entry points, public there (subclasses and tests call them)

    def initialize(self) -> None:
        """Advertise the topics and start the status publication (what :meth:`start` does)."""
        self.start()

    def internal_goal_callback(self, goal: Any) -> None:
        """Handle an ActionGoal message as if it came on the ``goal`` topic."""
        self._on_goal(goal)

    def internal_cancel_callback(self, goal_id: Any) -> None:
        """Handle a GoalID as if it came on the ``cancel`` topic."""
        self._on_cancel(goal_id)

    def publish_status_async(self, event: Any) -> None:
        """The status timer's callback: publish the status list."""
        self._on_timer(event)
