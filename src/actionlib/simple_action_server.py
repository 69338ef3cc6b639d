"""``actionlib.simple_action_server``: SimpleActionServer (ROS 1's API)."""

from __future__ import annotations

from collections.abc import Callable

from actionlib import _process
from actionlib.action_server import ActionServer, nop_cb
from actionlib.server_goal_handle import ServerGoalHandle
from actionlib_msgs.msg import GoalStatus
from ninjemys.actionlib import simple_server as _core

TYPE_CHECKING = False
if TYPE_CHECKING:
    from typing import Any

__all__ = ["ActionServer", "GoalStatus", "ServerGoalHandle", "SimpleActionServer", "nop_cb"]


class SimpleActionServer(_core.SimpleActionServer):
    """``SimpleActionServer(name, ActionSpec, execute_cb=None, auto_start=True)``."""

    def __init__(
        self,
        name: str,
        ActionSpec: Any,  # noqa: N803 - ROS 1's signature
        execute_cb: Callable[[Any], Any] | None = None,
        auto_start: bool = True,
    ) -> None:
        super().__init__(
            _process.node(),
            name,
            ActionSpec,
            execute_cb,
            auto_start,
        )

    # ROS 1's internal entry points, public there

    def internal_goal_callback(self, goal: ServerGoalHandle) -> None:
        """The action server's goal callback: ``goal`` becomes the next goal (preempting the current)."""
        self._on_goal(goal)

    def internal_preempt_callback(self, preempt: ServerGoalHandle) -> None:
        """The action server's cancel callback: a preempt request for the current or next goal."""
        self._on_preempt(preempt)

    def executeLoop(self) -> None:  # noqa: N802 - ROS 1's name
        """The execute thread's body: run ``execute_cb`` for each accepted goal until shutdown."""
        self._execute_loop()
