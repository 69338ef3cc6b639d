"""``actionlib.status_tracker``: StatusTracker with ROS 1's constructor (goal_id and status, or goal)."""

from __future__ import annotations

from actionlib import _process
from actionlib_msgs.msg import GoalStatus
from ninjemys.actionlib import server as _core
from ninjemys.actionlib.goal_id import GoalIDGenerator
from ninjemys.actionlib.states import PENDING
from ninjemys.rostime import Time

TYPE_CHECKING = False
if TYPE_CHECKING:
    from typing import Any

__all__ = ["StatusTracker"]


class StatusTracker(_core.StatusTracker):
    """``StatusTracker(goal_id, status)`` for a bare status, or ``StatusTracker(goal=action_goal)``."""

    def __init__(self, goal_id: Any = None, status: int | None = None, goal: Any = None) -> None:
        record = GoalStatus()
        if goal_id is not None:
            record.goal_id = goal_id
            record.status = status or 0
            super().__init__(record)
            return
        record.goal_id = goal.goal_id
        record.status = PENDING
        if not record.goal_id.id:
            record.goal_id = GoalIDGenerator(_process.node().name).generate_ID()
        if record.goal_id.stamp.is_zero():
            secs, nsecs = _process.node().clock.now_pair()
            record.goal_id.stamp = Time(secs, nsecs)
        super().__init__(record, goal)
