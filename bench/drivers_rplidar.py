"""rplidar_ros' rplidarNode at 8k samples/s (A2/A3-class express scans): CPU of the node and scan latency.

An emulated RPLIDAR (tests/drivers/emu_rplidar.py, on a pty) streams EXPRESS_SCAN capsules of a known
room at 8000 samples/s; our rplidarNode decodes them into /scan (angle-compensated, 720 beams). Printed:
the node's CPU (user+system over the window, % of one core; the issue's target is at most 5 %), the
scan rate, and the latency from the end of a revolution as the node stamps it (header.stamp +
scan_time) to delivery at a subscriber in another process. Debian ships no rplidar_ros, so the reference
printed is the target. Run alone: ``.venv/bin/python bench/drivers_rplidar.py [seconds] [--sensitivity]``;
``--sensitivity`` runs an emulated A3 in its Sensitivity mode instead: ultra capsules at 16.1k
samples/s, 1440 beams per scan.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "drivers"))

from emu_rplidar import EmulatedA1, EmulatedA3  # noqa: E402

from ninjemys.idl.loader import get_message_class  # noqa: E402
from ninjemys.node import Node  # noqa: E402
from ninjemys.testing import run_master  # noqa: E402

TARGET = 5.0
TICK = os.sysconf("SC_CLK_TCK")


def cpu_seconds(pid: int) -> float:
    with open(f"/proc/{pid}/stat") as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / TICK


def main() -> None:
    sensitivity = "--sensitivity" in sys.argv
    numbers = [a for a in sys.argv[1:] if not a.startswith("--")]
    window = float(numbers[0]) if numbers else 20.0
    lidar: EmulatedA1
    if sensitivity:
        lidar = EmulatedA3()
        mode_args = ["_scan_mode:=Sensitivity"]
    else:
        lidar = EmulatedA1(samples_per_s=8000.0)
        lidar.express_per_rev = 800  # 10 revolutions a second, as an A2 at 8k samples/s
        mode_args = []
    LaserScan = get_message_class("sensor_msgs/LaserScan")
    with run_master() as uri:
        env = dict(os.environ, ROS_MASTER_URI=uri)
        proc = subprocess.Popen(
            [
                sys.executable,
                "-m",
                "ninjemys.packages.run_shipped",
                "rplidar_ros",
                "rplidarNode",
                f"_serial_port:={lidar.path}",
                "_angle_compensate:=true",
                "_serial_baudrate:=256000",
                *mode_args,
            ],
            env=env,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        node = Node("bench_scan", master_uri=uri)
        lat: list[float] = []
        beams: list[int] = []
        lock = threading.Lock()

        def on_scan(m) -> None:  # noqa: ANN001
            now = time.time()
            marks = [t for t in lidar.rev_marks[-5:] if t <= now]
            if not marks:
                return
            with lock:
                lat.append(now - marks[-1])
                beams.append(len(m.ranges))

        node.subscriber("/scan", LaserScan, on_scan)
        try:
            deadline = time.monotonic() + 30
            while not lat and time.monotonic() < deadline:
                time.sleep(0.1)
            if not lat:
                raise SystemExit("no /scan within 30 s")
            time.sleep(2.0)  # settle
            with lock:
                lat.clear()
            c0, t0, s0 = cpu_seconds(proc.pid), time.monotonic(), lidar.sent_samples
            time.sleep(window)
            c1, t1, s1 = cpu_seconds(proc.pid), time.monotonic(), lidar.sent_samples
            with lock:
                got = sorted(lat)
                nbeams = beams[-1]
        finally:
            proc.send_signal(signal.SIGINT)
            proc.wait(20)
            node.shutdown()
            lidar.close()
    cpu = 100.0 * (c1 - c0) / (t1 - t0)
    rate = (s1 - s0) / (t1 - t0)
    load = os.getloadavg()
    print(
        f"rplidarNode, {'Sensitivity (ultra capsules)' if sensitivity else 'express'} scans at {rate:.0f} samples/s, {nbeams} beams per scan, {len(got) / (t1 - t0):.1f} scans/s"
    )
    print(
        f"  CPU of the node: {cpu:.1f} % of one core (target <= {TARGET:.0f} %: {cpu / TARGET:.2f} x the target)"
    )
    print(
        f"  latency device (revolution closed) -> subscriber: median {1000 * got[len(got) // 2]:.1f} ms, "
        f"p95 {1000 * got[int(len(got) * 0.95)]:.1f} ms (one revolution lasts {1000 / max(len(got) / (t1 - t0), 1e-9):.0f} ms)"
    )
    print(f"  load average {load[0]:.2f} {load[1]:.2f} {load[2]:.2f}")


if __name__ == "__main__":
    main()
