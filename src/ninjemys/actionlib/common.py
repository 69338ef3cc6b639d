"""What an action server and client share: the message types of an action, the clock, the log.

The library cores take the node they run on plus two optional collaborators: a ROS clock (waits and
stamps follow simulated time when the node uses it) and a log with ``debug``/``info``/``warn``/
``error`` (the node's /rosout log when the facade passes it). Without them the node's own are used
when it has them, else wall time and Python logging, so a core is usable (and testable) alone.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

from ninjemys.errors import ActionException
from ninjemys.idl.loader import get_message_class
from ninjemys.node.clock import Clock
from ninjemys.rostime import Duration, Time

TYPE_CHECKING = False
if TYPE_CHECKING:
    from typing import Any


@dataclass(frozen=True)
class ActionTypes:
    """The classes of one action, found the way ROS 1 finds them: from an instance of ``FooAction``."""

    action: type
    action_goal: type
    action_result: type
    action_feedback: type
    goal: type
    result: type
    feedback: type

    @classmethod
    def of(cls, action_class: Any) -> ActionTypes:
        try:
            sample = action_class()
            return cls(
                action_class,
                type(sample.action_goal),
                type(sample.action_result),
                type(sample.action_feedback),
                type(sample.action_goal.goal),
                type(sample.action_result.result),
                type(sample.action_feedback.feedback),
            )
        except (AttributeError, TypeError):
            raise ActionException(f"Type is not an action spec: {action_class!r}") from None


def goal_status_class() -> Any:
    return get_message_class("actionlib_msgs/GoalStatus")


def goal_id_class() -> Any:
    return get_message_class("actionlib_msgs/GoalID")


def goal_status_array_class() -> Any:
    return get_message_class("actionlib_msgs/GoalStatusArray")


class PyLog:
    """The log of a core used without a node log: Python's logging, printf-style like rospy."""

    def __init__(self, name: str) -> None:
        self._log = logging.getLogger(name)

    def debug(self, msg: Any, *args: Any) -> None:
        self._log.debug(msg, *args)

    def info(self, msg: Any, *args: Any) -> None:
        self._log.info(msg, *args)

    def warn(self, msg: Any, *args: Any) -> None:
        self._log.warning(msg, *args)

    def error(self, msg: Any, *args: Any) -> None:
        self._log.error(msg, *args)


_wall_clock: Clock | None = None


def resolve_clock(node: Any, clock: Clock | None) -> Clock:
    """The clock given, else the node's, else one shared wall clock."""
    global _wall_clock
    if clock is not None:
        return clock
    own = getattr(node, "clock", None)
    if own is not None:
        return own
    if _wall_clock is None:
        _wall_clock = Clock()
    return _wall_clock


def resolve_log(node: Any, log: Any, name: str) -> Any:
    if log is not None:
        return log
    own = getattr(node, "log", None)
    return own if own is not None else PyLog(name)


def stamp_of(clock: Clock) -> Time:
    secs, nsecs = clock.now_pair()
    return Time(secs, nsecs)


def seconds(value: Any) -> float:
    """Seconds from a float or a Duration (the facades accept both, like rospy)."""
    if isinstance(value, Duration):
        return value.to_sec()
    to_sec = getattr(value, "to_sec", None)
    return float(to_sec()) if to_sec is not None else float(value)
