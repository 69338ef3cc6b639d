"""Every message the simulator publishes over a few simulated seconds, from an older tree and from
this one, compared byte for byte (a guard for work on the step loop: same messages, stamps, rates
and order on every topic).

The URDF PuzzleBot in the office world (moving people, the lidar's noise, amcl's odometry noise,
all seeded) starts paused; a subscriber to every topic the simulator publishes (but /rosout: its
log lines carry timings) and a latched drive command are connected before
``/gazebo/unpause_physics``, so both trees simulate the very same run. Once ``/clock`` passes
``--secs`` the physics is paused again; what came after ``--secs`` (the pause lands at some step
past it) is cut off: stamped messages by their stamp, the others (model_states, link_states) to as
many as both runs have (their common prefix). The simulator runs at
``--rate`` times real time so no subscriber falls behind (a dropped message would differ).

Run alone: ``.venv/bin/python bench/sim_outputs.py [--before REV] [--secs 4] [--rate 2]``;
exit status 1 when a topic differs.
"""

from __future__ import annotations

import argparse
import os
import struct
import subprocess
import sys
import tempfile
import threading
import time
import xmlrpc.client
from pathlib import Path

from ninjemys.testing import run_master
from sim_gazebo import URDF_MODEL, default_before, extract_tree, short_rev

#: the simulator's node name (the shipped launch's default)
SIM_NODE = "/puzzlebot_sim"
#: stamped topics: where the first stamp is in the payload (Header's seq, then secs, nsecs; /tf: the
#: array's length first; /clock: the stamp alone)
STAMP_AT = {"/clock": 0, "/tf": 8}


def record(
    src: Path | None, secs: float, rate: float, only: set[str] | None = None
) -> tuple[dict[str, list[bytes]], set[str]]:
    """Every topic's payloads, in order, the stamped ones over the first ``secs`` simulated seconds,
    and which topics are stamped (``src``: that tree's ``src`` on PYTHONPATH; None: this tree;
    ``only``: subscribe to these topics alone, /clock always: what nobody reads is not computed)."""
    from ninjemys.idl.loader import get_message_class, get_service_class
    from ninjemys.node import Node

    env = dict(os.environ, PYTHONHASHSEED="0")
    if src is not None:
        env["PYTHONPATH"] = str(src)
    got: dict[str, list[bytes]] = {}
    stamped: set[str] = set()
    lock = threading.Lock()
    with run_master() as master:
        env["ROS_MASTER_URI"] = master
        cmd = [sys.executable, "-m", "ninjemys.packages.run_shipped", "puzzlebot_sim", "sim_node"]
        cmd += ["_world:=office", f"_rate:={rate}", "_gui:=false", f"_model:={URDF_MODEL}", "_paused:=true"]
        proc = subprocess.Popen(cmd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        node = Node("sim_outputs", anonymous=True, master_uri=master)
        try:
            node.wait_for_service("/gazebo/unpause_physics", 120)
            api = xmlrpc.client.ServerProxy(master)
            _, _, (pubs, _, _) = api.getSystemState("/sim_outputs")
            _, _, types = api.getTopicTypes("/sim_outputs")
            kinds = dict(types)
            topics = sorted(t for t, who in pubs if SIM_NODE in who and t != "/rosout")
            if only is not None:
                topics = [t for t in topics if t in only or t == "/clock"]
            subs = []
            for topic in topics:

                def keep(msg: object, topic: str = topic) -> None:
                    with lock:
                        got.setdefault(topic, []).append(bytes(msg.data))  # type: ignore[attr-defined]

                cls = get_message_class(kinds[topic])
                if topic in STAMP_AT or getattr(cls, "_has_header", False):
                    stamped.add(topic)
                subs.append(node.subscriber(topic, cls, keep, queue_size=1_000_000, raw=True))
            twist_cls = get_message_class("geometry_msgs/Twist")
            twist = twist_cls()
            twist.linear.x, twist.angular.z = 0.05, 0.5
            drive = node.publisher("/cmd_vel", twist_cls, queue_size=1, latch=True)
            drive.publish(twist)
            while not (drive.get_num_connections() and all(s.get_num_connections() for s in subs)):
                time.sleep(0.05)
            time.sleep(1.0)  # the latched command taken in, latched topics delivered
            empty = get_service_class("std_srvs/Empty")
            node.service_proxy("/gazebo/unpause_physics", empty).call()
            while _clock(got, lock) < secs:
                time.sleep(0.01)
            node.service_proxy("/gazebo/pause_physics", empty).call()
            time.sleep(1.0)  # what is on its way arrives
        finally:
            node.shutdown("recorded")
            proc.terminate()
            proc.wait(30)
    return {t: _cut(t, msgs, secs) if t in stamped else msgs for t, msgs in got.items()}, stamped


def _stamp(topic: str, data: bytes) -> float:
    at = STAMP_AT.get(topic, 4)
    s, ns = struct.unpack_from("<II", data, at)
    return s + ns * 1e-9


def _clock(got: dict[str, list[bytes]], lock: threading.Lock) -> float:
    with lock:
        clock = got.get("/clock")
        return _stamp("/clock", clock[-1]) if clock else 0.0


def _cut(topic: str, msgs: list[bytes], secs: float) -> list[bytes]:
    """A stamped topic's messages up to ``secs``."""
    return [d for d in msgs if _stamp(topic, d) <= secs + 1e-9]


def compare(a: dict[str, list[bytes]], b: dict[str, list[bytes]], stamped: set[str]) -> list[str]:
    """What differs between two recordings, one line per topic (empty: the same); an unstamped
    topic's common prefix is compared."""
    problems = []
    for topic in sorted(set(a) | set(b)):
        ma, mb = a.get(topic, []), b.get(topic, [])
        if topic not in stamped:
            n = min(len(ma), len(mb))
            ma, mb = ma[:n], mb[:n]
        if len(ma) != len(mb) or not ma:
            problems.append(f"{topic}: {len(ma)} messages before, {len(mb)} after")
            continue
        for i, (x, y) in enumerate(zip(ma, mb, strict=True)):
            if x != y:
                problems.append(f"{topic}: message {i} differs ({len(x)} and {len(y)} bytes)")
                break
    return problems


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--before", default=None, help="the older tree (default: merge-base with main)")
    p.add_argument("--secs", type=float, default=4.0, help="simulated seconds compared")
    p.add_argument("--rate", type=float, default=2.0, help="real-time factor of both runs")
    p.add_argument("--topics", default="", help="comma-separated: subscribe to these only (and /clock)")
    args = p.parse_args()
    only = set(args.topics.split(",")) if args.topics else None
    before = args.before or default_before()
    with tempfile.TemporaryDirectory() as tmp:
        a, _ = record(extract_tree(before, Path(tmp)), args.secs, args.rate, only)
    b, stamped = record(None, args.secs, args.rate, only)
    print(f"{short_rev(before)} (before) and this tree (after), {args.secs:g} simulated s:")
    for topic in sorted(b):
        n = len(b[topic]) if topic in stamped else min(len(b[topic]), len(a.get(topic, [])))
        print(f"  {topic}: {n} messages compared{'' if topic in stamped else ' (unstamped: common prefix)'}")
    problems = compare(a, b, stamped)
    for line in problems:
        print("DIFFERS", line)
    print("the same, byte for byte" if not problems else f"{len(problems)} topic(s) differ")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
