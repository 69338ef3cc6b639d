"""Shared pieces of the navigation tests: a small grid world and a numpy laser for it."""

from __future__ import annotations

import bisect
import collections
import math
import os
import subprocess
import time
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from ninjemys.maps.mapfile import GridMap

RUN = 16  # samples per beam and pass in cast(): 0.2 m at 5 cm cells


def room_map(size: float = 6.0, res: float = 0.05) -> GridMap:
    """A square room with walls and two boxes (the shapes break the symmetry for localization)."""
    n = int(round(size / res))
    data = np.zeros((n, n), dtype=np.int8)
    data[:2, :] = data[-2:, :] = data[:, :2] = data[:, -2:] = 100
    data[30:45, 90:105] = 100  # a box
    data[80:90, 70:110] = 100  # a long low box
    data[60:62, 2:50] = 100  # a wall stub from the left
    return GridMap(data, res, (0.0, 0.0, 0.0))


def cast(grid: GridMap, pose: tuple[float, float, float], angles: np.ndarray, max_range: float) -> np.ndarray:
    """Ranges from ``pose`` along ``angles`` (robot frame) to the first occupied cell, or inf.

    Sampled every quarter cell, RUN samples at a time for the beams that have hit nothing yet: the
    same samples and arithmetic as all of them at once, without the 360 x 400 arrays (a corner of the
    maze closed-loop test cast 800 scans; at once they were 1.4 million page faults and 4 of its 6 s)."""
    step = grid.resolution / 4
    t = np.arange(0.0, max_range, step)
    world = pose[2] + angles
    cos, sin = np.cos(world), np.sin(world)
    ranges = np.full(len(angles), np.inf)
    live = np.arange(len(angles))
    for lo in range(0, len(t), RUN):
        ts = t[lo : lo + RUN]
        xs = pose[0] + cos[live, None] * ts[None, :]
        ys = pose[1] + sin[live, None] * ts[None, :]
        ix = np.floor((xs - grid.origin[0]) / grid.resolution).astype(int)
        iy = np.floor((ys - grid.origin[1]) / grid.resolution).astype(int)
        inside = (ix >= 0) & (ix < grid.width) & (iy >= 0) & (iy < grid.height)
        occ = np.ones(xs.shape, dtype=bool)
        occ[inside] = grid.data[iy[inside], ix[inside]] >= 50
        hit = occ.any(axis=1)
        ranges[live[hit]] = ts[np.argmax(occ[hit], axis=1)]
        live = live[~hit]
        if not live.size:
            break
    return ranges


@pytest.fixture
def room() -> GridMap:
    return room_map()


@pytest.fixture
def laser():
    """(angles, cast) for a 360-beam laser with 5 m range."""
    angles = np.linspace(-math.pi, math.pi, 360, endpoint=False)
    return angles, cast


# -- whole-stack sessions -------------------------------------------------------------------------------

SHARE = Path(__file__).resolve().parents[2] / "src" / "ninjemys" / "packages" / "share"


def world_map(world: str) -> GridMap:
    """The ground-truth map of a shipped world (what the simulator rasterizes)."""
    from ninjemys.maps.mapfile import load_map

    return load_map(SHARE / "puzzlebot_sim" / "maps" / f"{world}.yaml")


def pick_goals(
    world: str, count: int, seed: int, clearance: float = 0.45, spacing: float = 1.5
) -> list[tuple]:
    """``count`` seeded goals (x, y, yaw) on free cells at least ``clearance`` from any obstacle,
    each at least ``spacing`` from the previous one (the first from the start at the origin)."""
    from ninjemys.nav.costmap import distance_transform

    grid = world_map(world)
    reach = int(clearance / grid.resolution) + 1
    dist = distance_transform(grid.data != 0, reach) * grid.resolution
    rows, cols = np.nonzero(dist >= clearance)
    rng = np.random.default_rng(seed)
    goals: list[tuple] = []
    last = (0.0, 0.0)
    while len(goals) < count:
        i = int(rng.integers(len(rows)))
        x, y = grid.cell_to_world(cols[i], rows[i])
        if math.hypot(x - last[0], y - last[1]) < spacing:
            continue
        yaw = float(rng.uniform(-math.pi, math.pi))
        goals.append((round(x, 2), round(y, 2), round(yaw, 2)))
        last = (x, y)
    return goals


class Probe:
    """A test node watching the stack: sim time, ground truth, contact, amcl, TF map -> base_link."""

    def __init__(self, master_uri: str) -> None:
        from ninjemys.idl.loader import get_message_class
        from ninjemys.node import Node
        from ninjemys.tf2.core import BufferCore
        from ninjemys.tf2.node import TransformListener

        self.node = Node("nav_probe", anonymous=True, master_uri=master_uri)
        self.sim_time = 0.0
        self.truth: tuple[float, float, float] | None = None
        self.truth_v = 0.0
        self.truth_w = 0.0
        self.truth_log: collections.deque[tuple[float, tuple[float, float, float]]] = collections.deque(
            maxlen=4000
        )  # (stamp, pose) of the recent ground truth, to compare amcl with the truth of its instant
        self.contacts = 0
        self.amcl: tuple[float, float, float] | None = None
        self.amcl_cov = (0.0, 0.0)
        self.buffer = BufferCore(cache_time=30.0)
        self.listener = TransformListener(self.node, self.buffer)
        Odometry = get_message_class("nav_msgs/Odometry")
        self.node.subscriber("/clock", get_message_class("rosgraph_msgs/Clock"), self._clock, queue_size=1)
        self.node.subscriber("/base_pose_ground_truth", Odometry, self._truth, queue_size=1)
        self.node.subscriber("/contact", get_message_class("std_msgs/Bool"), self._contact, queue_size=10)
        self.node.subscriber(
            "/amcl_pose",
            get_message_class("geometry_msgs/PoseWithCovarianceStamped"),
            self._amcl,
            queue_size=1,
        )
        self.front = math.inf  # nearest return within +-35 degrees ahead
        self._wander_pubs: dict[str, Any] = {}
        self.node.subscriber("/scan", get_message_class("sensor_msgs/LaserScan"), self._scan, queue_size=1)
        self.twist_cls = get_message_class("geometry_msgs/Twist")
        self.pose_cls = get_message_class("geometry_msgs/PoseStamped")

    @staticmethod
    def _yaw(q) -> float:
        return math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z))

    def _clock(self, msg) -> None:
        self.sim_time = msg.clock.to_sec()

    def _truth(self, msg) -> None:
        p = msg.pose.pose
        self.truth = (p.position.x, p.position.y, self._yaw(p.orientation))
        t = msg.header.stamp.to_sec()
        if self.truth_log and t < self.truth_log[-1][0]:
            self.truth_log.clear()  # the clock went back (a world reset): keep the log in time order
        self.truth_log.append((t, self.truth))
        self.truth_v = msg.twist.twist.linear.x
        self.truth_w = msg.twist.twist.angular.z

    def _scan(self, msg) -> None:
        r = np.asarray(msg.ranges, dtype=float)
        a = msg.angle_min + np.arange(len(r)) * msg.angle_increment
        ahead = np.abs((a + math.pi) % (2 * math.pi) - math.pi) < math.radians(35)
        r = np.where(np.isneginf(r), 0.0, r)
        self.front = float(np.nanmin(np.where(ahead, r, np.inf)))

    def wander(self, seconds: float, topic: str = "/teleop/cmd_vel") -> None:
        """Drive reactively for ``seconds`` of sim time: ahead while the way is clear, else turn left."""
        pub = self._wander_pubs.get(topic)
        if pub is None:  # one publisher per topic for the probe's life: a new one per call would stand
            # the robot still for its connection time on every call (2 s of sim time at rate 4)
            pub = self._wander_pubs[topic] = self.node.publisher(topic, self.twist_cls, queue_size=1)
            deadline = time.monotonic() + 5.0
            while pub.get_num_connections() == 0 and time.monotonic() < deadline:
                time.sleep(0.02)
            time.sleep(0.2)
        end = self.sim_time + seconds
        deadline = time.monotonic() + seconds * 3 + 60
        turning_until = 0.0
        while self.sim_time < end and time.monotonic() < deadline:
            msg = self.twist_cls()
            if self.sim_time < turning_until:
                msg.angular.z = 0.8
            elif self.front < 0.7:
                turning_until = self.sim_time + 1.0 + (hash(round(self.sim_time, 1)) % 10) / 10.0
                msg.angular.z = 0.8
            else:
                msg.linear.x = 0.25
            pub.publish(msg)
            time.sleep(0.02)
        pub.publish(self.twist_cls())

    def _contact(self, msg) -> None:
        if msg.data:
            self.contacts += 1

    def _amcl(self, msg) -> None:
        p = msg.pose.pose
        self.amcl = (p.position.x, p.position.y, self._yaw(p.orientation))
        self.amcl_cov = (msg.pose.covariance[0], msg.pose.covariance[7])

    def localized(self) -> tuple[float, float, float] | None:
        """The robot's pose in the map frame through TF (amcl's map -> odom, the sim's odom -> base)."""
        from ninjemys.nav.rosglue import tf_to_2d
        from ninjemys.tf2.errors import TransformException

        try:
            return tf_to_2d(self.buffer.lookup("map", "base_link", 0)[1])
        except TransformException:
            return None

    def truth_at(self, t: float) -> tuple[float, float, float] | None:
        """The ground truth at ROS time ``t`` (interpolated), or None when the log does not hold it."""
        log = list(self.truth_log)
        stamps = [s for s, _ in log]
        i = bisect.bisect_left(stamps, t)
        if i == len(log) or (i == 0 and stamps[0] != t):
            return None
        s1, p1 = log[i]
        if s1 == t or i == 0:
            return p1
        s0, p0 = log[i - 1]
        f = (t - s0) / (s1 - s0)
        return (p0[0] + f * (p1[0] - p0[0]), p0[1] + f * (p1[1] - p0[1]), p1[2])

    def localized_at(self, t: float) -> tuple[float, float, float] | None:
        """The pose through TF (``map -> base_link``) at ROS time ``t``, or None."""
        from ninjemys.nav.rosglue import tf_to_2d
        from ninjemys.tf2.errors import TransformException

        try:
            return tf_to_2d(self.buffer.lookup("map", "base_link", int(round(t * 1e9)))[1])
        except TransformException:
            return None

    def localized_with_truth(self) -> tuple[tuple[float, float, float], tuple[float, float, float]] | None:
        """(the pose through TF at its latest stamp, the ground truth of that same stamp), or None.

        Comparing TF with the newest ground truth instead would charge amcl with however far the robot
        drove while this process's TF listener caught up with /tf (under load, tenths of a second)."""
        from ninjemys.nav.rosglue import tf_to_2d
        from ninjemys.tf2.errors import TransformException

        try:
            stamp_ns, tf = self.buffer.lookup("map", "base_link", 0)
        except TransformException:
            return None
        truth = self.truth_at(stamp_ns * 1e-9)
        return None if truth is None else (tf_to_2d(tf), truth)

    def wait_sim(self, seconds: float, timeout: float = 120.0) -> None:
        """Sleep ``seconds`` of simulated time."""
        end = self.sim_time + seconds
        deadline = time.monotonic() + timeout
        while self.sim_time < end and time.monotonic() < deadline:
            time.sleep(0.02)

    def close(self) -> None:
        self.node.shutdown()


class NavSession:
    """A master, ``roslaunch puzzlebot_navigation <file> <args>`` (a :class:`NodeProcess`) and a
    :class:`Probe`; closed in order, the launch's output saved to ``launch.log`` for a post-mortem."""

    def __init__(self, launch_file: str, args: list[str], tmp_path: Path) -> None:
        from ninjemys.testing import NodeProcess, ninjemys_bin, run_master

        self._master = run_master()
        self.uri = self._master.__enter__()
        self.env = dict(os.environ)
        self.env.update(ROS_MASTER_URI=self.uri, ROS_HOME=str(tmp_path / "ros_home"), PYTHONUNBUFFERED="1")
        self.log_path = tmp_path / "launch.log"
        try:
            self.launch = NodeProcess(
                [ninjemys_bin("roslaunch"), "puzzlebot_navigation", launch_file, *args],
                env=self.env,
                merge_stderr=True,
            )
        except BaseException:
            self._master.__exit__(None, None, None)
            raise
        self.probe = Probe(self.uri)

    def log(self) -> str:
        """Everything roslaunch and its nodes printed so far."""
        return self.launch.text()

    def alive(self) -> bool:
        """Whether roslaunch is still running (it exits when a required node dies)."""
        return self.launch.proc.poll() is None

    def wait_for(self, predicate, timeout: float = 60.0) -> bool:
        """Whether ``predicate`` came true within ``timeout`` s (False at once if roslaunch ended)."""
        from ninjemys.testing import WaitTimeout, wait_until

        try:
            wait_until(lambda: predicate() or not self.alive(), timeout, "the navigation session")
        except WaitTimeout:
            return False
        return bool(predicate())

    def close(self) -> None:
        """Ctrl-C to roslaunch (it stops its nodes in order), then SIGKILL to whatever is left."""
        self.probe.close()
        if self.alive():
            self.launch.interrupt()
            try:
                self.launch.wait(20)
            except subprocess.TimeoutExpired:
                pass
        self.launch.stop(grace=0)
        self.log_path.write_text(self.log())
        self._master.__exit__(None, None, None)
