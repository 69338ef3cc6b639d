"""``actionlib.goal_id_generator``: GoalIDGenerator (``"<node>-<count>-<secs>.<nsecs>"`` ids)."""

from __future__ import annotations

from actionlib import _process
from actionlib_msgs.msg import GoalID
from ninjemys.actionlib import goal_id as _core

__all__ = ["GoalID", "GoalIDGenerator"]


class GoalIDGenerator(_core.GoalIDGenerator):
    """``GoalIDGenerator(name=None)``: ids prefixed with ``name``, else this node's name."""

    def __init__(self, name: str | None = None) -> None:
        super().__init__(name if name is not None else _process.node().name)
