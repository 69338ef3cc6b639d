"""The subscriber's fused receive path (issue 25): a plain stream read by one handle is cut and decoded
in one generated loop. Over TCPROS, UNIXROS and SHMROS every message arrives, once, in order; a
stream the fused loop cannot serve (several handles, latching, raw) still takes the per-frame path;
a large SHMROS message in the middle of small inline ones keeps its place."""

from __future__ import annotations

import threading

import pytest

from ninjemys.idl.loader import get_message_class
from ninjemys.node import subscriber
from ninjemys.testing import wait_until

String = get_message_class("std_msgs/String")

TRANSPORTS = {
    "tcpros": {"NINJEMYS_SHM": "0", "NINJEMYS_UNIXROS": "0"},
    "unixros": {"NINJEMYS_SHM": "0", "NINJEMYS_UNIXROS": "1"},
    "shmros": {"NINJEMYS_SHM": "1", "NINJEMYS_UNIXROS": "1"},
}


@pytest.fixture
def reads(monkeypatch: pytest.MonkeyPatch) -> dict[str, int]:
    """How many reads went each way."""
    counts = {"fused": 0, "frames": 0}
    lock = threading.Lock()
    fused, plain = subscriber.SubConnection.read_decoded, subscriber.SubConnection.read

    def read_decoded(self, *args):  # type: ignore[no-untyped-def]
        with lock:
            counts["fused"] += 1
        return fused(self, *args)

    def read(self, *args):  # type: ignore[no-untyped-def]
        with lock:
            counts["frames"] += 1
        return plain(self, *args)

    monkeypatch.setattr(subscriber.SubConnection, "read_decoded", read_decoded)
    monkeypatch.setattr(subscriber.SubConnection, "read", read)
    return counts


@pytest.mark.parametrize("transport", list(TRANSPORTS))
def test_a_burst_arrives_whole_and_in_order_through_the_fused_loop(
    make_node, monkeypatch: pytest.MonkeyPatch, reads: dict[str, int], transport: str
) -> None:
    for key, value in TRANSPORTS[transport].items():
        monkeypatch.setenv(key, value)
    talker, listener = make_node("talker"), make_node("listener")
    got: list[str] = []
    sub = listener.subscriber("burst", String, lambda m: got.append(m.data), queue_size=None)
    pub = talker.publisher("burst", String, queue_size=None)
    assert wait_until(lambda: pub.get_num_connections() == 1 and sub.get_num_connections() == 1)
    expected = [f"m{i}" for i in range(5000)]
    if transport == "shmros":  # a large message through the ring in the middle of the inline ones
        expected[2500] = "L" * 200_000
    for text in expected:
        pub.publish(String(text))
    assert wait_until(lambda: len(got) >= len(expected), timeout=30), len(got)
    assert got == expected
    assert reads["fused"] > 0
    assert reads["frames"] == 0


def test_a_second_handle_or_a_latched_stream_takes_the_per_frame_path(
    make_node, reads: dict[str, int]
) -> None:
    talker, listener = make_node("talker"), make_node("listener")
    first: list[str] = []
    second: list[str] = []
    a = listener.subscriber("two", String, lambda m: first.append(m.data))
    b = listener.subscriber("two", String, lambda m: second.append(m.data))
    latched: list[str] = []
    c = listener.subscriber("latched", String, lambda m: latched.append(m.data))
    pub = talker.publisher("two", String, queue_size=None)
    lpub = talker.publisher("latched", String, latch=True)
    assert wait_until(lambda: a.get_num_connections() == 1 and c.get_num_connections() == 1)
    assert b.get_num_connections() == 1
    for i in range(200):
        pub.publish(String(f"m{i}"))
    lpub.publish(String("kept"))
    want = [f"m{i}" for i in range(200)]
    assert wait_until(lambda: first == want and second == want and latched == ["kept"])
    assert reads["frames"] > 0
    assert reads["fused"] == 0


def test_a_bounded_queue_keeps_the_newest_and_counts_the_dropped(make_node) -> None:
    """queue_size drop-oldest with the fused loop: a callback blocked while 300 messages arrive sees
    the newest of them, in order, and the handle counts every other one as dropped."""
    talker, listener = make_node("talker"), make_node("listener")
    gate = threading.Event()
    got: list[str] = []

    def slow(msg: object) -> None:
        got.append(msg.data)  # type: ignore[attr-defined]
        gate.wait(10)

    sub = listener.subscriber("bounded", String, slow, queue_size=10)
    pub = talker.publisher("bounded", String, queue_size=None)
    assert wait_until(lambda: pub.get_num_connections() == 1 and sub.get_num_connections() == 1)
    pub.publish(String("first"))
    assert wait_until(lambda: got == ["first"])
    for i in range(300):
        pub.publish(String(f"m{i}"))
    gate.set()
    assert wait_until(lambda: got[-1:] == ["m299"]), got[-3:]
    numbers = [int(text[1:]) for text in got[1:]]
    assert numbers == sorted(numbers)
    assert numbers[-10:] == list(range(290, 300))  # the newest always arrive
    assert len(numbers) + sub.dropped == 300  # and every other one was counted as dropped
    assert sub.dropped > 0


@pytest.mark.parametrize("transport", ["unixros", "shmros"])
def test_a_lone_handle_is_read_and_called_back_by_its_worker_loop_itself(
    make_node, monkeypatch: pytest.MonkeyPatch, capfd: pytest.CaptureFixture[str], transport: str
) -> None:
    """A ping-pong's hop (issue 25): the worker of a lone handle reads, decodes and calls back in its
    own loop, not through the general per-connection dispatch (three calls less per message measured
    ~5 us of CPU on a cold path). A callback that raises is logged and the next message still comes;
    the stream stays on that loop."""
    for key, value in TRANSPORTS[transport].items():
        monkeypatch.setenv(key, value)
    dispatched = [0]
    general = subscriber.Subscriber._read

    def counted(self, conn):  # type: ignore[no-untyped-def]
        dispatched[0] += 1
        return general(self, conn)

    monkeypatch.setattr(subscriber.Subscriber, "_read", counted)
    talker, listener = make_node("talker"), make_node("listener")
    got: list[str] = []
    arrived = threading.Event()

    def callback(msg) -> None:  # type: ignore[no-untyped-def]
        got.append(msg.data)
        arrived.set()
        if msg.data == "m50":
            raise ValueError("callback failed on purpose")

    sub = listener.subscriber("hop", String, callback, queue_size=None)
    pub = talker.publisher("hop", String, queue_size=None)
    assert wait_until(lambda: pub.get_num_connections() == 1 and sub.get_num_connections() == 1)
    assert wait_until(lambda: dispatched[0] >= 1)  # the read made when the worker added the stream
    before = dispatched[0]
    expected = [f"m{i}" for i in range(200)]
    for text in expected:  # one at a time, as a ping-pong sends them
        arrived.clear()
        pub.publish(String(text))
        assert arrived.wait(10.0), text
    assert got == expected
    assert dispatched[0] == before
    err = capfd.readouterr().err  # logged as rospy's "bad callback" on the console (and /rosout)
    assert "bad callback: " in err and "callback failed on purpose" in err
