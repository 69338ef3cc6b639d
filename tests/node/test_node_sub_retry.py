"""A subscriber keeps trying a publisher the master lists when the first attempt fails.

rospy retries a failed connection (0.5 s, doubling up to 30 s) while the publisher is listed; a
subscriber that gave up after one failure stayed deaf for good (a CI run of the seed's roslaunch
talker/listener heard nothing for 90 s on a loaded machine).
"""

from __future__ import annotations

import threading
import time

from ninjemys.idl.loader import get_message_class


def test_a_declined_request_topic_is_tried_again(make_node) -> None:
    string = get_message_class("std_msgs/String")
    talker = make_node("talker")
    pub = talker.publisher("/chatter", string, queue_size=10)
    declined = []
    real = talker.publishes

    def first_two_declined(topic: str) -> bool:  # as if the node did not know the topic yet
        if topic == "/chatter" and len(declined) < 2:
            declined.append(time.monotonic())
            return False
        return real(topic)

    talker.publishes = first_two_declined  # type: ignore[method-assign]
    heard = threading.Event()
    listener = make_node("listener")
    listener.subscriber("/chatter", string, lambda m: heard.set())
    deadline = time.monotonic() + 20.0
    while not heard.is_set() and time.monotonic() < deadline:
        pub.publish(string(data="hello"))
        time.sleep(0.05)
    assert heard.is_set(), f"never connected after {len(declined)} declined requests"
    assert len(declined) == 2 and declined[1] - declined[0] >= 0.4  # backed off before trying again
