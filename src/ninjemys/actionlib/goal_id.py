"""Goal ids: unique strings plus a stamp, made the way ROS 1's action servers and clients make them.

A server that receives a goal with an empty id names it ``"<node>-<count>-<secs>.<nsecs>"``
(goal_id_generator.py); a client names each goal it sends ``"<node>-<count>-<secs with 3 decimals>"``
(action_client.py). Counters are per process, so ids stay unique across every client and server a
process holds. The stamp is the time the id was made: cancel-by-stamp compares it.
"""

from __future__ import annotations

import itertools
import threading
from collections.abc import Callable

from ninjemys.idl.loader import get_message_class
from ninjemys.rostime import Time, get_clock

TYPE_CHECKING = False
if TYPE_CHECKING:
    from typing import Any

_server_count = itertools.count(1)
_client_count = itertools.count(1)
_lock = threading.Lock()


def _now(now: Callable[[], tuple[int, int]] | None) -> Time:
    secs, nsecs = (now or get_clock())()
    return Time(secs, nsecs)


class GoalIDGenerator:
    """Makes server-side goal ids ``"<name>-<count>-<secs>.<nsecs>"`` stamped now."""

    def __init__(self, name: str, now: Callable[[], tuple[int, int]] | None = None) -> None:
        self.name = name
        self._now = now

    def set_name(self, name: str) -> None:
        self.name = name

    def generate_ID(self) -> Any:  # noqa: N802 - ROS 1's method name
        stamp = _now(self._now)
        with _lock:
            count = next(_server_count)
        goal_id: Any = get_message_class("actionlib_msgs/GoalID")()
        goal_id.id = f"{self.name}-{count}-{stamp.secs}.{stamp.nsecs}"
        goal_id.stamp = stamp
        return goal_id

    generate_id = generate_ID


def client_goal_id(name: str, now: Callable[[], tuple[int, int]] | None = None) -> Any:
    """A client's id for a new goal: ``"<name>-<count>-<secs.3f>"`` stamped now."""
    stamp = _now(now)
    with _lock:
        count = next(_client_count)
    goal_id: Any = get_message_class("actionlib_msgs/GoalID")()
    goal_id.id = f"{name}-{count}-{stamp.to_sec():.3f}"
    goal_id.stamp = stamp
    return goal_id
