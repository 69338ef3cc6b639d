"""``actionlib.action_server``: ActionServer (ROS 1's API) on the node of ``rospy.init_node``."""

from __future__ import annotations

from collections.abc import Callable

from actionlib import _process
from actionlib.server_goal_handle import ServerGoalHandle
from ninjemys.actionlib import server as _core

TYPE_CHECKING = False
if TYPE_CHECKING:
    from typing import Any

__all__ = ["ActionServer", "nop_cb"]


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
        self.ActionSpec = ActionSpec
        self.ActionGoal = self.types.action_goal
        self.ActionResult = self.types.action_result
        self.ActionFeedback = self.types.action_feedback
