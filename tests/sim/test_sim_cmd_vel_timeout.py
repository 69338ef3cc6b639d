"""sim_node's ``~cmd_vel_timeout``: with it the wheels stop when commands stop (diff_drive_controller's
behaviour, so a starved driver cannot leave the robot driving blind); without it (the default, as
Gazebo's diff drive plugin) the last command holds."""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

import pytest

from ninjemys.packages.shipped import shipped_executable
from ninjemys.testing import run_master, wait_until


def drive_once_then_watch(tmp_path: Path, *params: str) -> tuple[float, float]:
    """Start the sim (square world, rate 4), send ONE forward command, and return the ground-truth
    speed 1 s and 3 s of sim time later."""
    from geometry_msgs.msg import Twist
    from nav_msgs.msg import Odometry
    from ninjemys.node import Node
    from rosgraph_msgs.msg import Clock

    with run_master() as uri:
        env = dict(os.environ, ROS_MASTER_URI=uri, PYTHONUNBUFFERED="1")
        cmd = shipped_executable("puzzlebot_sim", "sim_node").command(
            ["_world:=square", "_rate:=4.0", "_gui:=false", *params]
        )
        log = tmp_path / "sim.log"
        with open(log, "wb") as out:
            proc = subprocess.Popen(
                cmd, env=env, stdout=out, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL
            )
        node = Node("timeout_test", anonymous=True, master_uri=uri)
        try:
            state = {"v": None, "t": 0.0}
            node.subscriber(
                "/base_pose_ground_truth", Odometry, lambda m: state.update(v=m.twist.twist.linear.x)
            )
            node.subscriber("/clock", Clock, lambda m: state.update(t=m.clock.to_sec()))
            pub = node.publisher("/cmd_vel", Twist, queue_size=1)
            wait_until(lambda: state["v"] is not None and pub.get_num_connections(), 30, "the simulator")
            msg = Twist()
            msg.linear.x = 0.2
            pub.publish(msg)
            start = state["t"]
            speeds = []
            for after in (1.0, 3.0):
                wait_until(lambda a=after: state["t"] >= start + a, 30, f"{after} s of sim time")
                speeds.append(state["v"])
            return speeds[0], speeds[1]
        finally:
            node.shutdown("test over")
            proc.terminate()
            try:
                proc.wait(10)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()


def test_without_a_timeout_the_last_command_holds(tmp_path):
    early, late = drive_once_then_watch(tmp_path)
    assert early == pytest.approx(0.2, abs=0.01) and late == pytest.approx(0.2, abs=0.01)


def test_a_timeout_stops_the_wheels_when_commands_stop(tmp_path):
    early, late = drive_once_then_watch(tmp_path, "_cmd_vel_timeout:=2.0")
    assert early == pytest.approx(0.2, abs=0.01)  # within the timeout: driving
    assert abs(late) < 1e-6  # 2 s after the only command: stopped
