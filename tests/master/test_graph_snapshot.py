"""The graph snapshot and ``rosnode ping``'s loop, said once (ninjemys.master.snapshot/graph): the
master's answers indexed one way for every reader, read-only, and ROS 1's ping lines for each way a
ping ends, followed through a node that moved; the rosnode command and facade both run that loop."""

from __future__ import annotations

import inspect
import socket

import pytest

from ninjemys.master.client import MasterClient
from ninjemys.master.graph import ping_node
from ninjemys.master.snapshot import GraphSnapshot
from ninjemys.testing import run_master

STATE = [
    [["/chatter", ["/talker", "/relay"]], ["/rosout", ["/talker"]]],
    [["/chatter", ["/listener"]], ["/cmd", ["/relay"]]],
    [["/talker/get_loggers", ["/talker"]]],
]


def test_snapshot_indexes_the_masters_answers():
    snap = GraphSnapshot.from_system_state(
        STATE,
        topic_types=[["/chatter", "std_msgs/String"], ["/cmd", "geometry_msgs/Twist"]],
        published_types=[["/chatter", "std_msgs/String"], ["/rosout", "rosgraph_msgs/Log"]],
    )
    assert snap.publishers["/chatter"] == ("/talker", "/relay")
    assert snap.node_names() == ["/listener", "/relay", "/talker"]
    assert snap.topic_names() == ["/chatter", "/cmd", "/rosout"]
    assert snap.topics_of("/relay") == (["/chatter"], ["/cmd"], [])
    assert snap.topics_of("/talker") == (["/chatter", "/rosout"], [], ["/talker/get_loggers"])
    assert snap.type_of("/cmd") == "geometry_msgs/Twist"  # subscribed only: getTopicTypes knows it
    assert snap.type_of("/rosout") == "rosgraph_msgs/Log"
    assert snap.type_of("/none") is None
    assert snap.system_state() == STATE
    assert snap == GraphSnapshot.from_system_state(STATE, *[snap.topic_types, snap.published_types])
    assert snap != GraphSnapshot.from_system_state(STATE)


def test_snapshot_is_read_only():
    snap = GraphSnapshot.from_system_state(STATE)
    with pytest.raises(AttributeError, match="read-only"):
        snap.publishers = {}  # type: ignore[misc]
    with pytest.raises(TypeError):
        snap.publishers["/x"] = ("/n",)  # type: ignore[index]
    with pytest.raises(AttributeError):
        snap.publishers["/chatter"].append("/n")  # type: ignore[attr-defined]


def test_snapshot_fetch_from_a_live_master():
    with run_master() as uri:
        client = MasterClient(uri, caller_id="/snap")
        try:
            client.register_publisher("/a", "std_msgs/String", "http://127.0.0.1:1/")
            client.register_subscriber("/b", "std_msgs/Int32", "http://127.0.0.1:1/")
            snap = GraphSnapshot.fetch(client)
            bare = GraphSnapshot.fetch(client, with_types=False)
        finally:
            client.close()
    assert snap.publishers["/a"] == ("/snap",)
    assert snap.type_of("/b") == "std_msgs/Int32"
    assert "/b" not in snap.published_types and snap.published_types["/a"] == "std_msgs/String"
    assert bare.topic_types == {} and bare.node_names() == snap.node_names()


def _closed_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def _ping(node, lookup, **kw):
    out: list[str] = []
    err: list[str] = []
    ok = ping_node(node, lookup, "/test", out=out.append, err=err.append, sleep=lambda _s: None, **kw)
    return ok, out, err


def test_ping_answers_and_averages():
    with run_master() as uri:  # the master answers getPid like any node's slave API
        ok, out, err = _ping("/n", lambda _n, _r: uri, max_count=3, verbose=True)
    assert ok and not err
    assert out[0] == "pinging /n with a timeout of 3.0s"
    assert [line.split("\t")[0] for line in out[1:4]] == [f"xmlrpc reply from {uri}"] * 3
    assert out[4].startswith("ping average: ") and out[4].endswith("ms")


def test_ping_failures_print_ros1s_lines():
    ok, out, err = _ping("/ghost", lambda _n, _r: None, max_count=1)
    assert (ok, out, err) == (False, [], ["cannot ping [/ghost]: unknown node"])
    dead = f"http://127.0.0.1:{_closed_port()}/"
    ok, _out, err = _ping("/dead", lambda _n, _r: dead, max_count=1)
    assert (ok, err) == (False, [f"ERROR: connection refused to [{dead}]"])
    ok, _out, err = _ping("/gone", lambda _n, refresh: None if refresh else dead, max_count=1)
    assert (ok, err) == (False, ["cannot ping [/gone]: unknown node"])
    host = "no-such-host.invalid"
    ok, _out, err = _ping("/far", lambda _n, _r: f"http://{host}:1/", max_count=1)
    assert (ok, err) == (False, [f"ERROR: Unknown host [{host}] for node [/far]"])


def test_ping_follows_a_node_that_moved():
    dead = f"http://127.0.0.1:{_closed_port()}/"
    with run_master() as uri:
        ok, out, err = _ping("/n", lambda _n, refresh: uri if refresh else dead, max_count=1, verbose=True)
    assert ok and not err
    assert f"node url has changed from [{dead}] to [{uri}], retrying to ping" in out


def test_the_command_and_the_facade_ping_through_the_one_loop():
    import rosnode
    from ninjemys.tools import rosnode as tool

    for source in (inspect.getsource(rosnode.rosnode_ping), inspect.getsource(tool._ping_node)):
        assert "ping_node(" in source
        assert ".getPid(" not in source and "ServerProxy" not in source
