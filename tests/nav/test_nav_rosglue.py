"""The nav nodes' background loops survive ROS time moving backwards (a /gazebo/reset_simulation)."""

from __future__ import annotations

import pytest

import rospy
from ninjemys.nav import rosglue


def test_sleep_goes_on_when_ros_time_moves_backwards(monkeypatch: pytest.MonkeyPatch) -> None:
    def jumped(_seconds: float) -> None:
        raise rospy.ROSTimeMovedBackwardsException(1.0)

    monkeypatch.setattr(rospy, "sleep", jumped)
    monkeypatch.setattr(rospy, "is_shutdown", lambda: False)
    assert rosglue.sleep(0.1) is True  # the loop goes on


def test_sleep_ends_the_loop_on_shutdown(monkeypatch: pytest.MonkeyPatch) -> None:
    def interrupted(_seconds: float) -> None:
        raise rospy.ROSInterruptException("shutdown")

    monkeypatch.setattr(rospy, "sleep", interrupted)
    assert rosglue.sleep(0.1) is False
