"""The local planner's control cycle at 20 Hz beside the running simulator (the issue's target: fewer
than 1 missed cycle per 1,000).

Starts our roscore and the PuzzleBot simulator (office, real time), feeds its scans into a rolling
local costmap in this process, and runs the control cycle (costmap update + DWA) every 50 ms of wall
time for ``N`` cycles while the robot drives along a plan down the office corridor. A cycle is missed
when its work ends after the next cycle's start; the cycle's CPU time is printed beside its wall
time, to tell the planner's cost from waiting for a core. Debian ships no dwa_local_planner, so the reference
printed is the target. Run alone: ``.venv/bin/python bench/nav_dwa.py [cycles]``.
"""

from __future__ import annotations

import math
import os
import signal
import subprocess
import sys
import threading
import time

import numpy as np

from ninjemys.idl.loader import get_message_class
from ninjemys.nav.costmap import Costmap, CostmapParams
from ninjemys.nav.dwa import DWAParams, DWAPlanner
from ninjemys.node import Node
from ninjemys.testing import ninjemys_bin, run_master

PERIOD = 0.05


def main() -> None:
    cycles = int(sys.argv[1]) if len(sys.argv) > 1 else 1000
    with run_master() as uri:
        env = dict(os.environ, ROS_MASTER_URI=uri)
        sim = subprocess.Popen(
            [ninjemys_bin("rosrun"), "puzzlebot_sim", "sim_node", "_world:=office", "_gui:=false"],
            env=env,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
            start_new_session=True,
        )
        node = Node("dwa_bench", master_uri=uri)
        lock = threading.Lock()
        latest: dict[str, object] = {}
        node.subscriber(
            "/scan",
            get_message_class("sensor_msgs/LaserScan"),
            lambda m: latest.__setitem__("scan", m),
            queue_size=1,
        )
        node.subscriber(
            "/odom",
            get_message_class("nav_msgs/Odometry"),
            lambda m: latest.__setitem__("odom", m),
            queue_size=1,
        )
        cmd = node.publisher("/cmd_vel", get_message_class("geometry_msgs/Twist"), queue_size=1)
        cm = Costmap(
            CostmapParams(rolling_window=True, width=3.0, height=3.0, robot_radius=0.16, inflation_radius=0.4)
        )
        dwa = DWAPlanner(DWAParams())
        xs = np.linspace(0.0, 10.0, 200)
        dwa.set_plan(np.column_stack([xs, np.zeros_like(xs), np.zeros_like(xs)]))
        try:
            deadline = time.monotonic() + 30
            while "odom" not in latest or "scan" not in latest:
                if time.monotonic() > deadline:
                    raise SystemExit("the simulator did not start")
                time.sleep(0.1)
            missed, work, cpu = 0, [], []
            start = time.monotonic()
            for k in range(cycles):
                t0, c0 = time.monotonic(), time.thread_time()
                with lock:
                    odom, scan = latest["odom"], latest["scan"]
                p = odom.pose.pose  # type: ignore[attr-defined]
                yaw = 2 * math.atan2(p.orientation.z, p.orientation.w)
                cm.update_origin(p.position.x, p.position.y)
                ranges = np.asarray(scan.ranges, dtype=float)  # type: ignore[attr-defined]
                angles = scan.angle_min + np.arange(len(ranges)) * scan.angle_increment  # type: ignore[attr-defined]
                cm.add_scan(p.position.x, p.position.y, yaw + angles, ranges, scan.range_max)  # type: ignore[attr-defined]
                cm.update()
                c = dwa.compute(
                    (p.position.x, p.position.y, yaw),
                    (odom.twist.twist.linear.x, odom.twist.twist.angular.z),
                    cm,
                )  # type: ignore[attr-defined]
                msg = get_message_class("geometry_msgs/Twist")()
                msg.linear.x, msg.angular.z = c.v, c.w
                cmd.publish(msg)
                t1 = time.monotonic()
                work.append(t1 - t0)
                cpu.append(time.thread_time() - c0)
                next_start = start + (k + 1) * PERIOD
                if t1 > next_start:
                    missed += 1
                else:
                    time.sleep(next_start - t1)
        finally:
            node.shutdown()
            os.killpg(sim.pid, signal.SIGINT)
            try:
                sim.wait(10)
            except subprocess.TimeoutExpired:
                os.killpg(sim.pid, signal.SIGKILL)
    w = np.array(work) * 1000
    c = np.array(cpu) * 1000
    print(f"load average {os.getloadavg()[0]:.2f} (2 cores shared)")
    # the cycle's own cost (CPU time of this thread) against its wall time: the difference is
    # waiting for a core (the load) or for the GIL (this process's message threads)
    print(f"cycle CPU time: median {np.median(c):.1f} ms, p99 {np.percentile(c, 99):.1f} ms")
    print(
        f"local planner cycle (costmap + DWA, {DWAParams().vx_samples}x{DWAParams().vth_samples} samples): "
        f"median {np.median(w):.1f} ms, p99 {np.percentile(w, 99):.1f} ms, max {w.max():.1f} ms; "
        f"missed {missed} of {cycles} cycles at 20 Hz ({1000 * missed / cycles:.1f} per 1,000)  | target < 1 per 1,000"
    )


if __name__ == "__main__":
    main()
