"""Direct in-process delivery (``direct=True``): an idle subscriber handle is called back on the
publisher's thread inside ``publish()`` (a nodelet's publish, no wake-up); a busy one queues as
before, so ``queue_size``, ordering and "callbacks of one handle never overlap" all hold."""

from __future__ import annotations

import threading
import time

import pytest
from node_msgs import String

from ninjemys.errors import NinjemysError
from ninjemys.idl.loader import get_message_class
from ninjemys.testing import wait_until

Header = get_message_class("std_msgs/Header")


def _connected(pub, n: int = 1) -> bool:  # noqa: ANN001
    return wait_until(lambda: pub.get_num_connections() == n)


def test_an_idle_direct_handle_is_called_back_inside_publish(make_node) -> None:  # noqa: ANN001
    talker, listener = make_node("talker"), make_node("listener")
    pub = talker.publisher("chatter", String, intraprocess=True)
    seen: list[tuple[object, str]] = []
    listener.subscriber(
        "chatter",
        String,
        lambda m: seen.append((m, threading.current_thread().name)),
        intraprocess=True,
        direct=True,
    )
    assert _connected(pub)
    msg = String(data="now")
    pub.publish(msg)
    # delivered before publish() returned, on this thread, the object itself
    assert seen == [(msg, threading.current_thread().name)]


def test_several_subscribers_direct_queued_and_remote(make_node) -> None:  # noqa: ANN001
    talker = make_node("talker")
    pub = talker.publisher("chatter", String, intraprocess=True)
    seen: dict[str, list[tuple[str, str]]] = {"a": [], "b": [], "queued": [], "remote": []}

    def keep(who: str):  # noqa: ANN202
        return lambda m: seen[who].append((m.data, threading.current_thread().name))

    make_node("a").subscriber("chatter", String, keep("a"), intraprocess=True, direct=True)
    make_node("b").subscriber("chatter", String, keep("b"), intraprocess=True, direct=True)
    make_node("queued").subscriber("chatter", String, keep("queued"), intraprocess=True)
    make_node("remote").subscriber("chatter", String, keep("remote"))
    assert _connected(pub, 4)
    me = threading.current_thread().name
    for i in range(3):
        pub.publish(String(data=str(i)))
    assert seen["a"] == seen["b"] == [(str(i), me) for i in range(3)]  # before publish returned
    assert wait_until(lambda: len(seen["queued"]) == 3 and len(seen["remote"]) == 3)
    assert [d for d, _ in seen["queued"]] == [d for d, _ in seen["remote"]] == ["0", "1", "2"]
    assert {t for _, t in seen["queued"]} == {"sub:/chatter"}


def test_a_copy_when_the_publisher_did_not_opt_in(make_node) -> None:  # noqa: ANN001
    talker, listener = make_node("talker"), make_node("listener")
    pub = talker.publisher("chatter", Header)
    seen: list[object] = []
    listener.subscriber("chatter", Header, seen.append, intraprocess=True, direct=True)
    assert _connected(pub)
    msg = Header(frame_id="a")
    pub.publish(msg)
    assert len(seen) == 1 and seen[0] is not msg and seen[0].frame_id == "a"


def test_a_busy_handle_queues_keeps_order_and_never_overlaps(make_node) -> None:  # noqa: ANN001
    talker, listener = make_node("talker"), make_node("listener")
    pub = talker.publisher("count", Header, intraprocess=True, queue_size=None)
    got: list[tuple[str, int]] = []
    running = [0]
    overlaps = [0]
    threads: set[str] = set()

    def slow(msg) -> None:  # noqa: ANN001
        running[0] += 1
        if running[0] > 1:
            overlaps[0] += 1
        threads.add(threading.current_thread().name)
        who, n = msg.frame_id.split(":")
        got.append((who, int(n)))
        time.sleep(0.0005)
        running[0] -= 1

    listener.subscriber("count", Header, slow, intraprocess=True, direct=True)
    assert _connected(pub)

    def burst(who: str) -> None:
        for i in range(200):
            pub.publish(Header(frame_id=f"{who}:{i}"))

    workers = [threading.Thread(target=burst, args=(w,), name=f"pub-{w}") for w in "ab"]
    for t in workers:
        t.start()
    for t in workers:
        t.join(30)
    assert wait_until(lambda: len(got) == 400, timeout=30)
    assert overlaps[0] == 0
    for who in "ab":  # each publisher's messages in the order published
        assert [n for w, n in got if w == who] == list(range(200))
    # some were called back on the publishing threads, some (while busy) on the handle's own thread
    assert threads & {"pub-a", "pub-b"}
    assert "sub:/count" in threads


def test_queue_size_applies_while_a_direct_callback_is_busy(make_node) -> None:  # noqa: ANN001
    talker, listener = make_node("talker"), make_node("listener")
    pub = talker.publisher("burst", Header, intraprocess=True, queue_size=100)
    release = threading.Event()
    got: list[str] = []

    def slow(msg) -> None:  # noqa: ANN001
        got.append(msg.frame_id)
        if msg.frame_id == "first":
            release.wait(10)

    sub = listener.subscriber("burst", Header, slow, queue_size=2, intraprocess=True, direct=True)
    assert _connected(pub)
    blocked = threading.Thread(target=pub.publish, args=(Header(frame_id="first"),))
    blocked.start()  # called back on that thread, which now waits in the callback
    assert wait_until(lambda: got == ["first"])
    for i in range(10):
        pub.publish(Header(frame_id=str(i)))  # busy: queued, the oldest dropped beyond 2
    assert got == ["first"]
    release.set()
    blocked.join(10)
    assert wait_until(lambda: len(got) == 3)
    time.sleep(0.2)
    assert got == ["first", "8", "9"]
    assert sub.dropped == 8


def test_a_callback_publishing_on_its_own_topic_does_not_recurse(make_node) -> None:  # noqa: ANN001
    node = make_node("loop")
    pub = node.publisher("echo", Header, intraprocess=True)
    depth = [0, 0]  # now, deepest
    got: list[int] = []

    def again(msg) -> None:  # noqa: ANN001
        depth[0] += 1
        depth[1] = max(depth[1], depth[0])
        got.append(int(msg.frame_id))
        if len(got) < 50:
            pub.publish(Header(frame_id=str(len(got) + 1)))
        depth[0] -= 1

    node.subscriber("echo", Header, again, intraprocess=True, direct=True)
    assert _connected(pub)
    pub.publish(Header(frame_id="1"))
    assert wait_until(lambda: len(got) == 50)
    assert depth[1] == 1 and got == list(range(1, 51))


def test_unregister_waits_for_a_direct_callback_in_flight(make_node) -> None:  # noqa: ANN001
    talker, listener = make_node("talker"), make_node("listener")
    pub = talker.publisher("t", Header, intraprocess=True)
    inside, done = threading.Event(), threading.Event()

    def slow(msg) -> None:  # noqa: ANN001
        inside.set()
        time.sleep(0.3)
        done.set()

    sub = listener.subscriber("t", Header, slow, intraprocess=True, direct=True)
    assert _connected(pub)
    threading.Thread(target=pub.publish, args=(Header(),), daemon=True).start()
    assert inside.wait(5)
    sub.unregister()
    assert done.is_set()  # no callback of the handle runs once unregister has returned


def test_a_direct_callback_may_unregister_its_handle_without_a_stall(make_node) -> None:  # noqa: ANN001
    talker, listener = make_node("talker"), make_node("listener")
    pub = talker.publisher("t", Header, intraprocess=True)
    queued = threading.Event()
    took: list[float] = []
    handle: list[object] = []

    def once(msg) -> None:  # noqa: ANN001
        if msg.frame_id != "first":
            return
        other = threading.Thread(target=pub.publish, args=(Header(frame_id="second"),))
        other.start()  # this handle is busy: queued, and its worker waits for the handle's lock
        other.join(5)
        queued.set()
        time.sleep(0.05)
        start = time.monotonic()
        handle[0].unregister()  # type: ignore[attr-defined]
        took.append(time.monotonic() - start)

    handle.append(listener.subscriber("t", Header, once, intraprocess=True, direct=True))
    assert _connected(pub)
    pub.publish(Header(frame_id="first"))
    assert queued.is_set() and len(took) == 1
    assert took[0] < 1.0  # not the 2 s join of a worker that waits for the lock this thread holds


def test_latched_replay_is_not_run_on_the_io_loop(make_node) -> None:  # noqa: ANN001
    talker, listener = make_node("talker"), make_node("listener")
    pub = talker.publisher("map", Header, latch=True, intraprocess=True)
    pub.publish(Header(frame_id="map"))
    where: list[str] = []
    listener.subscriber("map", Header, lambda m: where.append(threading.current_thread().name),
                        intraprocess=True, direct=True)  # fmt: skip
    assert wait_until(lambda: len(where) == 1)
    assert where == ["sub:/map"]


def test_direct_needs_intraprocess_and_its_own_thread(make_node) -> None:  # noqa: ANN001
    node = make_node("bad")
    with pytest.raises(NinjemysError, match="direct=True needs intraprocess=True"):
        node.subscriber("x", Header, print, direct=True)
    with pytest.raises(NinjemysError, match="lazy or share_thread"):
        node.subscriber("x", Header, print, intraprocess=True, direct=True, lazy=0.1)
