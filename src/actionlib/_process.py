"""How the actionlib facade reaches rospy's process: its core node, its ROS clock, its log."""

from __future__ import annotations

import rospy
import rospy.core

TYPE_CHECKING = False
if TYPE_CHECKING:
    from typing import Any


def node() -> Any:
    """The core Node of ``rospy.init_node`` (ROSInitException before it)."""
    return rospy.core.process_node()


def clock() -> Any:
    """rospy's ROS clock (wall time, or /clock under use_sim_time): waits and stamps follow it."""
    return getattr(node(), "clock", None) or rospy.core._process.clock


class RospyLog:
    """The cores' log interface onto rospy's loggers (console, log file and /rosout)."""

    @staticmethod
    def debug(msg: Any, *args: Any) -> None:
        rospy.logdebug(msg, *args)

    @staticmethod
    def info(msg: Any, *args: Any) -> None:
        rospy.loginfo(msg, *args)

    @staticmethod
    def warn(msg: Any, *args: Any) -> None:
        rospy.logwarn(msg, *args)

    @staticmethod
    def error(msg: Any, *args: Any) -> None:
        rospy.logerr(msg, *args)


LOG = RospyLog()
