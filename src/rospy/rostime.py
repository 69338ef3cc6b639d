"""rospy.Time / rospy.Duration and the process's ROS time (wall, or simulated once init_node sees /use_sim_time)."""

from __future__ import annotations

import time as _time
from typing import Any

from ninjemys.rostime import Duration, Time
from rospy.core import _process

__all__ = ["Time", "Duration", "get_time", "get_rostime", "is_wallclock"]

#: what ``set_rostime_initialized`` was last told (ROS 1's tests call it to use time without a node)
_rostime_initialized = False


def get_time() -> float:
    """ROS time in float seconds (0.0 under simulated time until the first /clock message)."""
    return _process.clock.now()


def get_rostime() -> Time:
    """ROS time as a Time."""
    secs, nsecs = _process.clock.now_pair()
    return Time(secs, nsecs)


def is_wallclock() -> bool:
    return _process.clock.is_wallclock


def set_rostime_initialized(val: bool) -> None:
    """ROS 1's switch that lets rospy's time be used before ``init_node`` (its tests call it).

    Ours reads the clock before ``init_node`` anyway (wall time), so this only records the flag that
    :func:`is_rostime_initialized` reports.
    """
    global _rostime_initialized
    _rostime_initialized = bool(val)


def is_rostime_initialized() -> bool:
    """Whether ROS time is usable: after ``init_node``, or once ``set_rostime_initialized(True)``."""
    return _rostime_initialized or _process.node is not None


def _set_rostime(t: Any) -> None:
    """Drive ROS time by hand (ROS 1's /clock callback, which tests call directly): from now on
    ``rospy.Time.now()`` is ``t`` until the next call, as under simulated time."""
    clock = _process.clock
    clock.switch_to_sim()
    clock.set_time(t.secs, t.nsecs)
    if _process.node is None:
        clock.install()  # before init_node, Time.now() reads the wall clock unless told otherwise


def switch_to_wallclock() -> None:
    """Back to wall time after :func:`_set_rostime` (ROS 1's test helper); sleepers re-check their clock."""
    clock = _process.clock
    clock.is_sim = False
    clock.wake()


def wallsleep(duration: float | Duration) -> None:
    """Sleep ``duration`` seconds of wall time, whatever ROS time does."""
    _time.sleep(duration.to_sec() if isinstance(duration, Duration) else float(duration))
