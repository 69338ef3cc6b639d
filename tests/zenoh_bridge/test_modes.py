"""Bridging modes, as the Rust bridge has them: ``auto`` bridges what one side wants, ``lazy_auto`` only
what both sides want, ``disabled`` (globally or per topic) never."""

from __future__ import annotations

import threading
import time

import pytest

pytest.importorskip("zenoh", reason="eclipse-zenoh (the zenoh extra) is not installed")

from ninjemys.master.client import MasterClient  # noqa: E402
from ninjemys.master.core import MasterThread  # noqa: E402
from ninjemys.node import Node  # noqa: E402
from ninjemys.testing import free_port, wait_until  # noqa: E402
from ninjemys.zenoh_bridge.core import ZenohBridge  # noqa: E402
from ninjemys.zenoh_bridge.discovery import BEACON_PERIOD  # noqa: E402
from ninjemys.zenoh_bridge.options import parse_options  # noqa: E402

BRIDGE = "/ros1_to_zenoh_bridge"


def _bridge_has(uri: str, topic: str, index: int) -> bool:
    with MasterClient(uri, "/test_probe") as m:
        return any(t == topic and BRIDGE in nodes for t, nodes in m.get_system_state()[index])


@pytest.fixture
def graphs(monkeypatch, tmp_path):
    monkeypatch.setenv("ROS_HOME", str(tmp_path))
    monkeypatch.setenv("ROS_HOSTNAME", "localhost")
    masters = [MasterThread(), MasterThread()]
    uris = [m.start() for m in masters]
    bridges: list[ZenohBridge] = []
    nodes: list[Node] = []
    port = free_port()

    def start(extra_a: list[str], extra_b: list[str]) -> None:
        for uri, link, extra in ((uris[0], "-l", extra_a), (uris[1], "-e", extra_b)):
            argv = ["--ros_master_uri", uri, "--no-multicast-scouting", link, f"tcp/127.0.0.1:{port}", *extra]
            b = ZenohBridge(parse_options(argv, env={}), status=lambda line: None)
            bridges.append(b)
            threading.Thread(target=b.run, daemon=True).start()

    def node(name: str, side: int) -> Node:
        n = Node(name, master_uri=uris[side], rosout=False)
        nodes.append(n)
        return n

    yield uris, start, node
    for n in nodes:
        n.shutdown()
    for b in bridges:
        b.close()
    for m in masters:
        m.stop()


def test_lazy_auto_waits_for_the_other_side(graphs):
    from std_msgs.msg import String

    (uri_a, uri_b), start, node = graphs
    start(["--publisher_bridging_mode", "lazy_auto"], [])
    node("talker", 0).publisher("/chatter", String)
    time.sleep(3 * BEACON_PERIOD)  # the talker is announced, but nobody across wants it yet
    assert not _bridge_has(uri_a, "/chatter", 1)
    node("listener", 1).subscriber("/chatter", String, lambda m: None)
    wait_until(lambda: _bridge_has(uri_a, "/chatter", 1), timeout=30, what="the lazy bridge to open")


def test_auto_bridges_a_remote_publisher_at_once(graphs):
    from std_msgs.msg import String

    (uri_a, uri_b), start, node = graphs
    start([], [])
    node("talker", 0).publisher("/chatter", String)
    # no subscriber on B: auto still advertises the topic there, so rostopic finds it
    wait_until(lambda: _bridge_has(uri_b, "/chatter", 0), timeout=30, what="the remote publisher on B")


def test_disabled_per_topic_never_bridges(graphs):
    from std_msgs.msg import String

    (uri_a, uri_b), start, node = graphs
    start([], ["--subscriber_topic_custom_bridging_mode", '{"/secret": "disabled"}'])
    talker = node("talker", 0)
    talker.publisher("/secret", String)
    talker.publisher("/public", String)
    wait_until(lambda: _bridge_has(uri_b, "/public", 0), timeout=30, what="the other topic to cross")
    time.sleep(2 * BEACON_PERIOD)
    assert not _bridge_has(uri_b, "/secret", 0)
