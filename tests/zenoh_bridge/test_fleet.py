"""Ten robots, identical topic names, kept apart by their bridge namespaces (per-robot key prefixes).

Each robot is a ROS graph (its own master) with a talker on ``/odom`` and a bridge with
``--bridge_namespace robotN``; the base station runs, per robot, a graph with a bridge in the same
namespace and a listener on ``/odom``. All twenty bridges share one Zenoh network (one listens, the
rest connect, no multicast). Each listener must hear its own robot, and only it. The bridges run in
this process (``ZenohBridge``, what the command runs) to keep twenty of them within the test's time.
"""

from __future__ import annotations

import threading
import time
from collections import defaultdict

import pytest

pytest.importorskip("zenoh", reason="eclipse-zenoh (the zenoh extra) is not installed")

from ninjemys.master.core import MasterThread  # noqa: E402
from ninjemys.node import Node  # noqa: E402
from ninjemys.testing import free_port, wait_until  # noqa: E402
from ninjemys.zenoh_bridge.core import ZenohBridge  # noqa: E402
from ninjemys.zenoh_bridge.options import parse_options  # noqa: E402

ROBOTS = 10


def test_ten_robots_with_identical_topic_names_kept_apart(monkeypatch, tmp_path):
    from std_msgs.msg import String

    monkeypatch.setenv("ROS_HOME", str(tmp_path))
    monkeypatch.setenv("ROS_HOSTNAME", "localhost")
    port = free_port()
    masters: list[MasterThread] = []
    bridges: list[ZenohBridge] = []
    nodes: list[Node] = []
    heard: dict[int, list[str]] = defaultdict(list)

    def graph() -> str:
        m = MasterThread()
        masters.append(m)
        return m.start()

    def bridge(uri: str, ns: str) -> None:
        link = ["-l", f"tcp/127.0.0.1:{port}"] if not bridges else ["-e", f"tcp/127.0.0.1:{port}"]
        argv = ["--ros_master_uri", uri, "--bridge_namespace", ns, "--no-multicast-scouting", *link]
        b = ZenohBridge(parse_options(argv, env={}), status=lambda line: None)
        bridges.append(b)
        threading.Thread(target=b.run, name=f"bridge-{ns}", daemon=True).start()

    try:
        pubs = []
        for i in range(ROBOTS):
            base_uri, robot_uri = graph(), graph()
            bridge(base_uri, f"robot{i}")
            bridge(robot_uri, f"robot{i}")
            talker = Node("odometry", master_uri=robot_uri, rosout=False)
            nodes.append(talker)
            pubs.append(talker.publisher("/odom", String))
            listener = Node("base_monitor", master_uri=base_uri, rosout=False)
            nodes.append(listener)
            listener.subscriber("/odom", String, lambda m, i=i: heard[i].append(m.data))

        def every_robot_heard() -> bool:
            for i, pub in enumerate(pubs):
                pub.publish(String(f"robot{i}"))
            return all(len(heard[i]) >= 3 for i in range(ROBOTS))

        wait_until(every_robot_heard, timeout=90, what="every base graph to hear its robot", step=0.2)
        time.sleep(0.5)  # anything crossing over would have arrived by now
        for i in range(ROBOTS):
            assert set(heard[i]) == {f"robot{i}"}, f"base graph {i} heard {sorted(set(heard[i]))}"
    finally:
        for n in nodes:
            n.shutdown()
        for b in bridges:
            b.close()
        for m in masters:
            m.stop()
