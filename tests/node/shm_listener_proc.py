"""A ninjemys subscriber in its own process for the shared-memory kill tests.

``shm_listener_proc.py MASTER_URI TOPIC``: subscribes to sensor_msgs/Image on TOPIC and prints
"got N" after every message (N counts them), keeping the last few messages alive (views into the ring).
"""

from __future__ import annotations

import sys
import time
from collections import deque

from ninjemys.node import Node
from sensor_msgs.msg import Image


def main() -> None:
    master_uri, topic = sys.argv[1:3]
    node = Node("shm_listener", master_uri=master_uri)
    kept: deque[Image] = deque(maxlen=2)
    count = 0

    def on_image(msg: Image) -> None:
        nonlocal count
        count += 1
        kept.append(msg)
        print(f"got {count}", flush=True)

    node.subscriber(topic, Image, on_image)
    while not node.is_shutdown:
        time.sleep(0.1)


if __name__ == "__main__":
    main()
