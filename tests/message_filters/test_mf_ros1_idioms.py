"""What ROS 1's own message_filters tests rely on: rospy.rostime's test hooks driving ROS time without a
node (``set_rostime_initialized``, ``_set_rostime``), headerless messages stamped from that time, and
mock messages whose stamps are plain numbers."""

from __future__ import annotations

import subprocess
import sys

import pytest

from ninjemys import testing

PROGRAM = r"""
import rospy
import rospy.rostime
from std_msgs.msg import String
import message_filters

rospy.rostime.set_rostime_initialized(True)
assert rospy.rostime.is_rostime_initialized()
rospy.rostime._set_rostime(rospy.Time(5))
assert rospy.Time.now() == rospy.Time(5) and rospy.get_time() == 5.0 and not rospy.rostime.is_wallclock()

source = message_filters.SimpleFilter()
cache = message_filters.Cache(source, 3, allow_headerless=True)
first, second = String("a"), String("b")
source.signalMessage(first)
rospy.rostime._set_rostime(rospy.Time(7))
source.signalMessage(second)
assert cache.getElemAfterTime(rospy.Time(6)) is second
assert cache.getElemBeforeTime(rospy.Time(6)) is first
assert cache.getLatestTime() == rospy.Time(7) and cache.getOldestTime() == rospy.Time(5)

strict = message_filters.Cache(message_filters.SimpleFilter(), 3)
strict.add(String("no header"))
assert strict.getLast() is None


class Header:
    pass


class Mock:
    def __init__(self, stamp, data):
        self.header = Header()
        self.header.stamp = stamp
        self.data = data


a, b = message_filters.SimpleFilter(), message_filters.SimpleFilter()
sync = message_filters.TimeSynchronizer([a, b], 5)
pairs = []
sync.registerCallback(lambda m, n: pairs.append((m.data, n.data)))
for t in (3, 1, 2):
    a.signalMessage(Mock(t, "a%d" % t))
for t in (2, 3, 1):
    b.signalMessage(Mock(t, "b%d" % t))
assert sorted(pairs) == [("a1", "b1"), ("a2", "b2"), ("a3", "b3")], pairs

import time
rospy.rostime.switch_to_wallclock()
assert rospy.rostime.is_wallclock() and abs(rospy.get_time() - time.time()) < 5.0
print("ok")
"""


def test_rostime_hooks_headerless_cache_and_number_stamps() -> None:
    # a process of its own: _set_rostime switches the process's clock to simulated time
    done = subprocess.run([sys.executable, "-c", PROGRAM], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0 and done.stdout.strip() == "ok", done.stderr


@pytest.mark.ros1
def test_same_program_passes_on_ros1() -> None:
    """The program above states ROS 1's behaviour: Debian's rospy and message_filters pass it too."""
    env = testing.ros1_env("http://localhost:11311")
    done = subprocess.run(
        [testing.ROS1_PYTHON, "-c", PROGRAM], capture_output=True, text=True, timeout=60, env=env
    )
    assert done.returncode == 0 and done.stdout.strip() == "ok", done.stderr
