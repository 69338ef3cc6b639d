"""move_base honours its costmaps' ``transform_tolerance`` as ROS 1's does: a robot pose whose /tf stamp
lags ROS time by more than the tolerance is refused ("Costmap2DROS transform timeout"), and move_base
stands still until the pose is fresh again, instead of steering from where the robot was (under load
/tf reached move_base tenths of a second late and it drove on the newest, stale, pose).

One move_base process on sim time: this test publishes /clock and odom -> base_link with a chosen lag,
sends a goal 1 m ahead and reads /cmd_vel. No simulator, no map (rolling-window costmaps in odom)."""

from __future__ import annotations

import threading
import time
from typing import Any

import pytest

from ninjemys.node import Node
from ninjemys.testing import NodeProcess, WaitTimeout, ninjemys_bin, run_master, wait_until

pytestmark = pytest.mark.timeout(180)

STEP = 0.01  # sim seconds per /clock message, one per wall STEP: real time


class Rig:
    """/clock and a standing robot's odom -> base_link, stamped ``lag`` sim seconds in the past."""

    def __init__(self, uri: str) -> None:
        from ninjemys.idl.loader import get_message_class

        self.node = Node("tf_lag_rig", master_uri=uri)
        self.lag = 0.0
        self.now = 100.0
        self.cmds: list[tuple[float, float, float]] = []  # (sim time, v, w) of each /cmd_vel
        self.lock = threading.Lock()
        Clock = get_message_class("rosgraph_msgs/Clock")
        TFMessage = get_message_class("tf2_msgs/TFMessage")
        self._tf_cls = get_message_class("geometry_msgs/TransformStamped")
        self._clock, self._clock_msg = self.node.publisher("/clock", Clock, queue_size=1), Clock()
        self._tf, self._tf_msg_cls = self.node.publisher("/tf", TFMessage, queue_size=10), TFMessage
        self.goal_cls = get_message_class("geometry_msgs/PoseStamped")
        self.goal_pub = self.node.publisher("/move_base_simple/goal", self.goal_cls, queue_size=1, latch=True)
        self.node.subscriber(
            "/cmd_vel", get_message_class("geometry_msgs/Twist"), self._on_cmd, queue_size=100
        )
        self._running = True
        self._thread = threading.Thread(target=self._run, name="rig-clock", daemon=True)
        self._thread.start()

    def _stamp(self, t: float) -> Any:
        from ninjemys.rostime import Time

        return Time.from_sec(t)

    def _run(self) -> None:
        next_wall = time.monotonic()
        while self._running:
            with self.lock:
                self.now = round(self.now + STEP, 6)
                now, lag = self.now, self.lag
            self._clock_msg.clock = self._stamp(now)
            self._clock.publish(self._clock_msg)
            tr = self._tf_cls()
            tr.header.frame_id, tr.child_frame_id = "odom", "base_link"
            tr.header.stamp = self._stamp(now - lag)
            tr.transform.rotation.w = 1.0
            self._tf.publish(self._tf_msg_cls(transforms=[tr]))
            next_wall += STEP
            time.sleep(max(0.0, next_wall - time.monotonic()))

    def _on_cmd(self, msg: Any) -> None:
        with self.lock:
            self.cmds.append((self.now, msg.linear.x, msg.angular.z))

    def set_lag(self, lag: float) -> float:
        with self.lock:
            self.lag = lag
            return self.now

    def cmds_since(self, t: float) -> list[tuple[float, float, float]]:
        with self.lock:
            return [c for c in self.cmds if c[0] > t]

    def close(self) -> None:
        self._running = False
        self._thread.join(2.0)
        self.node.shutdown("test over")


@pytest.fixture
def rig(tmp_path):
    with run_master() as uri:
        setup = Node("tf_lag_params", master_uri=uri)
        setup.set_param("/use_sim_time", True)
        for cm in ("global_costmap", "local_costmap"):
            setup.set_param(
                f"/move_base/{cm}",
                {"global_frame": "odom", "robot_base_frame": "base_link", "static_map": False,
                 "rolling_window": True, "width": 4.0, "height": 4.0, "update_frequency": 5.0},
            )  # fmt: skip
        setup.shutdown("params set")
        rig = Rig(uri)
        env = {
            "ROS_MASTER_URI": uri,
            "ROS_HOME": str(tmp_path),
            "PATH": "/usr/bin:/bin",
            "PYTHONUNBUFFERED": "1",
        }
        proc = NodeProcess([ninjemys_bin("rosrun"), "move_base", "move_base"], env=env, merge_stderr=True)
        try:
            yield rig, proc
        finally:
            proc.stop()
            rig.close()


def _quietly(fn: Any) -> Any:
    def call() -> bool:
        try:
            return bool(fn())
        except WaitTimeout:
            return False

    return call


def test_move_base_stands_still_on_a_pose_older_than_transform_tolerance(rig) -> None:  # noqa: ANN001
    rig, proc = rig
    wait_until(
        lambda: rig.goal_pub.get_num_connections() > 0, timeout=60, what=f"move_base up\n{proc.describe()}"
    )
    goal = rig.goal_cls()
    goal.header.frame_id = "odom"
    goal.pose.position.x = 1.0
    goal.pose.orientation.w = 1.0

    def driving_since(t: float) -> bool:
        return any(v > 0.02 for _, v, _ in rig.cmds_since(t))

    def goal_taken() -> bool:
        # a goal that comes before move_base's first costmap update is refused: send it again
        rig.goal_pub.publish(goal)
        return wait_until(lambda: driving_since(0.0), timeout=3.0, what="")

    # fresh /tf: move_base drives toward the goal
    wait_until(_quietly(goal_taken), timeout=60, what=f"move_base to drive\n{proc.describe()}", step=0.0)
    # /tf lags ROS time by 0.6 s, twice the default tolerance: refused, the robot is stopped
    since = rig.set_lag(0.6) + 0.5  # what move_base sent before it saw the lag does not count
    wait_until(lambda: len(rig.cmds_since(since)) >= 20, timeout=60, what="commands on a stale pose")
    stale = rig.cmds_since(since)
    assert all(v == 0.0 and w == 0.0 for _, v, w in stale), stale[:10]
    wait_until(lambda: "Costmap2DROS transform timeout" in proc.text(), timeout=30, what="the warning")
    assert "tolerance: 0.3000" in proc.text()
    # fresh again: it drives on (within 0.1 s of lag it always did)
    since = rig.set_lag(0.1)
    wait_until(lambda: driving_since(since), timeout=60, what=f"move_base to drive again\n{proc.describe()}")
