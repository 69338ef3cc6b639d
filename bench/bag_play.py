"""Playback timing: ninjemys `rosbag play` vs ROS 1's (C++ player), same bag, same subscriber.

    .venv/bin/python bench/bag_play.py [--messages 500]

The bag holds numbered messages with irregular recorded gaps (2-20 ms, seeded). A ninjemys raw
subscriber stamps each arrival on the monotonic clock; we report, per player, the deviation of every
arrival gap from its recorded gap (p50 / p99 / max) and the p99 drift of arrival times from the
recorded schedule (offset of message i from message 0). Uses our roscore on a free port.
"""

from __future__ import annotations

import argparse
import os
import random
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

from ninjemys.bag.play import stand_in_class
from ninjemys.bag.writer import BagWriter
from ninjemys.testing import have_ros1, ninjemys_bin, ros1_env, run_master

HEADER = {
    "type": b"std_msgs/String",
    "md5sum": b"992ce8a1687cec8c8bd883ec73ca41d1",
    "message_definition": b"string data\n",
}
String = stand_in_class("std_msgs/String", "992ce8a1687cec8c8bd883ec73ca41d1", "string data\n")


def make_bag(path: Path, count: int) -> list[int]:
    rng = random.Random(42)
    stamps = []
    t = 1_700_000_000 * 10**9
    with BagWriter(path) as w:
        c = w.connection("/timed", HEADER)
        for i in range(count):
            t += rng.randint(2_000_000, 20_000_000)
            data = b"%08d" % i + b"x" * 100
            w.write(c, t, len(data).to_bytes(4, "little") + data)
            stamps.append(t)
    return stamps


def percentile(values: list[float], q: float) -> float:
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, int(q * len(ordered)))]


def run_player(kind: str, uri: str, bag: Path, node, count: int) -> dict[int, float]:
    arrivals: dict[int, float] = {}
    done = threading.Event()

    def on_msg(raw):
        arrivals[int(bytes(raw.data[4:12]))] = time.monotonic()
        if len(arrivals) >= count:
            done.set()

    sub = node.subscriber("/timed", None, on_msg, raw=True)
    if kind == "ninjemys":
        cmd, env = (
            [ninjemys_bin("rosbag"), "play", "-q", "-d", "1", str(bag)],
            dict(os.environ, ROS_MASTER_URI=uri),
        )
    else:
        cmd, env = ["/usr/bin/rosbag", "play", "-q", "-d", "1", str(bag)], ros1_env(uri)
    proc = subprocess.Popen(cmd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        proc.wait(timeout=120)
        done.wait(5)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
        sub.unregister()
    return arrivals


def report(kind: str, stamps: list[int], arrivals: dict[int, float]) -> tuple[float, float]:
    idx = sorted(arrivals)
    gaps = [
        abs((arrivals[b] - arrivals[a]) - (stamps[b] - stamps[a]) / 1e9) * 1e3
        for a, b in zip(idx, idx[1:], strict=False)
        if b == a + 1
    ]
    first = idx[0]
    drift = [abs((arrivals[i] - arrivals[first]) - (stamps[i] - stamps[first]) / 1e9) * 1e3 for i in idx]
    p99 = percentile(gaps, 0.99)
    print(
        f"{kind:9} received {len(idx)}/{len(stamps)}  gap error ms: p50 {percentile(gaps, 0.5):.3f}  p99 {p99:.3f}  "
        f"max {max(gaps):.3f}   schedule drift p99 {percentile(drift, 0.99):.3f} ms",
        flush=True,
    )
    return p99, percentile(drift, 0.99)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--messages", type=int, default=500)
    args = ap.parse_args()
    from ninjemys.node import Node

    kinds = ["ninjemys"] + (["ROS 1"] if have_ros1() else [])
    results = {}
    with run_master() as uri, tempfile.TemporaryDirectory(prefix="bag_play_") as tmp:
        bag = Path(tmp) / "timed.bag"
        stamps = make_bag(bag, args.messages)
        node = Node("bench_sub", anonymous=True, master_uri=uri)
        try:
            for kind in kinds:
                results[kind] = report(kind, stamps, run_player(kind, uri, bag, node, args.messages))
        finally:
            node.shutdown("bench over")
    if "ROS 1" in results:
        ours, theirs = results["ninjemys"][0], results["ROS 1"][0]
        print(
            f"p99 gap error ratio ROS 1 / ninjemys: x{theirs / ours:.2f} (higher is better for ninjemys); machine shared, noisy"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
