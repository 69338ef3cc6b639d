"""With authentication on (NINJEMYS_SECRET) in both graphs, the bridge signs like any node: its
master calls, its type probes and its relays are accepted, and traffic crosses."""

from __future__ import annotations

import queue
import threading

import pytest

pytest.importorskip("zenoh", reason="eclipse-zenoh (the zenoh extra) is not installed")

from ninjemys.errors import NinjemysError  # noqa: E402
from ninjemys.master.client import MasterClient  # noqa: E402
from ninjemys.node import Node  # noqa: E402
from ninjemys.testing import free_port, run_master, wait_until  # noqa: E402
from ninjemys.zenoh_bridge.core import ZenohBridge  # noqa: E402
from ninjemys.zenoh_bridge.options import parse_options  # noqa: E402


def test_bridge_works_with_authentication_on(monkeypatch, tmp_path):

    monkeypatch.setenv("ROS_HOME", str(tmp_path))
    monkeypatch.setenv("ROS_HOSTNAME", "localhost")
    monkeypatch.setenv("NINJEMYS_SECRET", "fleet-secret")
    port = free_port()
    bridges = []
    nodes = []
    with (
        run_master() as uri_a,
        run_master() as uri_b,
    ):  # child processes: they keep the secret they started with
        _relay_and_refuse(monkeypatch, uri_a, uri_b, port, bridges, nodes)


def _relay_and_refuse(monkeypatch, uri_a, uri_b, port, bridges, nodes):
    from std_msgs.msg import String

    try:
        for uri, link in ((uri_a, "-l"), (uri_b, "-e")):
            argv = ["--ros_master_uri", uri, "--no-multicast-scouting", link, f"tcp/127.0.0.1:{port}"]
            b = ZenohBridge(parse_options(argv, env={}), status=lambda line: None)
            bridges.append(b)
            threading.Thread(target=b.run, daemon=True).start()
        talker = Node("talker", master_uri=uri_a, rosout=False)
        listener = Node("listener", master_uri=uri_b, rosout=False)
        nodes += [talker, listener]
        pub = talker.publisher("/chatter", String)
        got: queue.Queue[str] = queue.Queue()
        listener.subscriber("/chatter", String, lambda m: got.put(m.data))
        wait_until(
            lambda: pub.publish(String("signed")) or not got.empty(), timeout=30, what="a relay", step=0.1
        )
        assert got.get_nowait() == "signed"
        # and the secret is really enforced on master B: an unsigned caller is refused
        monkeypatch.delenv("NINJEMYS_SECRET")
        with pytest.raises(NinjemysError), MasterClient(uri_b, "/intruder") as m:
            m.register_publisher("/chatter", "std_msgs/String", "http://localhost:1/")
    finally:
        monkeypatch.setenv("NINJEMYS_SECRET", "fleet-secret")
        for n in nodes:
            n.shutdown()
        for b in bridges:
            b.close()
