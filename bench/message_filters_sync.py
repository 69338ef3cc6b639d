"""ApproximateTimeSynchronizer CPU: ninjemys vs Debian's python3-message-filters, same program, one run.

    .venv/bin/python bench/message_filters_sync.py [--seconds 10] [--rate 100]

One publisher (a ninjemys node in this process) sends sensor_msgs/Imu on /imu0, /imu1 and /imu2 at
``--rate`` Hz each, the three stamps of a round a few ms apart (seeded jitter). The same subscriber
program -- ``rospy.init_node``, three ``message_filters.Subscriber``, an
``ApproximateTimeSynchronizer(subs, 10, 0.01)`` -- runs at the same time under our venv (our rospy and
message_filters) and under /usr/bin/python3 (Debian's). Each measures its own CPU time (``time.process_time``: all threads, user+system) from its first message for ``--seconds`` and counts the synchronized sets. Uses our
roscore on a free port.

A second part times the synchronizer alone: the same 3 x ``--rounds`` stamped messages (seeded) fed
straight into each implementation's ApproximateTimeSynchronizer in one process, without a network,
so the library's own cost shows apart from each client library's receive path.
"""

from __future__ import annotations

import argparse
import json
import os
import random
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from ninjemys.idl.loader import get_message_class
from ninjemys.node import Node
from ninjemys.rostime import Time
from ninjemys.testing import have_ros1, ros1_env, run_master

SUBSCRIBER = """
import json, sys, threading, time
import rospy, message_filters
from sensor_msgs.msg import Imu

seconds = float(sys.argv[1])
rospy.init_node("sync_bench", anonymous=True)
state = {"sets": 0, "start": None, "t0": None}
done = threading.Event()

def on_set(a, b, c):
    if state["start"] is None:
        state["start"] = time.process_time()
        state["t0"] = rospy.get_time()
        return
    state["sets"] += 1
    if rospy.get_time() - state["t0"] >= seconds:
        done.set()

subs = [message_filters.Subscriber("/imu%d" % i, Imu, queue_size=50) for i in range(3)]
sync = message_filters.ApproximateTimeSynchronizer(subs, 10, 0.01)
sync.registerCallback(on_set)
print("ready", flush=True)
done.wait(seconds + 60)
end = time.process_time()
cpu = end - state["start"] if state["start"] is not None else float("nan")
print(json.dumps({"cpu": cpu, "sets": state["sets"], "wall": rospy.get_time() - (state["t0"] or 0)}), flush=True)
rospy.signal_shutdown("done")
"""


ALGORITHM = """
import json, random, sys
import message_filters
import rospy.rostime
if hasattr(rospy.rostime, "set_rostime_initialized"):
    rospy.rostime.set_rostime_initialized(True)  # Debian's rospy: Time.now() without init_node
from std_msgs.msg import Header

rounds = int(sys.argv[1])
class Stamped:
    __slots__ = ("header",)
    def __init__(self, ns):
        self.header = Header()
        self.header.stamp.secs, self.header.stamp.nsecs = divmod(ns, 1000000000)
rng = random.Random(1)
base = 1700000000 * 10**9
msgs = [(i, Stamped(base + k * 10000000 + rng.randint(0, 4000000))) for k in range(rounds) for i in range(3)]
sources = [message_filters.SimpleFilter() for _ in range(3)]
sync = message_filters.ApproximateTimeSynchronizer(sources, 10, 0.01)
sets = []
sync.registerCallback(lambda a, b, c: sets.append(1))
import time
start = time.process_time()
for i, m in msgs:
    sources[i].signalMessage(m)
cpu = time.process_time() - start
print(json.dumps({"cpu": cpu, "sets": len(sets), "msgs": len(msgs)}))
"""


def time_algorithm(python: str, env: dict[str, str], script: Path, rounds: int) -> dict[str, float]:
    out = subprocess.run(
        [python, str(script), str(rounds)], env=env, capture_output=True, text=True, timeout=300
    )
    if out.returncode != 0:
        raise RuntimeError(f"{python}: {out.stderr.strip().splitlines()[-1:]}")
    return json.loads(out.stdout)


def start_subscriber(
    cmd: list[str], env: dict[str, str], script: Path, seconds: float
) -> subprocess.Popen[str]:
    proc = subprocess.Popen(
        [*cmd, str(script), str(seconds)],
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
        text=True,
    )
    assert proc.stdout is not None
    line = proc.stdout.readline().strip()
    if line != "ready":
        raise RuntimeError(f"{cmd[0]} subscriber did not start: {line!r}")
    return proc


def publish(uri: str, rate: float, stop: list[subprocess.Popen[str]]) -> int:
    Imu = get_message_class("sensor_msgs/Imu")
    node = Node("imu_publisher", master_uri=uri)
    sent = 0
    try:
        pubs = [node.publisher(f"/imu{i}", Imu, queue_size=100) for i in range(3)]
        deadline = time.monotonic() + 20
        while any(p.get_num_connections() < len(stop) for p in pubs) and time.monotonic() < deadline:
            time.sleep(0.01)
        rng = random.Random(7)
        period = 1.0 / rate
        next_t = time.monotonic()
        msgs = [Imu() for _ in range(3)]
        while any(p.poll() is None for p in stop):
            base = Time.now().to_nsec()
            for i, (pub, msg) in enumerate(zip(pubs, msgs, strict=True)):
                msg.header.seq = sent
                msg.header.stamp = Time(*divmod(base + rng.randint(0, 4_000_000), 1_000_000_000))
                msg.header.frame_id = f"imu{i}"
                pub.publish(msg)
            sent += 1
            next_t += period
            time.sleep(max(0.0, next_t - time.monotonic()))
    finally:
        node.shutdown("bench done")
    return sent


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=10.0)
    parser.add_argument("--rate", type=float, default=100.0)
    parser.add_argument(
        "--rounds", type=int, default=20000, help="message triples for the synchronizer-only part"
    )
    args = parser.parse_args()
    if not have_ros1():
        print("Debian's ROS 1 is not installed (make test installs it)", file=sys.stderr)
        return 1
    with tempfile.TemporaryDirectory() as tmp, run_master() as uri:
        script = Path(tmp) / "sync_sub.py"
        script.write_text(SUBSCRIBER)
        ours_env = dict(os.environ, ROS_MASTER_URI=uri, ROS_HOME=tmp)
        procs = {
            "ninjemys": start_subscriber([sys.executable], ours_env, script, args.seconds),
            "ROS 1": start_subscriber(
                ["/usr/bin/python3"], ros1_env(uri, ROS_HOME=tmp), script, args.seconds
            ),
        }
        sent = publish(uri, args.rate, list(procs.values()))
        results = {}
        for name, proc in procs.items():
            out, _ = proc.communicate(timeout=60)
            results[name] = json.loads(out.strip().splitlines()[-1])
        algo_script = Path(tmp) / "sync_algo.py"
        algo_script.write_text(ALGORITHM)
        algo = {
            "ninjemys": time_algorithm(sys.executable, ours_env, algo_script, args.rounds),
            "ROS 1": time_algorithm(
                "/usr/bin/python3", ros1_env(uri, ROS_HOME=tmp), algo_script, args.rounds
            ),
        }
    load = os.getloadavg()[0]
    print(f"ApproximateTimeSynchronizer, 3 x sensor_msgs/Imu at {args.rate:.0f} Hz, {args.seconds:.0f} s "
          f"(load average {load:.2f}, {sent} rounds sent)")  # fmt: skip
    print(f"{'':10} {'CPU s':>8} {'sets':>6} {'CPU ms/s':>9}")
    for name, r in results.items():
        print(f"{name:10} {r['cpu']:8.3f} {r['sets']:6d} {1000 * r['cpu'] / r['wall']:9.1f}")
    ratio = results["ninjemys"]["cpu"] / results["ROS 1"]["cpu"]
    print(f"ratio ninjemys / ROS 1, whole subscriber process: {ratio:.2f}x (target <= 0.5x)")
    print(f"synchronizer alone, {args.rounds} x 3 stamped messages, no network:")
    for name, r in algo.items():
        print(f"{name:10} {r['cpu']:8.3f} s {r['sets']:6d} sets {1e6 * r['cpu'] / r['msgs']:6.2f} us/msg")
    print(
        f"ratio ninjemys / ROS 1, synchronizer alone: {algo['ninjemys']['cpu'] / algo['ROS 1']['cpu']:.2f}x"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
