"""``actionlib.handle_tracker_deleter``: HandleTrackerDeleter, ROS 1's hook that stamps a goal's end."""

from __future__ import annotations

from ninjemys.actionlib.common import stamp_of

TYPE_CHECKING = False
if TYPE_CHECKING:
    from typing import Any

__all__ = ["HandleTrackerDeleter"]


class HandleTrackerDeleter:
    """``HandleTrackerDeleter(action_server, status_tracker)``; calling it marks the goal's handles gone.

    From that stamp on, the goal stays in the status list for the server's ``status_list_timeout``
    and is then dropped, as when the goal reaches a terminal state.
    """

    def __init__(self, action_server: Any, status_tracker: Any) -> None:
        self.action_server = action_server
        self.status_tracker = status_tracker

    def __call__(self, ptr: Any) -> None:
        if self.action_server:
            with self.action_server.lock:
                self.status_tracker.handle_destruction_time = stamp_of(self.action_server.clock)
