"""``Node.subscriber(share_thread=handle)``: several subscriptions read and called back by one thread
(what message_filters' Subscribers use), and what happens to their streams as handles close."""

from __future__ import annotations

import threading

from ninjemys.idl.loader import get_message_class
from ninjemys.node import Node
from ninjemys.testing import run_master, wait_until

String = get_message_class("std_msgs/String")


def test_shared_thread_serves_every_topic_and_hands_streams_on() -> None:
    with run_master() as uri:
        pub_node = Node("share_pub", anonymous=True, master_uri=uri)
        sub_node = Node("share_sub", anonymous=True, master_uri=uri)
        try:
            pubs = {t: pub_node.publisher(t, String, queue_size=10) for t in ("/share_a", "/share_b")}
            got: dict[str, list[str]] = {"a": [], "b": [], "b2": []}
            threads: set[str] = set()

            def on(key: str):  # type: ignore[no-untyped-def]
                def cb(msg) -> None:  # type: ignore[no-untyped-def]
                    threads.add(threading.current_thread().name)
                    got[key].append(msg.data)

                return cb

            host = sub_node.subscriber("/share_a", String, on("a"))
            guest = sub_node.subscriber("/share_b", String, on("b"), share_thread=host)
            assert guest._thread is host._thread  # one worker for both
            assert "sub:/share_b" not in {t.name for t in threading.enumerate()}
            assert wait_until(lambda: all(p.get_num_connections() for p in pubs.values()))
            pubs["/share_a"].publish(String("a1"))
            pubs["/share_b"].publish(String("b1"))
            assert wait_until(lambda: got["a"] == ["a1"] and got["b"] == ["b1"])
            assert threads == {"sub:/share_a"}

            # the host closes: its thread goes on delivering the guest's topic
            host.unregister()
            pubs["/share_b"].publish(String("b2"))
            assert wait_until(lambda: got["b"] == ["b1", "b2"])

            # a second handle of /b (its own thread); when the guest closes, /b's stream goes to it
            second = sub_node.subscriber("/share_b", String, on("b2"))
            assert wait_until(lambda: second.get_num_connections() == 1)
            pubs["/share_b"].publish(String("b3"))
            assert wait_until(lambda: got["b2"] == ["b3"] and got["b"] == ["b1", "b2", "b3"])
            guest.unregister()
            assert not host._thread.is_alive()  # the last handle it served closed: it ended
            pubs["/share_b"].publish(String("b4"))
            assert wait_until(lambda: got["b2"] == ["b3", "b4"])
            assert got["b"] == ["b1", "b2", "b3"]
            assert got["a"] == ["a1"]
        finally:
            sub_node.shutdown("test over")
            pub_node.shutdown("test over")


def test_guest_closing_first_leaves_the_host_serving_and_a_closed_host_is_not_joined() -> None:
    with run_master() as uri:
        pub_node = Node("share_pub2", anonymous=True, master_uri=uri)
        sub_node = Node("share_sub2", anonymous=True, master_uri=uri)
        try:
            pub_a = pub_node.publisher("/share_a", String, queue_size=10)
            got: list[str] = []
            host = sub_node.subscriber("/share_a", String, lambda m: got.append(m.data))
            guest = sub_node.subscriber("/share_c", String, lambda m: None, share_thread=host)
            guest.unregister()
            assert host._thread.is_alive()
            assert wait_until(lambda: pub_a.get_num_connections() == 1)
            pub_a.publish(String("x"))
            assert wait_until(lambda: got == ["x"])
            host.unregister()
            assert not host._thread.is_alive()
            # a handle asked to share a finished thread gets a thread of its own
            late = sub_node.subscriber("/share_a", String, lambda m: got.append(m.data), share_thread=host)
            assert late._thread is not host._thread and late._thread.is_alive()
            assert wait_until(lambda: late.get_num_connections() == 1)
            pub_a.publish(String("y"))
            assert wait_until(lambda: got == ["x", "y"])
        finally:
            sub_node.shutdown("test over")
            pub_node.shutdown("test over")
        assert not late._thread.is_alive()
