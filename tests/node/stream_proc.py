"""A ninjemys publisher in its own process for the sustained-stream tests.

``stream_proc.py MASTER_URI KIND RATE SECONDS``: KIND is ``cloud`` (1 MB sensor_msgs/PointCloud2 on
/cloud), ``image`` (640x480 rgb8 sensor_msgs/Image on /image) or ``small`` (std_msgs/Header on
/small); RATE in Hz, 0 for back to back. Every message carries its sequence number and the wall time
of its publication in its header. Prints "ready" once a subscriber is connected, "done N" at the end.
"""

from __future__ import annotations

import sys
import time

from ninjemys.node import Node
from sensor_msgs.msg import Image, PointCloud2, PointField
from std_msgs.msg import Header


def message(kind: str) -> tuple[type, object]:
    if kind == "cloud":
        names = ("x", "y", "z", "intensity")
        fields = [
            PointField(name=n, offset=4 * i, datatype=PointField.FLOAT32, count=1)
            for i, n in enumerate(names)
        ]
        n = (1 << 20) // 16
        cloud = PointCloud2(height=1, width=n, fields=fields, point_step=16, row_step=16 * n, is_dense=True)
        cloud.data = bytes(1 << 20)
        return PointCloud2, cloud
    if kind == "image":
        return Image, Image(height=480, width=640, encoding="rgb8", step=640 * 3, data=bytes(640 * 480 * 3))
    return Header, Header()


def main() -> None:
    master_uri, kind, rate, seconds = sys.argv[1], sys.argv[2], float(sys.argv[3]), float(sys.argv[4])
    node = Node(f"stream_{kind}", master_uri=master_uri)
    msg_class, msg = message(kind)
    pub = node.publisher(f"/{kind}", msg_class, queue_size=None)
    while pub.get_num_connections() < 1:
        time.sleep(0.01)
    time.sleep(0.2)
    print("ready", flush=True)
    header = msg if kind == "small" else msg.header  # type: ignore[attr-defined]
    seq = 0
    start = time.monotonic()
    while time.monotonic() - start < seconds:
        seq += 1
        header.seq = seq
        header.stamp.secs, header.stamp.nsecs = divmod(time.time_ns(), 1_000_000_000)
        pub.publish(msg)
        if rate:
            time.sleep(max(0.0, start + seq / rate - time.monotonic()))
    print(f"done {seq}", flush=True)
    node.shutdown("done")


if __name__ == "__main__":
    main()
