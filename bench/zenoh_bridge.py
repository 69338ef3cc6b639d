"""Added latency and throughput through two ``zenoh-bridge-ros1`` processes vs direct TCPROS.

Run: ``.venv/bin/python bench/zenoh_bridge.py [round_trips]``. Two masters on localhost, two bridges
(one listens, one connects, TCP, no multicast). Latency: a ping node on graph A and a pong node on
graph B (through both bridges, twice per round trip) against the same nodes on one master (direct
TCPROS); the added one-way latency is half the difference of the p50 round trips (target <= 1 ms).
Throughput: a publisher sends as fast as it can for a few seconds, the far subscriber counts what
arrives: 1 KiB std_msgs/String, then 640x480 rgb8 sensor_msgs/Image.
"""

from __future__ import annotations

import contextlib
import os
import statistics
import subprocess
import sys
import threading
import time
from collections.abc import Iterator

from ninjemys.node import Node
from ninjemys.testing import NodeProcess, free_port, ninjemys_bin, run_master, wait_until

SECONDS = 3.0


@contextlib.contextmanager
def bridged_graphs() -> Iterator[tuple[str, str]]:
    port = free_port()
    with run_master() as a, run_master() as b:
        procs = []
        try:
            for uri, link in ((a, "-l"), (b, "-e")):
                env = dict(os.environ, ROS_MASTER_URI=uri)
                p = NodeProcess(
                    [ninjemys_bin("zenoh-bridge-ros1"), "--ros_master_uri", uri, "--no-multicast-scouting",
                     link, f"tcp/127.0.0.1:{port}"],
                    env=env,
                )  # fmt: skip
                procs.append(p)
                p.wait_for("running:", timeout=30)
            yield a, b
        finally:
            for p in procs:
                p.stop()


def round_trips(uri_ping: str, uri_pong: str, count: int) -> list[float]:
    """Seconds per round trip of a 16-byte string, ``count`` times after a warm-up."""
    from std_msgs.msg import String

    pong = Node("pong", master_uri=uri_pong, rosout=False)
    ping = Node("ping", master_uri=uri_ping, rosout=False)
    try:
        back = pong.publisher("/pong", String, queue_size=100)
        pong.subscriber("/ping", None, lambda raw: back.publish_raw(raw.data), raw=True)
        got = threading.Event()
        ping.subscriber("/pong", None, lambda raw: got.set(), raw=True)
        out = ping.publisher("/ping", String, queue_size=100)
        payload = String("x" * 12).serialize_to_bytes()

        def one(timeout: float) -> bool:
            got.clear()
            out.publish_raw(payload)
            return got.wait(timeout)

        wait_until(lambda: one(0.5), timeout=60, what="the first round trip")
        for _ in range(50):
            one(2.0)
        times = []
        for _ in range(count):
            t0 = time.perf_counter()
            if one(2.0):
                times.append(time.perf_counter() - t0)
        return times
    finally:
        ping.shutdown()
        pong.shutdown()


SINK = """
import sys, threading, time
from ninjemys.node import Node
node = Node("sink", master_uri=sys.argv[1], rosout=False)
count, first = [0], threading.Event()
def got(raw):
    count[0] += 1
    first.set()
node.subscriber(sys.argv[2], None, got, raw=True)
print("ready", flush=True)
first.wait()
print("first", flush=True)
sys.stdin.readline()  # the source starts its timed run: count from here
start = count[0]
sys.stdin.readline()  # the source is done
print("count", count[0] - start, flush=True)
node.shutdown()
"""


def throughput(uri_pub: str, uri_sub: str, type_name: str, payload: bytes, topic: str) -> tuple[float, float]:
    """(messages/s, MB/s) arriving at the far subscriber (its own process) while the publisher sends
    flat out: source and sink never share an interpreter, direct or bridged."""
    from ninjemys.idl.loader import get_message_class

    cls = get_message_class(type_name)
    sink = subprocess.Popen(
        [sys.executable, "-c", SINK, uri_sub, topic], stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True
    )
    assert sink.stdin is not None and sink.stdout is not None
    pub = Node("source", master_uri=uri_pub, rosout=False)
    try:
        assert sink.stdout.readline().strip() == "ready"
        out = pub.publisher(topic, cls, queue_size=200)
        first = threading.Event()
        threading.Thread(target=lambda: (sink.stdout.readline(), first.set()), daemon=True).start()
        wait_until(
            lambda: out.publish_raw(payload) or first.is_set(), timeout=60, what="the first message", step=0.1
        )
        sink.stdin.write("go\n")
        sink.stdin.flush()
        t0 = time.perf_counter()
        while time.perf_counter() - t0 < SECONDS:
            out.publish_raw(payload)
            if len(payload) > 100_000:
                time.sleep(0.001)  # images: let the queue drain rather than measure drops
        time.sleep(0.3)
        elapsed = time.perf_counter() - t0
        sink.stdin.write("done\n")
        sink.stdin.flush()
        line = sink.stdout.readline().split()
        rate = int(line[1]) / elapsed
        return rate, rate * len(payload) / 1e6
    finally:
        pub.shutdown()
        sink.kill()
        sink.wait()


def main() -> None:
    count = int(sys.argv[1]) if len(sys.argv) > 1 else 2000
    os.environ.setdefault("ROS_HOSTNAME", "localhost")
    from sensor_msgs.msg import Image
    from std_msgs.msg import String

    kib = String("k" * 1020).serialize_to_bytes()
    image = Image(
        height=480, width=640, encoding="rgb8", step=1920, data=bytes(640 * 480 * 3)
    ).serialize_to_bytes()
    print(
        f"zenoh-bridge-ros1 vs direct TCPROS on localhost, {count} round trips; load {os.getloadavg()[0]:.2f}"
    )
    with run_master() as one:
        direct = round_trips(one, one, count)
        direct_kib = throughput(one, one, "std_msgs/String", kib, "/load_kib")
        direct_img = throughput(one, one, "sensor_msgs/Image", image, "/load_image")
    with bridged_graphs() as (a, b):
        bridged = round_trips(a, b, count)
        bridged_kib = throughput(a, b, "std_msgs/String", kib, "/load_kib")
        bridged_img = throughput(a, b, "sensor_msgs/Image", image, "/load_image")
    d50, b50 = statistics.median(direct) * 1e3, statistics.median(bridged) * 1e3
    d99 = statistics.quantiles(direct, n=100)[98] * 1e3
    b99 = statistics.quantiles(bridged, n=100)[98] * 1e3
    print(f"round trip direct   p50 {d50:7.3f} ms  p99 {d99:7.3f} ms")
    print(f"round trip bridged  p50 {b50:7.3f} ms  p99 {b99:7.3f} ms  (two bridge crossings each way)")
    print(f"added one-way latency p50 {(b50 - d50) / 2:7.3f} ms (target <= 1 ms)")
    for name, d, b in (
        ("1 KiB String", direct_kib, bridged_kib),
        ("640x480 rgb8 Image", direct_img, bridged_img),
    ):
        print(
            f"{name:20s} direct {d[0]:9.0f} msg/s {d[1]:8.1f} MB/s   bridged {b[0]:9.0f} msg/s {b[1]:8.1f} MB/s"
            f"   ratio {b[0] / d[0]:.2f}x"
        )
    print(f"load average after: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
