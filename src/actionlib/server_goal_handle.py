"""``actionlib.server_goal_handle``: ServerGoalHandle, the server's handle on one goal."""

from ninjemys.actionlib.server import ServerGoalHandle

__all__ = ["ServerGoalHandle"]
