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


def test_ctrl_c_during_init_node_ends_the_node_quietly(monkeypatch: pytest.MonkeyPatch) -> None:
    def interrupted(*_args, **_kwargs) -> None:
        raise rospy.ROSInitException("init_node interrupted before it could complete")

    monkeypatch.setattr(rospy, "init_node", interrupted)
    monkeypatch.setattr(rospy, "is_shutdown", lambda: True)
    built = []
    assert rosglue.run_node("move_base", [], built.append) == 0
    assert built == []


def test_a_failed_init_node_is_not_hidden(monkeypatch: pytest.MonkeyPatch) -> None:
    def failed(*_args, **_kwargs) -> None:
        raise rospy.ROSInitException("Unable to register with master node")

    monkeypatch.setattr(rospy, "init_node", failed)
    monkeypatch.setattr(rospy, "is_shutdown", lambda: False)
    with pytest.raises(rospy.ROSInitException):
        rosglue.run_node("move_base", [], lambda node: None)
