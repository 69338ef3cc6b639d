"""``coalesce``: a subscriber that lets messages gather between wake-ups still gets every one, in
order, and a message published alone is delivered within about the coalescing interval."""

from __future__ import annotations

import time

from ninjemys.testing import wait_until
from std_msgs.msg import Int64


def test_coalescing_subscriber_gets_every_message_in_order(make_node) -> None:
    talker, listener = make_node("talker"), make_node("listener")
    got: list[int] = []
    sub = listener.subscriber("n", Int64, lambda m: got.append(m.data), coalesce=0.02)
    pub = talker.publisher("n", Int64, queue_size=None)
    assert wait_until(lambda: pub.get_num_connections() >= 1)
    for i in range(500):
        pub.publish(Int64(i))
        if i % 100 == 0:
            time.sleep(0.01)
    assert wait_until(lambda: len(got) == 500, timeout=10)
    assert got == list(range(500))
    # alone, after a quiet spell: it still arrives (the worker sleeps, then polls again)
    time.sleep(0.1)
    pub.publish(Int64(-1))
    assert wait_until(lambda: got[-1] == -1, timeout=5)
    sub.unregister()
    assert sub.closed
