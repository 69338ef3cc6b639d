"""genpy.rostime: ROS 1's Time and Duration. They are ninjemys's own (the classes rospy.Time and every
message's time fields already use), so a genpy.Time is a rospy.Time and compares, hashes and
serializes as one."""

from __future__ import annotations

from ninjemys.rostime import Duration, Time, TVal

__all__ = ["TVal", "Time", "Duration"]
