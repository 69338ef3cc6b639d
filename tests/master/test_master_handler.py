"""MasterHandler semantics that need more than one call: notifications, name clash, * type rule."""

from __future__ import annotations

from typing import Any

import pytest

from ninjemys.master.server import MasterHandler
from ninjemys.wire import xmlrpc as wire


class RecordingNotifier:
    def __init__(self) -> None:
        self.calls: list[tuple[str, str, Any, Any]] = []

    def publisher_update(self, api: str, topic: str, publishers: list[str]) -> None:
        self.calls.append(("publisherUpdate", api, topic, list(publishers)))

    def param_update(self, api: str, key: str, value: Any) -> None:
        if isinstance(value, wire.Marshalled):  # compare what will be sent
            value = wire.parse_call(wire.dump_call("m", (value,)))[1][0]
        self.calls.append(("paramUpdate", api, key, value))

    def revive(self, api: str) -> None:
        self.calls.append(("revive", api, None, None))

    def shutdown_node(self, api: str, message: str) -> None:
        self.calls.append(("shutdown", api, message, None))


@pytest.fixture
def master() -> tuple[MasterHandler, RecordingNotifier]:
    notifier = RecordingNotifier()
    return MasterHandler(notifier=notifier, uri="http://m:1/"), notifier  # type: ignore[arg-type]


def call(handler: MasterHandler, method: str, *args: Any) -> list[Any]:
    reply = handler._dispatch(method, args)
    if isinstance(reply[2], wire.Marshalled):
        reply[2] = reply[2].value
    notifier = handler.notifier
    notifier.calls = [c for c in notifier.calls if c[0] != "revive"]  # type: ignore[attr-defined]
    return reply


def test_register_publisher_notifies_every_subscriber(
    master: tuple[MasterHandler, RecordingNotifier],
) -> None:
    h, n = master
    assert call(h, "registerSubscriber", "/l1", "/chatter", "std_msgs/String", "http://l1/")[2] == []
    call(h, "registerSubscriber", "/l2", "chatter", "*", "http://l2/")
    reply = call(h, "registerPublisher", "/t", "/chatter", "std_msgs/String", "http://t/")
    assert reply[2] == ["http://l1/", "http://l2/"]
    assert n.calls == [
        ("publisherUpdate", "http://l1/", "/chatter", ["http://t/"]),
        ("publisherUpdate", "http://l2/", "/chatter", ["http://t/"]),
    ]
    n.calls.clear()
    call(h, "unregisterPublisher", "/t", "/chatter", "http://t/")
    assert [c[3] for c in n.calls] == [[], []]
    n.calls.clear()
    call(h, "unregisterPublisher", "/t", "/chatter", "http://t/")  # nothing removed: nobody told
    assert n.calls == []


def test_name_clash_shuts_down_the_old_node(master: tuple[MasterHandler, RecordingNotifier]) -> None:
    h, n = master
    call(h, "registerSubscriber", "/l", "/x", "std_msgs/String", "http://l/")
    call(h, "registerPublisher", "/talker", "/x", "std_msgs/String", "http://old/")
    n.calls.clear()
    call(h, "registerPublisher", "/talker", "/y", "std_msgs/String", "http://new/")
    assert (
        "shutdown",
        "http://old/",
        "[/talker] Reason: new node registered with same name",
        None,
    ) in n.calls
    # the old node's publication is gone and its subscribers learn it
    assert ("publisherUpdate", "http://l/", "/x", []) in n.calls
    assert call(h, "lookupNode", "/a", "/talker")[2] == "http://new/"
    assert call(h, "getSystemState", "/a")[2][0] == [["/y", ["/talker"]]]


def test_same_name_same_api_is_not_a_clash(master: tuple[MasterHandler, RecordingNotifier]) -> None:
    h, n = master
    call(h, "registerPublisher", "/t", "/a", "std_msgs/String", "http://t/")
    call(h, "registerPublisher", "/t", "/b", "std_msgs/String", "http://t/")
    assert not any(c[0] == "shutdown" for c in n.calls)


def test_param_updates(master: tuple[MasterHandler, RecordingNotifier]) -> None:
    h, n = master
    assert call(h, "subscribeParam", "/n1", "http://n1/", "/cfg")[2] == {}
    call(h, "subscribeParam", "/n2", "http://n2/", "/cfg/a")
    call(h, "setParam", "/n1", "/cfg", {"a": 1, "b": 2})
    # n1 made the change: not notified; n2 (sub-key) gets its new value
    assert n.calls == [("paramUpdate", "http://n2/", "/cfg/a/", 1)]
    n.calls.clear()
    call(h, "setParam", "/other", "/cfg", {"b": 3})
    assert sorted(n.calls) == [
        ("paramUpdate", "http://n1/", "/cfg/", {"b": 3}),
        ("paramUpdate", "http://n2/", "/cfg/a/", {}),
    ]
    n.calls.clear()
    call(h, "deleteParam", "/other", "/cfg")
    # a delete is "set to {}": sub-key subscribers learn their key is gone too
    assert sorted(n.calls) == [
        ("paramUpdate", "http://n1/", "/cfg/", {}),
        ("paramUpdate", "http://n2/", "/cfg/a/", {}),
    ]
    assert call(h, "subscribeParam", "/n3", "http://n3/", "/cfg")[2] == {}


def test_param_update_rejected_unsubscribes(master: tuple[MasterHandler, RecordingNotifier]) -> None:
    h, n = master
    call(h, "subscribeParam", "/n1", "http://n1/", "/k")
    h._param_rejected("http://n1/", "/k/")
    call(h, "setParam", "/x", "/k", 1)
    assert n.calls == []


def test_large_ints_and_binary_are_stored(master: tuple[MasterHandler, RecordingNotifier]) -> None:
    h, _ = master
    call(h, "setParam", "/a", "/big", 2**40)
    call(h, "setParam", "/a", "/bin", b"\x00\x01")
    assert call(h, "getParam", "/a", "/")[2] == {"big": 2**40, "bin": b"\x00\x01"}


def test_subgraph_filter(master: tuple[MasterHandler, RecordingNotifier]) -> None:
    h, _ = master
    call(h, "registerPublisher", "/n", "/ns/a", "std_msgs/String", "http://n/")
    call(h, "registerPublisher", "/n", "/nsx/b", "std_msgs/String", "http://n/")
    assert call(h, "getPublishedTopics", "/n", "/ns")[2] == [["/ns/a", "std_msgs/String"]]
    assert len(call(h, "getPublishedTopics", "/n", "")[2]) == 2


def test_a_replaced_node_cannot_take_its_name_back(master: tuple[MasterHandler, RecordingNotifier]) -> None:
    h, n = master
    call(h, "registerPublisher", "/talker", "/x", "std_msgs/String", "http://old/")
    call(h, "registerPublisher", "/talker", "/x", "std_msgs/String", "http://new/")
    n.calls.clear()
    # a dying rospy node re-subscribes an unset parameter on every log call
    reply = call(h, "subscribeParam", "/talker", "http://old/", "/rosout_disable_topics_generation")
    assert reply[0] == -1 and "replaced by a newer node" in reply[1]
    assert call(h, "lookupNode", "/a", "/talker")[2] == "http://new/"
    assert not any(c[0] == "shutdown" for c in n.calls)
    # the same API under another name is a different node
    assert call(h, "registerPublisher", "/other", "/x", "std_msgs/String", "http://old/")[0] == 1


def test_param_update_carries_the_value_at_the_time_of_the_change(
    master: tuple[MasterHandler, RecordingNotifier],
) -> None:
    h, n = master
    sent: list[Any] = []
    n.param_update = lambda api, key, value: sent.append(value)  # type: ignore[method-assign]
    call(h, "subscribeParam", "/n1", "http://n1/", "/cfg")
    call(h, "setParam", "/x", "/cfg", {"a": 1})
    call(h, "setParam", "/x", "/cfg/a", 2)  # mutates the stored dict before anything was sent
    first = sent[0]
    assert isinstance(first, wire.Marshalled)
    assert wire.parse_call(wire.dump_call("m", (first,)))[1] == ({"a": 1},)
