"""Recording throughput: ninjemys `rosbag record` vs ROS 1's (C++ record node) in one run.

    .venv/bin/python bench/bag_record.py [--seconds 2]

A ninjemys publisher (publisher queue 100, like a typical node) sends numbered messages at a rising
ladder of rates to each recorder in turn; after each step the bag is counted. The figure reported
per recorder is the highest rate at which every published message was recorded (zero drops), for
1 KiB messages (msgs/s) and 1 MiB messages (MB/s). Uses our roscore on a free port.
"""

from __future__ import annotations

import argparse
import os
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from ninjemys.bag.play import stand_in_class
from ninjemys.bag.reader import BagReader
from ninjemys.testing import have_ros1, ninjemys_bin, ros1_env, run_master

String = stand_in_class("std_msgs/String", "992ce8a1687cec8c8bd883ec73ca41d1", "string data\n")


def publish(pub, rate: float, seconds: float, size: int) -> int:
    body = b"x" * (size - 16)
    total = int(rate * seconds)
    start = time.monotonic()
    sent = 0
    while sent < total:
        due = int((time.monotonic() - start) * rate) + 1
        while sent < min(due, total):
            data = b"%012d" % sent + body
            pub.publish_raw(len(data).to_bytes(4, "little") + data)
            sent += 1
        time.sleep(0.0005)
    return sent


def subscribed(node, topic: str) -> bool:
    state = node.master.get_system_state()
    return any(t == topic and any("record" in n for n in nodes) for t, nodes in state[1])


def trial(
    kind: str, uri: str, node, pub, topic: str, rate: float, seconds: float, size: int, tmp: Path
) -> tuple[int, int]:
    out = tmp / f"{kind}.bag"
    for stale in (out, Path(str(out) + ".active")):
        stale.unlink(missing_ok=True)
    if kind == "ninjemys":
        env = dict(os.environ, ROS_MASTER_URI=uri)
        cmd = [ninjemys_bin("rosbag"), "record", "-q", "-O", str(out), topic]
    else:
        env = ros1_env(uri)
        cmd = ["/usr/bin/rosbag", "record", "-q", "-O", str(out), topic]
    proc = subprocess.Popen(
        cmd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True
    )
    try:
        deadline = time.monotonic() + 20
        while not (subscribed(node, topic) and pub.get_num_connections()):
            if time.monotonic() > deadline:
                raise RuntimeError(f"{kind} recorder never connected")
            time.sleep(0.05)
        time.sleep(0.3)
        sent = publish(pub, rate, seconds, size)
        time.sleep(1.0)
    finally:
        os.killpg(proc.pid, signal.SIGINT)
        try:
            proc.wait(timeout=60)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
    # ROS 1's `rosbag record` is a wrapper around the C++ record node: wait for the bag to be closed
    active = Path(str(out) + ".active")
    deadline = time.monotonic() + 60
    while active.exists() and time.monotonic() < deadline:
        time.sleep(0.1)
    path = out if out.exists() else active
    with BagReader(path) as r:
        got = r.message_count
    path.unlink()
    return sent, got


def ladder(kind, uri, node, pub, topic, rates, seconds, size, tmp) -> tuple[float, list[str]]:
    best = 0.0
    notes = []
    for rate in rates:
        sent, got = trial(kind, uri, node, pub, topic, rate, seconds, size, tmp)
        notes.append(f"{rate:g}/s: {got}/{sent}")
        print(f"  {kind:9} {size:>8} B @ {rate:>7g}/s: recorded {got}/{sent}", flush=True)
        if got == sent:
            best = rate
        else:
            break
    return best, notes


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--seconds", type=float, default=2.0)
    args = ap.parse_args()
    from ninjemys.node import Node

    kinds = ["ninjemys"] + (["ROS 1"] if have_ros1() else [])
    small_rates = [1000, 2000, 5000, 10000, 20000, 40000]
    big_rates = [10, 25, 50, 100, 200, 400]
    results: dict[tuple[str, str], float] = {}
    with run_master() as uri, tempfile.TemporaryDirectory(prefix="bag_record_") as tmp:
        node = Node("bench_pub", anonymous=True, master_uri=uri)
        try:
            small = node.publisher("/small", String, queue_size=100)
            big = node.publisher("/big", String, queue_size=100)
            for kind in kinds:
                results[(kind, "1KiB")], _ = ladder(
                    kind, uri, node, small, "/small", small_rates, args.seconds, 1024, Path(tmp)
                )
                results[(kind, "1MiB")], _ = ladder(
                    kind, uri, node, big, "/big", big_rates, args.seconds, 1 << 20, Path(tmp)
                )
        finally:
            node.shutdown("bench over")
    print("\nhighest zero-drop rate (ladder steps; machine shared, figures are noisy):")
    for kind in kinds:
        r1 = results[(kind, "1KiB")]
        r2 = results[(kind, "1MiB")]
        print(f"  {kind:9} 1 KiB: {r1:>8g} msgs/s    1 MiB: {r2:>5g} msgs/s = {r2 * 1.048576:7.1f} MB/s")
    if "ROS 1" in kinds:
        for size in ("1KiB", "1MiB"):
            base = results[("ROS 1", size)]
            ratio = results[("ninjemys", size)] / base if base else float("inf")
            print(f"  ratio ninjemys/ROS 1 at {size}: x{ratio:.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
