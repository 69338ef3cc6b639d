"""A ninjemys publisher in its own process that holds a loan, for the shared-memory kill test.

``shm_loan_proc.py MASTER_URI TOPIC``: once a subscriber is connected, publishes one loaned
640x480 rgb8 sensor_msgs/Image (every byte 9) on TOPIC, then takes a second loan, fills it half way
and prints "holding shared" (or "holding heap") while it keeps that loan, until killed.
"""

from __future__ import annotations

import sys
import time

from ninjemys.node import Node
from sensor_msgs.msg import Image

W, H = 640, 480


def main() -> None:
    master_uri, topic = sys.argv[1:3]
    node = Node("shm_loaner", master_uri=master_uri)
    pub = node.publisher(topic, Image, queue_size=None)
    while pub.get_num_connections() < 1:
        time.sleep(0.01)
    time.sleep(0.2)
    with pub.loan(H * W * 3, height=H, width=W, encoding="rgb8", step=W * 3) as msg:
        msg.data[:] = 9
        pub.publish(msg)
    kept = pub.loan(H * W * 3, height=H, width=W, encoding="rgb8", step=W * 3)
    kept.msg.data[: H * W] = 1  # killed "mid-write"
    print(f"holding {'shared' if kept.shared else 'heap'}", flush=True)
    while not node.is_shutdown:
        time.sleep(0.1)


if __name__ == "__main__":
    main()
