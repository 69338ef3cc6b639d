"""``lazy=`` and ``batch=`` subscribers: a lazy thread sleeps through small messages, yet a flood never
fills its socket (the low-water mark wakes it, no message is dropped), ``pull()`` delivers what the
kernel holds on the caller's thread, and a batch callback gets lists in order."""

from __future__ import annotations

import socket
import threading
import time

from ninjemys.testing import wait_until
from std_msgs.msg import Int64, String

LONG = 300.0  # a lazy period far beyond every timeout here


def test_a_flood_never_fills_a_lazy_subscribers_socket(make_node) -> None:
    talker, listener = make_node("talker"), make_node("listener")
    got: list[int] = []
    calls: list[int] = []

    def on_batch(msgs: list[String]) -> None:
        calls.append(len(msgs))
        got.extend(int(m.data[:6]) for m in msgs)

    sub = listener.subscriber("flood", String, on_batch, lazy=LONG, batch=True)
    pub = talker.publisher("flood", String, queue_size=1)  # a full socket would make it drop
    assert wait_until(lambda: pub.get_num_connections() >= 1 and sub.get_num_connections() >= 1)
    time.sleep(0.2)
    calls.clear()
    pad = "x" * 4000
    n = 1000
    for i in range(n):  # 4 MB, far more than the socket buffers hold, in a few seconds
        pub.publish(String(f"{i:06d}{pad}"))
        time.sleep(0.001)
    # all but what is left under the low-water mark arrives unasked; a pull takes the rest
    (conn,) = sub._host._conns.values()
    mark = conn.sock.getsockopt(socket.SOL_SOCKET, socket.SO_RCVLOWAT)
    assert wait_until(lambda: len(got) >= n - mark // 4000 - 1, timeout=30)
    time.sleep(0.2)
    sub.pull()
    assert got == list(range(n))
    assert sum(c.dropped for c in pub._pub.connections) == 0  # type: ignore[attr-defined]
    # woken by the low-water mark (a quarter of the buffer): several 4 kB messages at a time
    assert sorted(calls)[len(calls) // 2] >= 3


def test_pull_delivers_on_the_callers_thread(make_node) -> None:
    talker, listener = make_node("talker"), make_node("listener")
    got: list[tuple[int, str]] = []
    sub = listener.subscriber(
        "n",
        Int64,
        lambda msgs: got.extend((m.data, threading.current_thread().name) for m in msgs),
        lazy=LONG,
        batch=True,
    )
    pub = talker.publisher("n", Int64, queue_size=None)
    assert wait_until(lambda: pub.get_num_connections() >= 1 and sub.get_num_connections() >= 1)
    time.sleep(0.2)  # the connection is taken over (and read once)
    for i in range(5):
        pub.publish(Int64(i))
    time.sleep(0.3)
    assert got == []  # the lazy thread sleeps on
    sub.pull()
    assert [d for d, _ in got] == list(range(5))
    assert {name for _, name in got} == {threading.current_thread().name}
    sub.set_eager(True)  # now every message wakes the thread, which delivers it
    pub.publish(Int64(5))
    assert wait_until(lambda: len(got) == 6, timeout=10)
    assert got[-1][1] != threading.current_thread().name
    sub.unregister()
    assert sub.closed


def test_a_batch_callback_gets_every_message_in_order(make_node) -> None:
    talker, listener = make_node("talker"), make_node("listener")
    batches: list[list[int]] = []
    sub = listener.subscriber("b", Int64, lambda msgs: batches.append([m.data for m in msgs]), batch=True)
    pub = talker.publisher("b", Int64, queue_size=None)
    assert wait_until(lambda: pub.get_num_connections() >= 1 and sub.get_num_connections() >= 1)
    for i in range(200):
        pub.publish(Int64(i))
    assert wait_until(lambda: sum(map(len, batches)) == 200, timeout=10)
    assert [d for b in batches for d in b] == list(range(200))
    assert all(batches)
