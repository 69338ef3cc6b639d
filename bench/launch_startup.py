"""roslaunch benchmark: a 20-node launch, ours vs Debian's real roslaunch, side by side.

Measures, for each implementation (the master auto-started by roslaunch in both cases):

* startup: from starting ``roslaunch`` until all 20 nodes are registered with the master;
* shutdown: from SIGINT (Ctrl-C) to roslaunch exiting with every process gone.

The nodes are the same rospy script: real roslaunch runs it with Debian's rospy
(/usr/bin/python3), ours with ninjemys' rospy. Run: ``.venv/bin/python bench/launch_startup.py [runs]``.
The machine may be shared: figures are medians of several runs and vary from run to run.
"""

from __future__ import annotations

import os
import signal
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from ninjemys.errors import NinjemysError
from ninjemys.master.client import MasterClient
from ninjemys.testing import free_port, have_ros1, ninjemys_bin, ros1_env

NODES = 20

NODE_SCRIPT = """#!/usr/bin/python3
import rospy
from std_msgs.msg import String

rospy.init_node("bench_node")
rospy.Subscriber("chatter", String, lambda msg: None)
rospy.spin()
"""


def make_package(root: Path) -> Path:
    pkg = root / "bench_launch"
    (pkg / "scripts").mkdir(parents=True)
    (pkg / "package.xml").write_text(
        '<package format="2"><name>bench_launch</name><version>0.0.1</version>'
        "<description>bench</description><maintainer email='b@b.b'>b</maintainer><license>BSD</license>"
        "<buildtool_depend>catkin</buildtool_depend></package>"
    )
    script = pkg / "scripts" / "node.py"
    script.write_text(NODE_SCRIPT)
    script.chmod(0o755)
    nodes = "\n".join(f'  <node name="n{i}" pkg="bench_launch" type="node.py"/>' for i in range(NODES))
    launch = pkg / "twenty.launch"
    launch.write_text(f"<launch>\n{nodes}\n</launch>\n")
    return launch


def all_registered(uri: str) -> bool:
    client = MasterClient(uri, "/bench", timeout=2.0)
    try:
        for i in range(NODES):
            client.lookup_node(f"/n{i}")
        return True
    except NinjemysError:
        return False
    finally:
        client.close()


def master_gone(uri: str) -> bool:
    try:
        MasterClient(uri, "/bench", timeout=0.5).get_pid()
        return False
    except NinjemysError:
        return True


def run_once(command: list[str], env: dict[str, str], uri: str) -> tuple[float, float]:
    start = time.monotonic()
    proc = subprocess.Popen(command, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        deadline = start + 120
        while not all_registered(uri):
            if time.monotonic() > deadline or proc.poll() is not None:
                raise RuntimeError(f"{command[0]}: nodes did not register")
            time.sleep(0.01)
        startup = time.monotonic() - start
        stop = time.monotonic()
        proc.send_signal(signal.SIGINT)
        proc.wait(120)
        while not master_gone(uri):
            time.sleep(0.01)
        shutdown = time.monotonic() - stop
        return startup, shutdown
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()


def main() -> int:
    runs = int(sys.argv[1]) if len(sys.argv) > 1 else 3
    if not have_ros1():
        print("Debian's ROS 1 is not installed: nothing to compare against", file=sys.stderr)
        return 1
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp)
        launch = make_package(root / "pkgs")
        results: dict[str, list[tuple[float, float]]] = {"ninjemys": [], "ROS 1": []}
        for _ in range(runs):
            for impl in ("ninjemys", "ROS 1"):
                port = free_port()
                uri = f"http://localhost:{port}"
                home = root / f"home_{impl.replace(' ', '')}_{port}"
                if impl == "ninjemys":
                    env = dict(
                        os.environ,
                        ROS_MASTER_URI=uri,
                        ROS_PACKAGE_PATH=str(root / "pkgs"),
                        ROS_HOME=str(home),
                    )
                    command = [ninjemys_bin("roslaunch"), str(launch)]
                else:
                    env = ros1_env(uri, ROS_PACKAGE_PATH=str(root / "pkgs"), ROS_HOME=str(home))
                    command = ["/usr/bin/roslaunch", str(launch)]
                results[impl].append(run_once(command, env, uri))
    ours_up = statistics.median(r[0] for r in results["ninjemys"])
    ros_up = statistics.median(r[0] for r in results["ROS 1"])
    ours_down = statistics.median(r[1] for r in results["ninjemys"])
    ros_down = statistics.median(r[1] for r in results["ROS 1"])
    print(
        f"roslaunch, {NODES} rospy nodes, master auto-started, median of {runs} runs (load: {os.getloadavg()[0]:.1f})"
    )
    print(f"{'metric':<40} {'ninjemys':>10} {'ROS 1':>10} {'ratio':>8}")
    print(
        f"{'start -> all nodes registered (s)':<40} {ours_up:>10.2f} {ros_up:>10.2f} {ours_up / ros_up:>8.2f}"
    )
    print(
        f"{'Ctrl-C -> everything stopped (s)':<40} {ours_down:>10.2f} {ros_down:>10.2f} {ours_down / ros_down:>8.2f}"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
