"""A worker with one stream whose messages come fast sleeps in that socket's ``recv`` (one system
call per message) instead of its poller (see ``Subscriber._solo_rounds``). What that must keep: it
really waits there while the stream flows and goes back to the poller once it stops; a second
publisher, a second handle, an unregister, a dropped publisher and a node's shutdown are all still
seen while the worker sleeps in ``recv``, and no message is lost or left behind on the way."""

from __future__ import annotations

import logging
import os
import platform
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager

import pytest
from node_msgs import String

from ninjemys.testing import wait_until

#: x86_64 system call numbers, as /proc/<pid>/task/<tid>/syscall shows them
RECVFROM = 45
POLLER = {232, 281, 441}  # epoll_wait, epoll_pwait, epoll_pwait2


@contextmanager
def streaming(publish: Callable[[int], None], hz: float = 200.0) -> Iterator[list[int]]:
    """Call ``publish(i)`` ``hz`` times a second on a thread until the block ends; yields the list of
    the numbers published so far."""
    sent: list[int] = []
    stop = threading.Event()

    def run() -> None:
        i = 0
        while not stop.is_set():
            publish(i)
            sent.append(i)
            i += 1
            time.sleep(1.0 / hz)

    thread = threading.Thread(target=run, daemon=True)
    thread.start()
    try:
        yield sent
    finally:
        stop.set()
        thread.join(5.0)


def _syscalls(thread: threading.Thread, samples: int = 60) -> list[int]:
    """The system call ``thread`` is in, sampled every 5 ms (-1: running, not in one)."""
    seen = []
    path = f"/proc/{os.getpid()}/task/{thread.native_id}/syscall"
    for _ in range(samples):
        with open(path) as f:
            field = f.read().split()[0]
        seen.append(int(field) if field.lstrip("-").isdigit() else -1)
        time.sleep(0.005)
    return seen


@pytest.mark.skipif(
    platform.system() != "Linux" or platform.machine() != "x86_64", reason="x86_64 Linux system call numbers"
)
def test_a_fast_stream_is_waited_for_in_recv_and_an_idle_one_in_the_poller(make_node) -> None:
    talker, listener = make_node("talker"), make_node("listener")
    got: list[str] = []
    sub = listener.subscriber("fast", String, lambda m: got.append(m.data), queue_size=10)
    pub = talker.publisher("fast", String, queue_size=10)
    assert wait_until(lambda: pub.get_num_connections() == 1)
    with streaming(lambda i: pub.publish(String(f"m{i}"))):
        assert wait_until(lambda: len(got) > 20)
        during = _syscalls(sub._thread)
    assert during.count(RECVFROM) > len(during) // 2, during
    time.sleep(0.5)  # more than _BLOCKING_WAIT: the recv timed out, the poller waits now
    idle = _syscalls(sub._thread, samples=10)
    assert all(call in POLLER for call in idle), idle


def test_a_second_publisher_joins_a_fast_stream(make_node) -> None:
    first, second, listener = make_node("first"), make_node("second"), make_node("listener")
    got: list[str] = []
    listener.subscriber("joined", String, lambda m: got.append(m.data), queue_size=None)
    pub1 = first.publisher("joined", String, queue_size=None)
    assert wait_until(lambda: pub1.get_num_connections() == 1)
    with streaming(lambda i: pub1.publish(String(f"a{i}"))):
        assert wait_until(lambda: len(got) > 20)
        pub2 = second.publisher("joined", String, queue_size=None, latch=True)
        pub2.publish(String("latched from the second"))
        assert wait_until(lambda: "latched from the second" in got)
        pub2.publish(String("b1"))
        assert wait_until(lambda: "b1" in got)
    firsts = [int(m[1:]) for m in got if m.startswith("a")]
    assert firsts == list(range(firsts[0], firsts[0] + len(firsts)))  # in order, none lost


def test_unregister_and_shutdown_under_a_fast_stream_end_the_worker(make_node) -> None:
    talker, listener, other = make_node("talker"), make_node("listener"), make_node("other")
    got: list[str] = []
    sub = listener.subscriber("ends", String, lambda m: got.append(m.data), queue_size=10)
    sub2 = other.subscriber("ends", String, lambda m: got.append(m.data), queue_size=10)
    pub = talker.publisher("ends", String, queue_size=10)
    assert wait_until(lambda: pub.get_num_connections() == 2)
    with streaming(lambda i: pub.publish(String(f"m{i}"))):
        assert wait_until(lambda: len(got) > 40)
        conns = list(sub._conns.values())
        assert len(conns) == 1 and conns[0].flags  # the worker may wait in its recv
        sub.unregister()
        assert not sub._thread.is_alive()
        assert wait_until(lambda: conns[0].closed)
        other.shutdown("test over")
        assert wait_until(lambda: not sub2._thread.is_alive())
    assert wait_until(lambda: pub.get_num_connections() == 0)


def test_the_next_handle_gets_every_message_across_the_readers_unregister(make_node) -> None:
    talker, listener = make_node("talker"), make_node("listener")
    first: list[int] = []
    second: list[int] = []
    reader = listener.subscriber("handover", String, lambda m: first.append(int(m.data)), queue_size=None)
    pub = talker.publisher("handover", String, queue_size=None)
    assert wait_until(lambda: pub.get_num_connections() == 1)
    with streaming(lambda i: pub.publish(String(str(i))), hz=300.0) as sent:
        assert wait_until(lambda: len(first) > 30)  # the reader's worker sleeps in recv now
        listener.subscriber("handover", String, lambda m: second.append(int(m.data)), queue_size=None)
        reader.unregister()
        assert wait_until(lambda: len(second) > 60)
    assert wait_until(lambda: second and second[-1] == sent[-1])
    assert second == list(range(second[0], sent[-1] + 1))  # nothing lost at the hand-over


def test_a_dropped_publisher_under_a_wait_leaves_the_worker_serving(make_node, caplog) -> None:
    """The drop ends the worker's recv at once (the socket shut down under it) and without a word:
    the stream did not end on its own, so neither "publisher closed the connection" nor a retry."""
    caplog.set_level(logging.INFO, logger="ninjemys.node.subscriber")
    talker, later, listener = make_node("talker"), make_node("later"), make_node("listener")
    got: list[str] = []
    sub = listener.subscriber("dropped", String, lambda m: got.append(m.data), queue_size=None)
    pub = talker.publisher("dropped", String, queue_size=None)
    assert wait_until(lambda: pub.get_num_connections() == 1)
    with streaming(lambda i: pub.publish(String(f"m{i}"))):
        assert wait_until(lambda: len(got) > 20)
        conn = next(iter(sub._conns.values()))
        # the master's publisherUpdate without it (on the loop, as the slave API applies it): a drop
        listener.runtime.call_soon(sub._sub.update_publishers, [])
        assert wait_until(lambda: conn.closed and not sub._conns)
    said = [r.getMessage() for r in caplog.records if r.name == "ninjemys.node.subscriber"]
    assert not [line for line in said if "closed the connection" in line or "read failed" in line], said
    assert sub._thread.is_alive()
    pub2 = later.publisher("dropped", String, queue_size=None)
    assert wait_until(lambda: sub.get_num_connections() == 2)
    count = len(got)
    pub2.publish(String("after the drop"))
    assert wait_until(lambda: "after the drop" in got[count:])
