"""The nav nodes run on the core Node (one idiom from core to apps): their background loops survive ROS
time moving backwards (a /gazebo/reset_simulation) and end on shutdown (tests/test_node_idiom.py
checks that no app module imports rospy)."""

from __future__ import annotations

from ninjemys.errors import ShutdownError
from ninjemys.nav import rosglue
from ninjemys.node.run import run_node
from ninjemys.node.timers import TimeMovedBackwardsError


class _Node:
    def __init__(self, raises: BaseException | None, shut: bool = False) -> None:
        self.raises = raises
        self.is_shutdown = shut

    def sleep(self, _seconds: float) -> None:
        if self.raises is not None:
            raise self.raises


def test_sleep_goes_on_when_ros_time_moves_backwards() -> None:
    assert rosglue.node_sleep(_Node(TimeMovedBackwardsError(5.0, 1.0)), 0.1) is True
    assert rosglue.node_sleep(_Node(None), 0.1) is True


def test_sleep_ends_the_loop_on_shutdown() -> None:
    assert rosglue.node_sleep(_Node(ShutdownError("bye")), 0.1) is False
    assert rosglue.node_sleep(_Node(None, shut=True), 0.1) is False


def test_nav_nodes_run_on_the_one_runner() -> None:
    assert rosglue.run_node is run_node  # ninjemys.node.run's: the one runner of in-house nodes
