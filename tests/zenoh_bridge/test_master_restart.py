"""A master restarted under a bridge: the bridge closes its bridges while the master is away and
rebuilds them when it answers again, and the nodes' traffic flows across once more."""

from __future__ import annotations

import queue
import threading

import pytest

pytest.importorskip("zenoh", reason="eclipse-zenoh (the zenoh extra) is not installed")

from ninjemys.master.core import MasterThread  # noqa: E402
from ninjemys.net.addresses import split_uri  # noqa: E402
from ninjemys.node import Node  # noqa: E402
from ninjemys.testing import free_port, wait_until  # noqa: E402
from ninjemys.zenoh_bridge.core import ZenohBridge  # noqa: E402
from ninjemys.zenoh_bridge.options import parse_options  # noqa: E402


def test_master_restart_heals_across_the_bridge(monkeypatch, tmp_path):
    from std_msgs.msg import String

    monkeypatch.setenv("ROS_HOME", str(tmp_path))
    monkeypatch.setenv("ROS_HOSTNAME", "localhost")
    port = free_port()
    master_a, master_b = MasterThread(), MasterThread()
    uri_a, uri_b = master_a.start(), master_b.start()
    lines: list[str] = []
    bridges = []
    for uri, link in ((uri_a, "-l"), (uri_b, "-e")):
        argv = ["--ros_master_uri", uri, "--no-multicast-scouting", link, f"tcp/127.0.0.1:{port}"]
        b = ZenohBridge(parse_options(argv, env={}), status=lines.append)
        bridges.append(b)
        threading.Thread(target=b.run, daemon=True).start()
    talker = Node("talker", master_uri=uri_a, rosout=False)
    listener = Node("listener", master_uri=uri_b, rosout=False)
    got: queue.Queue[str] = queue.Queue()
    try:
        pub = talker.publisher("/chatter", String)
        listener.subscriber("/chatter", String, lambda m: got.put(m.data))

        def relays(text: str) -> bool:
            pub.publish(String(text))
            found = False
            while not got.empty():
                found |= got.get_nowait() == text
            return found

        wait_until(lambda: relays("before"), timeout=30, what="the first relay", step=0.1)
        master_b.stop()
        wait_until(
            lambda: any("unreachable" in line for line in lines), timeout=30, what="the bridge to notice"
        )
        assert not bridges[1].bridges  # everything on the dead master's side closed
        host, b_port = split_uri(uri_b)
        master_b = MasterThread(port=b_port)
        assert master_b.start() == uri_b
        wait_until(lambda: relays("after"), timeout=60, what="the relay after the restart", step=0.1)
    finally:
        listener.shutdown()
        talker.shutdown()
        for b in bridges:
            b.close()
        master_a.stop()
        master_b.stop()
