"""A second Subscriber handle of a topic in one node (frames handed over by the reader handle) keeps
receiving under a fast stream: its wake-up flag is cleared only after the wake-up pipe is drained."""

from __future__ import annotations

import threading
import time

from ninjemys.node import Node
from ninjemys.testing import run_master, wait_until


def test_second_handle_of_a_fast_topic_never_stalls() -> None:
    from ninjemys.rostime import Time
    from rosgraph_msgs.msg import Clock

    with run_master() as uri:
        pub_node = Node("fast_clock", anonymous=True, master_uri=uri)
        sub_node = Node("two_handles", anonymous=True, master_uri=uri)
        try:
            pub = pub_node.publisher("/clock", Clock, queue_size=10)
            counts = [0, 0]

            def first(_msg) -> None:  # type: ignore[no-untyped-def]
                counts[0] += 1

            def second(_msg) -> None:  # type: ignore[no-untyped-def]
                counts[1] += 1

            sub_node.subscriber("/clock", Clock, first, queue_size=1)
            sub_node.subscriber("/clock", Clock, second, queue_size=1)
            deadline = time.monotonic() + 10
            while pub.get_num_connections() == 0 and time.monotonic() < deadline:
                time.sleep(0.01)
            stop = threading.Event()

            def run() -> None:
                i = 0
                while not stop.is_set():
                    i += 1
                    pub.publish(Clock(clock=Time(i // 1000, (i % 1000) * 1_000_000)))

            threading.Thread(target=run, daemon=True).start()
            # the second handle keeps receiving: after each of 12 quarter seconds of the stream it has
            # received more. A lost wake-up stalls it for good; a loaded machine may only starve its
            # thread for a while, so each round waits for the next message (no timed assertion)
            try:
                seen = [0]
                for _ in range(12):
                    time.sleep(0.25)
                    last = seen[-1]
                    seen.append(
                        wait_until(
                            lambda last=last: counts[1] > last and counts[1],
                            timeout=15.0,
                            what=f"the second handle to receive more than {last} messages",
                        )
                    )
            finally:
                stop.set()
            assert all(b > a for a, b in zip(seen, seen[1:], strict=False)), seen
        finally:
            sub_node.shutdown("test over")
            pub_node.shutdown("test over")
