"""rospy.Time / rospy.Duration and the process's ROS time (wall, or simulated once init_node sees /use_sim_time)."""

from __future__ import annotations

from ninjemys.rostime import Duration, Time
from rospy.core import _process

__all__ = ["Time", "Duration", "get_time", "get_rostime", "is_wallclock"]


def get_time() -> float:
    """ROS time in float seconds (0.0 under simulated time until the first /clock message)."""
    return _process.clock.now()


def get_rostime() -> Time:
    """ROS time as a Time."""
    secs, nsecs = _process.clock.now_pair()
    return Time(secs, nsecs)


def is_wallclock() -> bool:
    return _process.clock.is_wallclock
