"""The gateway's shared raw subscriptions (Taps): every client gets a latched topic's message, as
every ROS subscriber does, whether it subscribes first or joins a tap that already runs."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from ninjemys.bridge.graph import Delivery, Taps
from ninjemys.idl.loader import get_message_class
from ninjemys.master.core import MasterThread
from ninjemys.node import Node
from ninjemys.node.subscriber import RawMessage
from ninjemys.testing import wait_until

String = get_message_class("std_msgs/String")


class _EagerSubscription:
    """A subscription whose latched message arrives before ``node.subscriber`` returns (what a busy
    machine does when the subscription's thread runs ahead of the caller's)."""

    def __init__(self, callback: Callable[[RawMessage], None]) -> None:
        callback(RawMessage(String(data="latched").serialize_to_bytes(), {"latching": "1", "callerid": "/p"}))

    def publisher_ids(self) -> frozenset[str]:
        return frozenset({"/p"})

    def unregister(self) -> None:
        pass


class _EagerNode:
    def subscriber(self, topic: str, msg_class: Any, callback: Callable[[RawMessage], None], **_: Any) -> Any:
        return _EagerSubscription(callback)


def test_the_first_sink_gets_a_message_that_arrives_while_the_tap_is_made() -> None:
    got: list[Delivery] = []
    Taps(_EagerNode(), lambda: 0).add("/t", "std_msgs/String", "client", got.append)  # type: ignore[arg-type]
    assert [d.message().data for d in got] == ["latched"]


def test_a_sink_joining_a_running_tap_gets_the_latched_message_of_connected_publishers_only() -> None:
    with MasterThread() as uri:
        peer = Node("taps_peer", anonymous=True, master_uri=uri)
        gateway = Node("taps_gateway", anonymous=True, master_uri=uri)
        try:
            latched = peer.publisher("/latched", String, queue_size=1, latch=True)
            latched.publish(String(data="one"))
            taps = Taps(gateway, lambda: 0)
            first: list[str] = []
            taps.add("/latched", "std_msgs/String", "first", lambda d: first.append(d.message().data))
            wait_until(lambda: first == ["one"], what="the latched message on the first sink")
            second: list[str] = []
            taps.add("/latched", "std_msgs/String", "second", lambda d: second.append(d.message().data))
            assert second == ["one"]  # replayed as it joined, once
            latched.publish(String(data="two"))
            wait_until(lambda: first == ["one", "two"] and second == ["one", "two"], what="'two' on both")
            # a publisher that left: a new subscriber of ROS would not get its message, nor does a sink
            latched.unregister()
            wait_until(lambda: not taps._taps["/latched"].sub.publisher_ids(), what="the publisher gone")
            third: list[str] = []
            taps.add("/latched", "std_msgs/String", "third", lambda d: third.append(d.message().data))
            assert third == []
            for owner in ("first", "second", "third"):
                taps.remove("/latched", owner)
            assert taps.topics() == []
        finally:
            gateway.shutdown("test over")
            peer.shutdown("test over")
