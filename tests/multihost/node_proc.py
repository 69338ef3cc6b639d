"""A ninjemys talker or listener for the multi-host tests (run inside a host's namespace).

``talker TOPIC TAG`` publishes ``"TAG i"`` at 20 Hz; ``listener TOPIC`` prints ``got <data>`` per
message, flushed, so the test sees arrivals as they happen.
"""

from __future__ import annotations

import sys
import time

from ninjemys.idl.loader import get_message_class
from ninjemys.node import Node

String = get_message_class("std_msgs/String")


def main() -> None:
    role, topic = sys.argv[1], sys.argv[2]
    node = Node(f"/{role}_{sys.argv[3]}")
    if role == "talker":
        pub = node.publisher(topic, String)
        print("ready", flush=True)
        i = 0
        while not node.is_shutdown:
            pub.publish(String(f"{sys.argv[3]} {i}"))
            i += 1
            time.sleep(0.05)
    else:
        node.subscriber(topic, String, lambda m: print(f"got {m.data} {time.time():.3f}", flush=True))
        print("ready", flush=True)
        node.spin()


if __name__ == "__main__":
    main()
