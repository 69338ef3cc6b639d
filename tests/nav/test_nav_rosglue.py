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


def test_lookup_stamped_gives_the_newest_transform_and_its_time() -> None:
    """move_base's goal check needs the age of amcl's map -> odom (late under load): a fresh
    odom -> base_link does not make it fresh."""
    tf = _tf(_item("map", "odom", 9.0, 0.5), _item("map", "odom", 9.5, 0.6))
    found = tf.lookup_stamped("map", "odom")
    assert found is not None and found[0] == (0.6, 0.0, 0.0) and abs(found[1] - 9.5) < 1e-9
    tf.buffer.set_transforms([_item("map", "odom", 10.2, 0.7)])  # amcl's next, future-dated
    found = tf.lookup_stamped("map", "odom")
    assert found is not None and found[0] == (0.7, 0.0, 0.0) and abs(found[1] - 10.2) < 1e-9
    assert tf.lookup_stamped("map", "nowhere") is None


def test_move_base_carries_the_local_pose_by_the_newest_map_to_odom() -> None:
    """move_base's global pose under TF lag: amcl's map -> odom of 9.5, the robot's odom -> base_link
    of 10.0 after turning 0.5 rad since 9.5. The global pose is the fresh local one carried by the
    newest map -> odom, so local * global^-1 is map -> odom itself; map -> base_link at the chain's
    latest common time (9.5) was half a second old and turned the goal with the robot."""
    import math
    from types import SimpleNamespace

    from ninjemys.nav.move_base_node import MoveBase
    from ninjemys.tf2.math import se2_compose, se2_inverse

    def odom_base(t: float, yaw: float) -> tuple:
        return (
            "odom",
            "base_link",
            int(round(t * 1e9)),
            1.0,
            0.0,
            0.0,
            0.0,
            0.0,
            math.sin(yaw / 2),
            math.cos(yaw / 2),
        )

    tf = _tf(
        _item("map", "odom", 9.5, 0.3),
        *(odom_base(9.0 + i * 0.1, max(0.0, i * 0.1 - 0.5)) for i in range(11)),
    )
    local = tf.lookup("odom", "base_link", 10.0)
    assert local is not None and abs(local[2] - 0.5) < 1e-9
    fake = SimpleNamespace(
        _pose=lambda cm: (local, False, 10.0),
        tf=tf,
        local_cm=SimpleNamespace(global_frame="odom"),
        global_cm=SimpleNamespace(global_frame="map", robot_base_frame="base_link"),
    )
    gpose, lpose, too_old, stamp, global_stamp = MoveBase._robot_poses(fake)  # type: ignore[arg-type]
    assert lpose == local and not too_old and stamp == 10.0 and abs(global_stamp - 9.5) < 1e-9
    assert gpose is not None and abs(gpose[2] - 0.5) < 1e-9 and abs(gpose[0] - 1.3) < 1e-9
    odom_from_map = se2_compose(lpose, se2_inverse(gpose))
    assert all(abs(a - b) < 1e-9 for a, b in zip(odom_from_map, (-0.3, 0.0, 0.0), strict=True))
