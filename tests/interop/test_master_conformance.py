"""Our master answers every Master / Parameter Server API call exactly as Debian's rosmaster does.

Both masters get the same sequence of calls through ``xmlrpc.client``; the replies must be equal
(apart from values that differ by nature: the master's own URI and PID).
"""

from __future__ import annotations

import time
import xmlrpc.client
from collections.abc import Iterator
from typing import Any

import pytest

from ninjemys.master.core import MasterThread
from ninjemys.testing import run_real_master

pytestmark = pytest.mark.ros1

API = "http://127.0.0.1:1/"  # nodes that do not exist: notifications to them fail fast
API2 = "http://127.0.0.1:2/"
SRV = "rosrpc://127.0.0.1:3"

# (method, args) - run in order against a fresh master; state carries over between calls.
CALLS: list[tuple[str, tuple[Any, ...]]] = [
    # argument validation
    ("getPid", ()),
    ("getPid", (5,)),
    ("getPid", ("/a", "extra")),
    ("getUri", ("/a", 1)),
    ("shutdown", ("/a",)),
    ("getParam", ("/a", 5)),
    ("getParam", ("/a", "")),
    ("setParam", ("/a", "", 1)),
    ("lookupNode", ("/a", "")),
    ("lookupNode", ("/a", 7)),
    ("lookupService", ("/a", "/")),
    ("lookupService", ("/a", "a b")),
    ("registerPublisher", ("/a", "t", "badtype", API)),
    ("registerPublisher", ("/a", "t:x", "a/b", API)),
    ("registerPublisher", ("/a", "/", "a/b", API)),
    ("registerPublisher", ("/a", "t", "a/b", "ftp://x:1/")),
    ("registerPublisher", ("/a", "t", "a/b", "")),
    ("registerPublisher", ("/a", 5, "a/b", API)),
    ("registerPublisher", ("/a", "t", "", API)),
    ("registerSubscriber", ("/a", "t", "a/b/c", API)),
    ("registerService", ("/a", "s", "bogus", API)),
    ("getPublishedTopics", ("/a", 3)),
    ("subscribeParam", ("/a", "nope", "k")),
    ("searchParam", ("/a", "~x")),
    ("searchParam", ("a", "x")),
    ("unregisterService", ("/a", "s", SRV)),
    ("unregisterPublisher", ("/a", "t", API)),
    ("unregisterSubscriber", ("/a", "t", API)),
    # topics, types and the * rule, name resolution relative to the caller
    ("registerSubscriber", ("/ns/listener", "chatter", "*", API)),
    ("getTopicTypes", ("/a",)),
    ("registerPublisher", ("/ns/talker", "chatter", "std_msgs/String", API2)),
    ("registerPublisher", ("/other", "/ns/chatter", "*", API2.replace("2", "4"))),
    ("getTopicTypes", ("/a",)),
    ("registerSubscriber", ("/ns/listener", "chatter", "*", API)),
    ("registerSubscriber", ("/x/late", "/late", "*", API)),
    ("registerSubscriber", ("/x/late", "/late", "std_msgs/Int32", API)),
    ("registerPublisher", ("/x/late", "/late", "*", API)),
    ("getTopicTypes", ("/a",)),
    ("getPublishedTopics", ("/a", "")),
    ("getPublishedTopics", ("/a", "/ns")),
    ("getPublishedTopics", ("/ns/a", "x")),
    ("getSystemState", ("/a",)),
    ("lookupNode", ("/a", "/ns/talker")),
    ("lookupNode", ("/ns/a", "talker")),
    ("lookupNode", ("/a", "talker")),
    ("unregisterPublisher", ("/ns/talker", "chatter", API)),
    ("unregisterPublisher", ("/ns/talker", "chatter", API2)),
    ("unregisterPublisher", ("/ns/talker", "chatter", API2)),
    ("lookupNode", ("/a", "/ns/talker")),
    ("unregisterSubscriber", ("/nobody", "chatter", API2)),
    ("getSystemState", ("/a",)),
    # services
    ("unregisterService", ("/svc", "s", SRV)),
    ("registerService", ("/svc", "add", SRV, API2)),
    ("lookupService", ("/a", "/add")),
    ("lookupService", ("/b", "add")),
    ("lookupService", ("/b", "missing")),
    ("registerService", ("/svc2", "/add", SRV + "9", API)),
    ("lookupService", ("/a", "/add")),
    ("unregisterService", ("/svc", "/add", SRV)),
    ("unregisterService", ("/svc2", "/add", SRV)),
    ("unregisterService", ("/svc2", "/add", SRV + "9")),
    ("lookupService", ("/a", "/add")),
    ("getSystemState", ("/a",)),
    # parameters
    ("getParam", ("/a", "/missing")),
    ("hasParam", ("/a", "missing")),
    ("setParam", ("/a", "/", 5)),
    ("setParam", ("/ns/node", "x", 1)),
    ("setParam", ("/ns/node", "~priv", "p")),
    ("setParam", ("/a", "/f", 1.5)),
    ("setParam", ("/a", "/b", True)),
    ("setParam", ("/a", "/bin", xmlrpc.client.Binary(b"\x00\x01\xff"))),
    ("setParam", ("/a", "/l", [1, "two", [3.0]])),
    ("setParam", ("/a", "/tree", {"a": 1, "sub": {"b": 2, "c": "three"}})),
    ("getParam", ("/a", "/tree")),
    ("getParam", ("/a", "/tree/sub/")),
    ("getParam", ("/ns/node", "x")),
    ("getParam", ("/ns/node", "~priv")),
    ("getParam", ("/a", "/bin")),
    ("hasParam", ("/ns/y", "x")),
    ("setParam", ("/a", "/tree", {"z": 0})),
    ("getParam", ("/a", "/tree")),
    ("setParam", ("/a", "/f/deeper", 2)),
    ("getParam", ("/a", "/f")),
    ("getParam", ("/a", "/")),
    ("getParamNames", ("/a",)),
    ("searchParam", ("/ns/node", "x")),
    ("searchParam", ("/ns/node", "x/deep")),
    ("searchParam", ("/ns/node", "tree")),
    ("searchParam", ("/ns/node", "/tree")),
    ("searchParam", ("/ns/node", "/nothing")),
    ("searchParam", ("/ns/node", "nothing")),
    ("deleteParam", ("/a", "/missing")),
    ("deleteParam", ("/a", "/")),
    ("deleteParam", ("/a", "/tree/z")),
    ("deleteParam", ("/a", "/tree/z/q")),
    ("deleteParam", ("/ns/node", "x")),
    ("getParam", ("/a", "/")),
    ("subscribeParam", ("/p", API, "/l")),
    ("subscribeParam", ("/p", API, "unset")),
    ("unsubscribeParam", ("/p", API, "/l")),
    ("unsubscribeParam", ("/p", API, "/never")),
    ("lookupNode", ("/a", "/p")),
    ("unsubscribeParam", ("/p", API, "unset")),
    ("lookupNode", ("/a", "/p")),
    # name clash: same name, new API replaces the node and its registrations
    ("registerPublisher", ("/dup", "/d1", "std_msgs/String", API)),
    ("registerSubscriber", ("/dup", "/d2", "std_msgs/String", API)),
    ("registerPublisher", ("/dup", "/d3", "std_msgs/String", API2)),
    ("getSystemState", ("/a",)),
    ("lookupNode", ("/a", "/dup")),
]


def _normalise(method: str, reply: Any, uri: str) -> Any:
    if isinstance(reply, str) and reply.startswith("<Fault"):
        return reply
    if method == "getUri" and reply[0] == 1:
        assert reply[2] == uri
        return [1, reply[1], "URI"]
    if method == "getPid" and reply[0] == 1:
        assert isinstance(reply[2], int) and reply[2] > 0
        return [1, reply[1], "PID"]
    return reply


def _run_calls(uri: str) -> list[Any]:
    proxy = xmlrpc.client.ServerProxy(uri)
    out = []
    for method, args in CALLS:
        try:
            reply = getattr(proxy, method)(*args)
        except xmlrpc.client.Fault as fault:
            reply = f"<Fault {fault.faultCode}: {fault.faultString}>"
        out.append(_normalise(method, reply, uri))
    return out


@pytest.fixture
def real_master() -> Iterator[str]:
    with run_real_master("127.0.0.1") as uri:
        yield uri


def test_every_call_answers_like_rosmaster(real_master: str) -> None:
    expected = _run_calls(real_master)
    with MasterThread() as uri:
        actual = _run_calls(uri)
    for (method, args), want, got in zip(CALLS, expected, actual, strict=True):
        assert got == want, f"{method}{args}: rosmaster {want!r}, ninjemys {got!r}"


def test_unknown_method_is_the_same_fault(real_master: str) -> None:
    def fault(uri: str) -> tuple[int, str]:
        with pytest.raises(xmlrpc.client.Fault) as info:
            xmlrpc.client.ServerProxy(uri).noSuchMethod("/a")
        return info.value.faultCode, info.value.faultString

    with MasterThread() as uri:
        assert fault(uri) == fault(real_master)


class _Recorder:
    """A fake node's slave API that records what the master tells it."""

    def __init__(self) -> None:
        self.calls: list[tuple[str, str, Any]] = []

    def paramUpdate(self, caller_id: str, key: str, value: Any) -> list[Any]:  # noqa: N802
        self.calls.append(("paramUpdate", key, value))
        return [1, "", 0]

    def publisherUpdate(self, caller_id: str, topic: str, publishers: list[str]) -> list[Any]:  # noqa: N802
        self.calls.append(("publisherUpdate", topic, publishers))
        return [1, "", 0]


def _notifications(master_uri: str) -> dict[str, list[tuple[str, str, Any]]]:
    """Run a scripted session against ``master_uri`` with three recording nodes; what each was told."""
    import asyncio
    import threading

    from ninjemys.net.xmlrpc_server import XmlRpcServer

    loop = asyncio.new_event_loop()
    thread = threading.Thread(target=loop.run_forever, daemon=True)
    thread.start()
    recorders = {name: _Recorder() for name in ("/n1", "/n2", "/n3")}
    servers = {}
    try:
        for name, rec in recorders.items():
            server = XmlRpcServer(rec, "127.0.0.1", 0, advertise="127.0.0.1")
            asyncio.run_coroutine_threadsafe(server.start(), loop).result(5)
            servers[name] = server
        proxy = xmlrpc.client.ServerProxy(master_uri)
        api = {name: server.uri for name, server in servers.items()}
        steps = [
            ("subscribeParam", "/n1", api["/n1"], "/cfg"),
            ("subscribeParam", "/n2", api["/n2"], "/cfg/a"),
            ("subscribeParam", "/n3", api["/n3"], "/cfg/gone/deep"),
            ("setParam", "/n1", "/cfg", {"a": 1, "gone": {"deep": 2}}),  # n1 made the change: not told
            ("setParam", "/other", "/cfg/a", 5),
            ("setParam", "/other", "/cfg", {"a": {"x": 1}}),
            ("deleteParam", "/other", "/cfg/a"),
            ("setParam", "/other", "/unrelated", 1),
            ("registerSubscriber", "/n2", "/chatter", "std_msgs/String", api["/n2"]),
            ("registerPublisher", "/talker", "/chatter", "std_msgs/String", "http://127.0.0.1:9/"),
            ("unregisterPublisher", "/talker", "/chatter", "http://127.0.0.1:9/"),
        ]
        for method, *args in steps:
            before = sum(len(r.calls) for r in recorders.values())
            getattr(proxy, method)(*args)
            # rosmaster sends a live reference to its tree: let each change arrive before the next one
            deadline = time.monotonic() + 0.5
            while sum(len(r.calls) for r in recorders.values()) == before and time.monotonic() < deadline:
                time.sleep(0.01)
            time.sleep(0.05)
        time.sleep(0.3)  # nothing else may arrive
        return {name: rec.calls for name, rec in recorders.items()}
    finally:
        for server in servers.values():
            loop.call_soon_threadsafe(server.close)
        loop.call_soon_threadsafe(loop.stop)
        thread.join(5)


def test_param_and_publisher_updates_match_rosmaster(real_master: str) -> None:
    expected = _notifications(real_master)
    with MasterThread() as uri:
        actual = _notifications(uri)
    assert actual == expected
