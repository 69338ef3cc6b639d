"""The seeds' PuzzleBot activity (examples/puzzlebot) runs as printed against the simulator; the final
pose is compared with the simulator's ground truth."""

from __future__ import annotations

import math
import os
import subprocess
import sys
import threading
from pathlib import Path

import pytest

from ninjemys.packages.shipped import shipped_executable
from ninjemys.testing import run_master

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "puzzlebot" / "scripts"


@pytest.fixture
def sim_master(tmp_path):  # type: ignore[no-untyped-def]
    with run_master() as master:
        log = tmp_path / "sim.log"
        cmd = shipped_executable("puzzlebot_sim", "sim_node").command(
            ["_world:=square", "_rate:=4.0", "_gui:=false"]
        )
        with open(log, "wb") as out:
            proc = subprocess.Popen(
                cmd, env=dict(os.environ, ROS_MASTER_URI=master), stdout=out, stderr=subprocess.STDOUT
            )
        try:
            import time

            deadline = time.monotonic() + 20
            while "PuzzleBot simulator:" not in log.read_text():
                assert proc.poll() is None and time.monotonic() < deadline, log.read_text()
                time.sleep(0.05)
            yield master
        finally:
            proc.terminate()
            try:
                proc.wait(10)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()


def ground_truth(master: str) -> tuple[float, float, float]:
    from nav_msgs.msg import Odometry
    from ninjemys.node import Node

    node = Node("gt_reader", anonymous=True, master_uri=master)
    got = threading.Event()
    box: list = []

    def on(msg) -> None:  # type: ignore[no-untyped-def]
        if not box:
            box.append(msg)
            got.set()

    try:
        node.subscriber("/base_pose_ground_truth", Odometry, on)
        assert got.wait(20)
    finally:
        node.shutdown("done")
    p = box[0].pose.pose
    return p.position.x, p.position.y, 2 * math.atan2(p.orientation.z, p.orientation.w)


def run_example(master: str, name: str, *params: str) -> str:
    done = subprocess.run(
        [sys.executable, str(EXAMPLE / name), *params],
        env=dict(os.environ, ROS_MASTER_URI=master),
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 0, done.stderr
    return done.stdout


def test_straight_line_example(sim_master):
    out = run_example(sim_master, "straight_line.py", "_distance:=1.0")
    assert "straight line done" in out
    x, y, yaw = ground_truth(sim_master)
    print(f"straight line, 1 m at 0.2 m/s: ground truth x={x:.4f} y={y:.4f} yaw={yaw:.4f}")
    assert abs(x - 1.0) < 0.05 and abs(y) < 1e-6 and abs(yaw) < 1e-6  # open loop: a little overshoot


def test_square_example(sim_master):
    out = run_example(sim_master, "square.py")
    assert "square done" in out
    x, y, yaw = ground_truth(sim_master)
    err = math.hypot(x, y)
    print(
        f"1 m square at 0.2 m/s, 0.5 rad/s: back at x={x:.4f} y={y:.4f} yaw={yaw:.4f} (position error {err:.4f} m)"
    )
    assert err < 0.15 and abs(math.atan2(math.sin(yaw), math.cos(yaw))) < 0.15  # open loop, 4x sim time
