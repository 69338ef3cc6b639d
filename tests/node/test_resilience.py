"""Peers that die, come back, and a master that restarts: the graph heals by itself."""

from __future__ import annotations

import subprocess
import sys
import threading
from collections.abc import Iterator
from pathlib import Path

import pytest
from node_harness import MasterProcess
from node_msgs import String

from ninjemys.master.client import MasterClient
from ninjemys.node import Node
from ninjemys.testing import free_port, wait_until

TALKER = str(Path(__file__).parent / "talker_proc.py")


@pytest.fixture
def procs() -> Iterator[list[subprocess.Popen[bytes]]]:
    started: list[subprocess.Popen[bytes]] = []
    try:
        yield started
    finally:
        for p in started:
            p.kill()
            p.wait()


def _talker(procs, master_uri: str, tag: str) -> subprocess.Popen[bytes]:
    p = subprocess.Popen(
        [sys.executable, TALKER, master_uri, "talker", "/chatter", tag], stdout=subprocess.PIPE
    )
    procs.append(p)
    assert p.stdout is not None and p.stdout.readline().strip() == b"ready"
    return p


def test_sigkilled_publisher_is_dropped_and_its_restart_reconnected(make_node, master, procs) -> None:
    listener = make_node("listener")
    got: list[str] = []
    sub = listener.subscriber("chatter", String, lambda m: got.append(m.data))
    first = _talker(procs, master.uri, "first")
    assert wait_until(lambda: any(g.startswith("first") for g in got), timeout=10)
    first.kill()
    first.wait()
    assert wait_until(lambda: sub.get_num_connections() == 0, timeout=5)
    _talker(procs, master.uri, "second")
    assert wait_until(lambda: any(g.startswith("second") for g in got), timeout=10)
    assert sub.get_num_connections() == 1


@pytest.fixture(
    params=["ninjemys", pytest.param("ros1", marks=pytest.mark.ros1)], ids=["our-roscore", "real-rosmaster"]
)
def restartable_master(request: pytest.FixtureRequest) -> Iterator[MasterProcess]:
    m = MasterProcess(free_port(), kind=request.param)
    m.start()
    try:
        yield m
    finally:
        m.kill()


def test_master_restart_heals_the_graph(restartable_master: MasterProcess) -> None:
    master = restartable_master
    nodes: list[Node] = []

    def make_node(name: str) -> Node:
        nodes.append(Node(name, master_uri=master.uri))
        return nodes[-1]

    try:
        _heal(master, make_node)
    finally:
        for node in nodes:
            node.shutdown("test over")


def _heal(master: MasterProcess, make_node) -> None:
    talker, listener = make_node("talker"), make_node("listener")
    got: list[str] = []
    listener.subscriber("chatter", String, lambda m: got.append(m.data))
    pub = talker.publisher("chatter", String)
    stop = threading.Event()

    def publish() -> None:
        i = 0
        while not stop.wait(0.02):
            pub.publish(String(f"m {i}"))
            i += 1

    thread = threading.Thread(target=publish)
    thread.start()
    try:
        assert wait_until(lambda: len(got) > 3, timeout=5)
        master.kill()
        master.start()  # same port, empty state
        client = MasterClient(master.uri, "/check", timeout=2)
        try:

            def healed() -> bool:
                pubs, subs, _ = client.get_system_state()
                return ["/chatter", ["/talker"]] in pubs and ["/chatter", ["/listener"]] in subs

            assert wait_until(healed, timeout=3.5)
        finally:
            client.close()
        # the healed registrations are real: a newcomer on either side connects
        late = make_node("late_listener")
        late_got: list[str] = []
        late.subscriber("chatter", String, lambda m: late_got.append(m.data))
        assert wait_until(lambda: late_got, timeout=3)
        count = len(got)
        assert wait_until(lambda: len(got) > count + 3, timeout=3)
    finally:
        stop.set()
        thread.join()


def test_shutdown_is_prompt_without_a_master(master) -> None:
    import time

    from node_msgs import AddTwoInts

    from ninjemys.node import Node

    node = Node("orphan", master_uri=master.uri)
    for i in range(5):
        node.publisher(f"out{i}", String)
        node.subscriber(f"in{i}", String, lambda m: None)
    node.service("add", AddTwoInts, lambda r: r.a + r.b)
    master.kill()
    started = time.monotonic()
    node.shutdown("bye")
    assert time.monotonic() - started < 2.0
    assert node.is_shutdown


def test_a_node_with_names_the_master_refuses_still_reregisters_the_rest() -> None:
    """rospy's leniency (a node named "a b": the master refuses its "/a b/get_loggers"): after a
    master restart, the refused names are skipped and everything else is registered again."""
    master = MasterProcess(free_port(), kind="ninjemys")
    master.start()
    node = None
    try:
        node = Node("a b", master_uri=master.uri, strict_names=False)
        node.publisher("bad topic", String)  # refused first: must not stop what comes after
        node.publisher("/ok_topic", String)
        client = MasterClient(master.uri, "/check", timeout=2)
        try:
            pubs, _, srvs = client.get_system_state()
            assert ["/ok_topic", ["/a b"]] in pubs
            assert not any(name.startswith("/a b/") for name, _ in srvs)  # refused, logged FATAL
            master.kill()
            master.start()
            assert wait_until(lambda: ["/ok_topic", ["/a b"]] in client.get_system_state()[0], timeout=5)
        finally:
            client.close()
    finally:
        if node is not None:
            node.shutdown("test over")
        master.kill()


def test_a_restarted_master_filling_in_does_not_cut_live_streams(monkeypatch) -> None:
    """A new master learns the graph node by node: its first publisher lists miss the publishers that
    have not re-registered yet. A subscriber must keep those live streams (the soak saw a message lost
    when it did not), and apply the master's full list once the settling window is over."""
    from ninjemys.node import registration

    monkeypatch.setattr(registration, "SETTLE_PERIOD", 2.0)
    master = MasterProcess(free_port(), kind="ninjemys")
    master.start()
    nodes: list[Node] = []
    stop = threading.Event()
    try:
        a, b, listener = (Node(n, master_uri=master.uri) for n in ("talker_a", "talker_b", "listener"))
        nodes += [a, b, listener]
        got: dict[str, list[int]] = {"a": [], "b": []}
        sub = listener.subscriber("chatter", String, lambda m: got[m.data[0]].append(int(m.data[2:])))
        pubs = {"a": a.publisher("chatter", String), "b": b.publisher("chatter", String)}

        def publish() -> None:
            i = 0
            while not stop.wait(0.02):
                for tag, pub in pubs.items():
                    pub.publish(String(f"{tag} {i}"))
                i += 1

        thread = threading.Thread(target=publish)
        thread.start()
        assert wait_until(lambda: sub.get_num_connections() == 2 and len(got["b"]) > 3, timeout=10)
        master.kill()
        master.start()
        assert wait_until(listener.registrar.settling, timeout=5, what="the listener's re-registration")
        # what the new master says while only talker_a has registered again
        listener.publisher_update("/chatter", [a.uri])
        count = len(got["b"])
        assert wait_until(lambda: len(got["b"]) > count + 10, timeout=5)
        assert sub.get_num_connections() == 2
        # the window ends: the master's full list (both talkers by now) is applied; nothing is cut
        assert wait_until(lambda: not listener.registrar.settling(), timeout=5)
        count = len(got["b"])
        assert wait_until(lambda: len(got["b"]) > count + 10, timeout=5)
        assert sub.get_num_connections() == 2
        stop.set()
        thread.join()
        for seqs in got.values():  # one stream each, never cut: no message missing in the middle
            assert seqs == list(range(seqs[0], seqs[0] + len(seqs)))
        # after the window, the master's word holds again (ROS 1 semantics): an omitted publisher is dropped
        listener.publisher_update("/chatter", [a.uri])
        assert wait_until(lambda: sub.get_num_connections() == 1, timeout=5)
    finally:
        stop.set()
        for node in nodes:
            node.shutdown("test over")
        master.kill()
