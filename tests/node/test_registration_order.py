"""The master hears of one topic's (or service's) registration changes in the order the node made
them, whatever threads made them: an unsubscribe still on its way must not overtake a new subscribe
of the same topic, or the master forgets a live subscription (and a restarted master is never told
of it again). Each test holds the first call at the master's door, makes the second change from
another thread, then lets the first call go: the master must end up knowing the live one."""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import Any

import pytest
from node_msgs import String

from ninjemys.master.client import MasterClient
from ninjemys.node import Node
from ninjemys.testing import wait_until


class _Door:
    """Wraps one MasterClient method: the first call waits at the door until it is opened."""

    def __init__(self, client: MasterClient, method: str) -> None:
        self.arrived = threading.Event()
        self.opened = threading.Event()
        real = getattr(client, method)
        first = [True]

        def held(*args: Any) -> Any:
            if first[0]:
                first[0] = False
                self.arrived.set()
                assert self.opened.wait(30), "the door was never opened"
            return real(*args)

        setattr(client, method, held)


def _in_thread(fn: Callable[[], object]) -> tuple[threading.Thread, threading.Event]:
    done = threading.Event()

    def run() -> None:
        fn()
        done.set()

    thread = threading.Thread(target=run, daemon=True)
    thread.start()
    return thread, done


def _queued(node: Node, kind: str, name: str) -> int:
    """Calls of ``name`` in line at the node (0 for a node with no line, as before the fix: then only
    the second change completing opens the door, which is what shows the old bug)."""
    turns = getattr(node.registrar, "turns", None)
    return 0 if turns is None else turns.waiting(kind, name)


def _reorder(node: Node, kind: str, name: str, first: Callable[[], object], second: Callable[[], object],
             door: _Door) -> None:  # fmt: skip
    """Run ``first`` (held at the door), then ``second`` from another thread; open the door once
    ``second`` is either done (the order is broken) or waiting its turn (the order is kept)."""
    t1, _ = _in_thread(first)
    assert door.arrived.wait(30), "the first call never reached the master"
    t2, done2 = _in_thread(second)
    wait_until(
        lambda: done2.is_set() or _queued(node, kind, name) >= 2,
        timeout=30,
        what="the second change to be made or to wait its turn",
    )
    door.opened.set()
    t1.join(30)
    t2.join(30)
    assert not t1.is_alive() and not t2.is_alive()


def _state(node: Node) -> tuple[list[str], list[str], list[str]]:
    """The topics/services the master lists ``node`` for: (publications, subscriptions, services)."""
    client = MasterClient(node.master_uri, "/order_probe")
    try:
        state = client.get_system_state()
    finally:
        client.close()
    lists = [[name for name, nodes in part if node.name in nodes] for part in state]
    return lists[0], lists[1], lists[2]


def test_a_resubscribe_is_not_overtaken_by_the_unsubscribe_before_it(make_node) -> None:  # noqa: ANN001
    node = make_node("order_sub")
    old = node.subscriber("chatter", String, None)
    door = _Door(node.master, "unregister_subscriber")
    new: list[Any] = []
    _reorder(node, "sub", "/chatter", old.unregister, lambda: new.append(node.subscriber("chatter", String, None)),
             door)  # fmt: skip
    assert "/chatter" in _state(node)[1], "the master forgot the live subscription"
    assert "/chatter" in node.registrar.subscriptions, "a restarted master would never hear of it again"
    assert _queued(node, "sub", "/chatter") == 0


def test_a_readvertise_is_not_overtaken_by_the_unadvertise_before_it(make_node) -> None:  # noqa: ANN001
    node = make_node("order_pub")
    old = node.publisher("chatter", String)
    door = _Door(node.master, "unregister_publisher")
    _reorder(node, "pub", "/chatter", old.unregister, lambda: node.publisher("chatter", String), door)
    assert "/chatter" in _state(node)[0], "the master forgot the live publication"
    assert "/chatter" in node.registrar.publications


def test_an_unsubscribe_is_not_overtaken_by_the_resubscribe_after_it(make_node) -> None:  # noqa: ANN001
    """The other way round: the subscribe is held, the unsubscribe of that new handle comes after it."""
    node = make_node("order_unsub")
    door = _Door(node.master, "register_subscriber")
    handles: list[Any] = []

    def subscribe() -> None:
        handles.append(node.subscriber("chatter", String, None))

    def unsubscribe() -> None:
        # subscribe() has not returned its handle yet: it is in the node's table already
        node._subscriptions["/chatter"].handles[0].unregister()

    t1, _ = _in_thread(subscribe)
    assert door.arrived.wait(30)
    t2, done2 = _in_thread(unsubscribe)
    wait_until(lambda: done2.is_set() or _queued(node, "sub", "/chatter") >= 2, timeout=30)
    door.opened.set()
    t1.join(30)
    t2.join(30)
    assert "/chatter" not in _state(node)[1], "the master kept a subscription the node dropped"
    assert "/chatter" not in node.registrar.subscriptions


@pytest.mark.parametrize("give_up", [True, False])
def test_a_turn_given_up_while_waiting_does_not_block_the_name(give_up: bool) -> None:
    from ninjemys.node.registration import Turns

    turns = Turns()
    a = turns.take("sub", "/t")
    b = turns.take("sub", "/t")
    c = turns.take("sub", "/t")
    turns.wait(a)
    if give_up:
        turns.done(b)  # b's thread was interrupted before its turn came
        turns.done(a)
    else:
        turns.done(a)
        turns.wait(b)
        turns.done(b)
    turns.wait(c)  # returns at once: a and b are over
    turns.done(c)
    assert turns.waiting("sub", "/t") == 0 and not turns._next and not turns._serving and not turns._finished


def test_a_limited_wait_goes_out_of_turn_and_the_line_still_clears() -> None:
    """A shutting-down node does not wait long for a call still in flight (a hung master)."""
    from ninjemys.node.registration import Turns

    turns = Turns()
    first, second = turns.take("srv", "/s"), turns.take("srv", "/s")
    turns.wait(first)
    assert turns.wait(second, limit=0.05) is False  # first is still in flight
    turns.done(second)  # went out of turn and finished
    assert turns.waiting("srv", "/s") == 2
    turns.done(first)
    assert turns.waiting("srv", "/s") == 0 and not turns._next and not turns._finished


def test_a_reregistration_does_not_undo_an_unsubscribe_made_meanwhile(make_node) -> None:  # noqa: ANN001
    """After a master restart the watchdog registers everything again from a copy of the node's
    registrations; a topic unsubscribed meanwhile must not be registered again behind it."""
    node = make_node("order_rereg")
    handle = node.subscriber("chatter", String, None)
    arrived, opened = threading.Event(), threading.Event()
    real = node.publisher_updates

    def held(topic: str) -> int:  # the watchdog asks this just before its registerSubscriber
        if threading.current_thread().name == "rereg":
            arrived.set()
            assert opened.wait(30)
        return real(topic)

    node.publisher_updates = held  # type: ignore[method-assign]
    rereg = threading.Thread(target=node.registrar._reregister, name="rereg", daemon=True)
    rereg.start()
    assert arrived.wait(30), "the re-registration never reached the subscriber"
    t2, done2 = _in_thread(handle.unregister)
    wait_until(lambda: done2.is_set() or _queued(node, "sub", "/chatter") >= 2, timeout=30)
    opened.set()
    rereg.join(30)
    t2.join(30)
    assert "/chatter" not in _state(node)[1], "the re-registration undid the unsubscribe"
    assert "/chatter" not in node.registrar.subscriptions
