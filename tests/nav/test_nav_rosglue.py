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


def _tf(*items: tuple) -> rosglue.Tf2D:
    from ninjemys.tf2.core import BufferCore

    tf = rosglue.Tf2D.__new__(rosglue.Tf2D)  # the buffer alone: no node, no /tf subscription
    tf.buffer = BufferCore()
    tf.buffer.set_transforms(items)
    static = [i for i in items if i[2] == 0]
    if static:
        tf.buffer.set_transforms(static, is_static=True)
    return tf


def _item(parent: str, child: str, t: float, x: float) -> tuple:
    return (parent, child, int(round(t * 1e9)), x, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0)


def test_robot_pose_refuses_a_transform_older_than_the_tolerance() -> None:
    """costmap_2d's getRobotPose: the newest pose, refused when ROS time is more than
    transform_tolerance past its stamp (move_base then stands still)."""
    tf = _tf(_item("odom", "base_link", 9.9, 1.0), _item("odom", "base_link", 10.0, 1.5))
    pose, stamp = tf.robot_pose("odom", "base_link", now=10.2, tolerance=0.3)
    assert pose == (1.5, 0.0, 0.0) and abs(stamp - 10.0) < 1e-9
    pose, stamp = tf.robot_pose("odom", "base_link", now=10.31, tolerance=0.3)
    assert pose is None and abs(stamp - 10.0) < 1e-9  # 0.31 s old: refused, with its stamp
    assert tf.robot_pose("odom", "base_link", now=10.31, tolerance=0.5)[0] == (1.5, 0.0, 0.0)
    assert tf.robot_pose("map", "base_link", now=10.0, tolerance=0.3) == (None, 0.0)  # unknown frame


def test_robot_pose_takes_the_transform_at_now_when_the_buffer_has_it() -> None:
    tf = _tf(_item("odom", "base_link", 10.0, 1.0), _item("odom", "base_link", 11.0, 2.0))
    pose, stamp = tf.robot_pose("odom", "base_link", now=10.5, tolerance=0.3)
    assert pose is not None and abs(pose[0] - 1.5) < 1e-9 and abs(stamp - 10.5) < 1e-9


def test_robot_pose_of_a_static_chain_is_never_too_old() -> None:
    tf = _tf(_item("base_link", "laser", 0.0, 0.1))
    assert tf.robot_pose("base_link", "laser", now=1000.0, tolerance=0.3)[0] == (0.1, 0.0, 0.0)
