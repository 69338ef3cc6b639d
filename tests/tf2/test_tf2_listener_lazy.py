"""The tf listener's lazy /tf subscription: its thread does not wake per message, yet a lookup sees
every message the kernel holds when it is asked, a waiter wakes when its data arrives, and the
subscription stays clean to unregister. The lazy period is set far beyond the test's timeouts, so
an outcome that needs the thread to wake per message could only come from the mechanism under test."""

from __future__ import annotations

import socket
import threading
import time
from collections.abc import Iterator

import pytest

from ninjemys import testing
from ninjemys.node import Node
from ninjemys.testing import wait_until
from ninjemys.tf2 import node as tfnode
from ninjemys.tf2.core import BufferCore

S = 1_000_000_000


@pytest.fixture
def pair(
    monkeypatch: pytest.MonkeyPatch,
) -> Iterator[tuple[tfnode.TransformBroadcaster, tfnode.TransformListener]]:
    monkeypatch.setattr(tfnode, "LAZY_PERIOD", 300.0)
    with testing.run_master() as uri:
        talker = Node("tf_lazy_talker", master_uri=uri)
        listener_node = Node("tf_lazy_listener", master_uri=uri)
        try:
            br = tfnode.TransformBroadcaster(talker)
            listener = tfnode.TransformListener(listener_node, BufferCore())
            assert wait_until(
                lambda: br.pub_tf.get_num_connections() == 1 and listener.tf_sub.get_num_connections() == 1
            )
            time.sleep(0.2)  # the listener's thread takes the connection over (and reads it once)
            yield br, listener
        finally:
            listener_node.shutdown("test done")
            talker.shutdown("test done")


def _send(br: tfnode.TransformBroadcaster, stamp: float, child: str = "base") -> None:
    br.send_items([("odom", child, int(round(stamp * S)), stamp, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0)])


def test_a_lookup_sees_what_the_kernel_holds(pair) -> None:
    br, listener = pair
    buf = listener.buffer
    for k in range(20):
        _send(br, 10.0 + 0.01 * k)
    time.sleep(0.3)  # in the listener's socket now; its thread sleeps on
    assert "base" not in buf._frames and not buf._pending  # nothing was read behind our back
    stamp, tr = buf.lookup("odom", "base", 0)
    assert stamp == int(round(10.19 * S))
    assert tr[0] == pytest.approx(10.19)
    _send(br, 11.0)
    time.sleep(0.1)
    assert buf.can_transform("odom", "base", int(11.0 * S)) == (True, "")


def test_a_waiter_wakes_when_its_data_arrives(pair) -> None:
    br, listener = pair
    buf = listener.buffer
    got: list[tuple[bool, str]] = []
    waiter = threading.Thread(
        target=lambda: got.append(buf.wait_for_transform(lambda: buf.can_transform("odom", "late", 0), 20.0))
    )
    waiter.start()
    time.sleep(0.3)
    _send(br, 5.0, child="late")
    waiter.join(30.0)
    assert got and got[0][0]  # within the wait's 20 s, while the lazy period is 300 s
    assert wait_until(lambda: not listener.tf_sub._host._eager)  # lazy again once nobody waits


def test_the_sockets_wake_the_thread_before_they_fill(pair) -> None:
    _br, listener = pair
    sub = listener.tf_sub
    (conn,) = sub._host._conns.values()
    mark = conn.sock.getsockopt(socket.SOL_SOCKET, socket.SO_RCVLOWAT)
    assert mark == max(1, conn.sock.getsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF) // 4)
    sub.set_eager(True)
    assert wait_until(lambda: conn.sock.getsockopt(socket.SOL_SOCKET, socket.SO_RCVLOWAT) == 1)
    sub.set_eager(False)
    assert wait_until(lambda: conn.sock.getsockopt(socket.SOL_SOCKET, socket.SO_RCVLOWAT) == mark)


def test_unregister_ends_the_lazy_thread(pair) -> None:
    _br, listener = pair
    thread = listener.tf_sub._thread
    assert listener.buffer._sources == [listener]
    listener.unregister()
    thread.join(5.0)
    assert not thread.is_alive()
    assert listener.buffer._sources == []


def test_under_simulated_time_every_message_wakes_the_listener() -> None:
    """A jump back of /clock clears the buffer: only messages delivered as they arrive are known to be
    older or newer than the jump, so the listener is not lazy under simulated time."""
    with testing.run_master() as uri:
        node = Node("tf_lazy_sim", master_uri=uri, sim_time=True)
        try:
            listener = tfnode.TransformListener(node, BufferCore(), now=lambda: node.clock.now())
            assert listener.tf_sub._host._eager
            listener.buffer.set_transforms([("odom", "base", 1, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0)])
            listener.buffer.lookup("odom", "base", 0)  # pulls: still eager
            assert listener.tf_sub._host._eager
        finally:
            node.shutdown("test done")
