"""What every navigation node shares: start-up, parameters, message conversions and 2D TF lookups.

Every navigation node is a core :class:`~ninjemys.node.Node` made from the process's command line
and run by :func:`ninjemys.node.run.run_node` (re-exported here as :func:`run_core_node`), the one way
in-house nodes run; rospy stays for tutorials and users. Everything below takes the Node and uses
its log and clock (sim time under /use_sim_time).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from ninjemys.errors import ShutdownError
from ninjemys.maps.mapfile import GridMap
from ninjemys.node.node import Node
from ninjemys.node.run import run_node
from ninjemys.node.timers import TimeMovedBackwardsError
from ninjemys.rostime import Time
from ninjemys.tf2.core import BufferCore
from ninjemys.tf2.errors import TransformException
from ninjemys.tf2.math import Pose2D, quaternion_from_yaw, yaw_from_quaternion
from ninjemys.tf2.node import TransformBroadcaster, TransformListener

#: how long (wall seconds) a scan waits for the transform at its stamp before it is dropped; ROS 1's
#: message filters hold up to their queue size of scans, about a second of a 40 Hz (4x sim) laser
STAMP_WAIT = 1.0


def run_core_node(name: str, argv: list[str] | None, build: Callable[[Node], Any]) -> int:
    """Start core node ``name``, build its object with ``build(node)``, wait for shutdown (Ctrl-C,
    SIGTERM, ``rosnode kill``): :func:`ninjemys.node.run.run_node`, the one way in-house nodes run."""
    return run_node(name, argv, build)


def node_sleep(node: Any, seconds: float) -> bool:
    """Sleep ``seconds`` of the node's ROS time; False once it is shutting down (for background loops).
    ROS time moving backwards (a simulation reset) ends the sleep early but not the loop."""
    try:
        node.sleep(seconds)
    except TimeMovedBackwardsError:
        pass
    except ShutdownError:
        return False
    return not node.is_shutdown


def stamp(t: float) -> Time:
    """ROS time ``t`` (seconds) as a message stamp."""
    return Time.from_sec(t)


def pose_msg_to_2d(pose: Any) -> Pose2D:
    """geometry_msgs/Pose -> (x, y, yaw)."""
    q = pose.orientation
    return float(pose.position.x), float(pose.position.y), yaw_from_quaternion(q.x, q.y, q.z, q.w)


def fill_pose(pose: Any, p: Pose2D) -> Any:
    pose.position.x, pose.position.y, pose.position.z = float(p[0]), float(p[1]), 0.0
    (pose.orientation.x, pose.orientation.y, pose.orientation.z, pose.orientation.w) = quaternion_from_yaw(
        p[2]
    )
    return pose


def grid_from_msg(msg: Any) -> GridMap:
    """nav_msgs/OccupancyGrid -> GridMap (the origin's yaw is kept but, as in amcl, not applied)."""
    info = msg.info
    data = np.asarray(msg.data, dtype=np.int8).reshape(info.height, info.width)
    return GridMap(data.copy(), float(info.resolution), pose_msg_to_2d(info.origin))


def grid_to_msg(grid: GridMap, frame_id: str, t: float, cls: Any = None) -> Any:
    """GridMap -> nav_msgs/OccupancyGrid stamped (and loaded) at ROS time ``t``."""
    from nav_msgs.msg import OccupancyGrid

    msg = (cls or OccupancyGrid)()
    msg.header.frame_id = frame_id
    msg.header.stamp = stamp(t)
    fill_info(msg.info, grid.width, grid.height, grid.resolution, grid.origin, t)
    msg.data = np.ascontiguousarray(grid.data, dtype=np.int8).ravel()
    return msg


def fill_info(info: Any, width: int, height: int, resolution: float, origin: Pose2D, t: float) -> Any:
    info.map_load_time = stamp(t)
    info.resolution = float(resolution)
    info.width, info.height = int(width), int(height)
    fill_pose(info.origin, origin)
    return info


def tf_to_2d(t: tuple) -> Pose2D:
    """The buffer's 7-float transform (x, y, z, qx, qy, qz, qw) as (x, y, yaw)."""
    return float(t[0]), float(t[1]), yaw_from_quaternion(t[3], t[4], t[5], t[6])


def tf_item(parent: str, child: str, t: float, p: Pose2D) -> tuple:
    """A broadcaster item for a planar transform at ROS time ``t``."""
    q = quaternion_from_yaw(p[2])
    return (parent, child, int(round(t * 1e9)), float(p[0]), float(p[1]), 0.0, *q)


class Tf2D:
    """A tf2 buffer fed from /tf and /tf_static, answering planar lookups, plus a broadcaster."""

    def __init__(self, node: Any, cache_time: float = 10.0) -> None:
        self.buffer = BufferCore(cache_time=cache_time, report=lambda text: node.log.warn("%s", text))
        self.listener = TransformListener(node, self.buffer, now=node.get_time)
        self._broadcaster: TransformBroadcaster | None = None
        self._node = node

    def lookup(self, target: str, source: str, t: float = 0.0) -> Pose2D | None:
        """``source``'s pose in ``target`` at ROS time ``t`` (0: latest); None when unknown."""
        try:
            return tf_to_2d(self.buffer.lookup(target, source, int(round(t * 1e9)))[1])
        except TransformException:
            return None

    def lookup_stamped(self, target: str, source: str) -> tuple[Pose2D, float] | None:
        """``source``'s newest pose in ``target`` and its ROS time (the chain's latest common time; 0 for
        a static chain); None when unknown."""
        try:
            stamp_ns, tr = self.buffer.lookup(target, source, 0)
        except TransformException:
            return None
        return tf_to_2d(tr), stamp_ns * 1e-9

    def robot_pose(
        self, target: str, source: str, now: float, tolerance: float
    ) -> tuple[Pose2D | None, float]:
        """costmap_2d's getRobotPose: ``source``'s pose in ``target`` at ``now`` when the buffer has it,
        else the newest; refused (``None``) when it is older than ``now - tolerance``, the costmap's
        ``transform_tolerance``. Returns ``(pose, stamp)``; ``(None, 0.0)`` when unknown, ``(None,
        stamp)`` when too old. A zero stamp (a static chain) is never too old, as in ROS 1.

        Under load /tf reaches move_base late: driving on the newest pose then steers from where the
        robot was tenths of a second ago. ROS 1 refuses such a pose (move_base stands still, replans,
        and runs its recoveries after ``controller_patience``); so does move_base here."""
        t_ns = int(round(now * 1e9))
        try:
            ok, _ = self.buffer.can_transform(target, source, t_ns)
            stamp_ns, tr = self.buffer.lookup(target, source, t_ns if ok else 0)
        except TransformException:
            return None, 0.0
        stamp = stamp_ns * 1e-9
        if stamp_ns and now - stamp > tolerance:
            return None, stamp
        return tf_to_2d(tr), stamp

    def lookup_at(self, target: str, source: str, t: float, timeout: float = STAMP_WAIT) -> Pose2D | None:
        """``source``'s pose in ``target`` at exactly the data's stamp ``t``, waiting up to ``timeout``
        wall seconds for the transform to arrive; None when it does not (the data is then dropped).

        This is what ROS 1's ``tf2_ros::MessageFilter`` does for amcl, gmapping and the costmaps: a scan
        is used only with the odometry of its own instant. A scan often arrives before the /tf message
        of the same simulation step, and under load /tf lags by many cycles; pairing the scan with the
        newest (older) odometry instead would shift it by whatever the robot moved meanwhile (0.4 rad
        for half a second of turning), which is what sent amcl and the mapper astray under load."""
        t_ns = int(round(t * 1e9))
        ok, _ = self.buffer.wait_for_transform(
            lambda: self.buffer.can_transform(target, source, t_ns), timeout
        )
        if not ok:
            return None
        return self.lookup(target, source, t)

    def send(self, items: list[tuple]) -> None:
        if self._broadcaster is None:
            self._broadcaster = TransformBroadcaster(self._node)
        self._broadcaster.send_items(items)


def scan_arrays(scan: Any) -> tuple[np.ndarray, np.ndarray]:
    """(ranges, angles) of a sensor_msgs/LaserScan as float arrays (NaN/inf kept for the caller)."""
    ranges = np.asarray(scan.ranges, dtype=np.float64)
    angles = scan.angle_min + np.arange(len(ranges)) * scan.angle_increment
    return ranges, angles


def param(node: Any, key: str, default: Any) -> Any:
    """A private parameter with ROS 1's default; a value of the wrong kind is reported and ignored."""
    value = node.get_param("~" + key, default)
    if default is None or value is default:
        return value
    try:
        if isinstance(default, bool):
            if isinstance(value, str):
                raise ValueError
            return bool(value)
        if isinstance(default, int):
            return int(value)
        if isinstance(default, float):
            return float(value)
    except (TypeError, ValueError):
        node.log.error(
            "%s: parameter %s: expected a %s, got %r; using %r",
            node.name,
            node.resolve_name("~" + key),
            type(default).__name__,
            value,
            default,
        )
        return default
    return value
