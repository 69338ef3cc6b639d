"""Benchmark processes written against the rospy API, so the very same code runs under ninjemys
(the project venv) and under Debian's real rospy (/usr/bin/python3).

Usage: ``python bench/node_roles.py ROLE [ARGS...]``; every measuring role prints one JSON line.
The drivers (bench/node_*.py) start these in pairs, pinned with taskset, and print ratios.
"""

from __future__ import annotations

import json
import os
import sys
import threading
import time


def _pct(values: list[float], q: float) -> float:
    values = sorted(values)
    if not values:
        return float("nan")
    return values[min(len(values) - 1, int(q * len(values)))]


def _wait_connections(pub, n: int = 1, timeout: float = 20.0) -> None:
    deadline = time.monotonic() + timeout
    while pub.get_num_connections() < n and time.monotonic() < deadline:
        time.sleep(0.01)


def _queue_size(text: str) -> int | None:
    return None if text == "None" else int(text)


def pong(queue_size: str = "10") -> None:
    import rospy
    from std_msgs.msg import String

    rospy.init_node("pong")
    pub = rospy.Publisher("/pong", String, queue_size=_queue_size(queue_size), tcp_nodelay=True)
    rospy.Subscriber("/ping", String, pub.publish, tcp_nodelay=True)
    rospy.spin()


def ping(count: str, queue_size: str = "10") -> None:
    import rospy
    from std_msgs.msg import String

    rospy.init_node("ping")
    got = threading.Event()
    rospy.Subscriber("/pong", String, lambda m: got.set(), tcp_nodelay=True)
    pub = rospy.Publisher("/ping", String, queue_size=_queue_size(queue_size), tcp_nodelay=True)
    _wait_connections(pub)
    msg = String("x" * 64)
    deadline = time.monotonic() + 20
    while time.monotonic() < deadline:  # the pong side must be connected back to us too
        got.clear()
        pub.publish(msg)
        if got.wait(0.2):
            break
    rtts = []
    for i in range(int(count) + 200):
        got.clear()
        t0 = time.perf_counter()
        pub.publish(msg)
        if not got.wait(2.0):
            continue
        if i >= 200:
            rtts.append(time.perf_counter() - t0)
    print(json.dumps({"p50_us": _pct(rtts, 0.5) * 1e6, "p99_us": _pct(rtts, 0.99) * 1e6, "n": len(rtts)}))
    rospy.signal_shutdown("done")


def flood(queue_size: str, seconds: str) -> None:
    import rospy
    from std_msgs.msg import String

    rospy.init_node("flood")
    qs = None if queue_size == "None" else int(queue_size)
    pub = rospy.Publisher("/flood", String, queue_size=qs, tcp_nodelay=True)
    _wait_connections(pub)
    time.sleep(0.5)
    msg = String("x" * 16)
    sent = 0
    end = time.monotonic() + float(seconds)
    while time.monotonic() < end:
        for _ in range(100):
            pub.publish(msg)
        sent += 100
    print(json.dumps({"sent": sent}), flush=True)
    time.sleep(3)
    rospy.signal_shutdown("done")


def sink() -> None:
    import rospy
    from std_msgs.msg import String

    rospy.init_node("sink")
    stamps = {"n": 0, "first": 0.0, "last": 0.0}

    def cb(msg: String) -> None:
        now = time.perf_counter()
        if not stamps["n"]:
            stamps["first"] = now
        stamps["n"] += 1
        stamps["last"] = now

    rospy.Subscriber("/flood", String, cb, queue_size=None, tcp_nodelay=True)
    print("ready", flush=True)
    while stamps["n"] == 0 or time.perf_counter() - stamps["last"] < 1.5:
        time.sleep(0.1)
    span = max(stamps["last"] - stamps["first"], 1e-9)
    print(json.dumps({"received": stamps["n"], "rate": stamps["n"] / span}), flush=True)
    rospy.signal_shutdown("done")


def _image(rospy, Image, seq: int = 0):
    data = bytes(range(256)) * (1920 * 1080 * 3 // 256)
    img = Image(height=1080, width=1920, encoding="rgb8", step=1920 * 3, data=data)
    return img


def camera(count: str) -> None:
    import rospy
    from sensor_msgs.msg import Image

    rospy.init_node("camera")
    pub = rospy.Publisher("/image", Image, queue_size=None, tcp_nodelay=True)
    _wait_connections(pub)
    time.sleep(0.5)
    img = _image(rospy, Image)
    # phase 1: one-way latency, images spaced out so none queues behind another
    for _ in range(int(count)):
        img.header.stamp = rospy.Time.from_sec(time.time())
        pub.publish(img)
        time.sleep(0.1)
    time.sleep(0.5)
    # phase 2: bandwidth, back to back (queue_size=None: synchronous, lossless)
    for _ in range(int(count)):
        img.header.stamp = rospy.Time.from_sec(0)
        pub.publish(img)
    time.sleep(3)
    rospy.signal_shutdown("done")


def viewer(count: str) -> None:
    import rospy
    from sensor_msgs.msg import Image

    rospy.init_node("viewer")
    n = int(count)
    latencies: list[float] = []
    bulk: list[tuple[float, int]] = []
    done = threading.Event()

    def cb(msg: Image) -> None:
        now = time.time()
        stamp = msg.header.stamp.to_sec()
        if stamp > 0:
            latencies.append(now - stamp)
        else:
            bulk.append((time.perf_counter(), len(msg.data)))
            if len(bulk) == n:
                done.set()

    rospy.Subscriber("/image", Image, cb, queue_size=None, buff_size=2**26, tcp_nodelay=True)
    print("ready", flush=True)
    done.wait(120)
    span = bulk[-1][0] - bulk[0][0] if len(bulk) > 1 else float("nan")
    mbps = sum(b for _, b in bulk[1:]) / span / 1e6 if len(bulk) > 1 else float("nan")
    print(json.dumps({"latency_ms": _pct(latencies, 0.5) * 1e3, "mb_per_s": mbps, "images": len(bulk)}))
    rospy.signal_shutdown("done")


def fan_pub(subscribers: str, seconds: str) -> None:
    import rospy
    from std_msgs.msg import Header

    rospy.init_node("fan_pub")
    pub = rospy.Publisher("/fan", Header, queue_size=10, tcp_nodelay=True)
    _wait_connections(pub, int(subscribers), timeout=60)
    time.sleep(0.5)
    msg = Header()
    period = 0.001
    nxt = time.perf_counter()
    end = time.monotonic() + float(seconds)
    while time.monotonic() < end:
        msg.stamp = rospy.Time.from_sec(time.time())
        pub.publish(msg)
        nxt += period
        delay = nxt - time.perf_counter()
        if delay > 0:
            time.sleep(delay)
    time.sleep(1.5)
    rospy.signal_shutdown("done")


def fan_sub(index: str) -> None:
    import rospy
    from std_msgs.msg import Header

    rospy.init_node(f"fan_sub_{index}")
    lat: list[float] = []
    last = [time.perf_counter()]

    def cb(msg: Header) -> None:
        lat.append(time.time() - msg.stamp.to_sec())
        last[0] = time.perf_counter()

    rospy.Subscriber("/fan", Header, cb, queue_size=100, tcp_nodelay=True)
    print("ready", flush=True)
    while not lat or time.perf_counter() - last[0] < 1.0:
        time.sleep(0.05)
    lat = lat[200:]  # skip the start-up
    print(json.dumps({"latencies_us": [round(x * 1e6, 1) for x in lat]}))
    rospy.signal_shutdown("done")


def trigger_server() -> None:
    import rospy
    from std_srvs.srv import Trigger, TriggerResponse

    rospy.init_node("trigger_server")
    rospy.Service("/bench_trigger", Trigger, lambda req: TriggerResponse(True, "ok"))
    print("ready", flush=True)
    rospy.spin()


def trigger_client(count: str) -> None:
    import rospy
    from std_srvs.srv import Trigger

    rospy.init_node("trigger_client")
    rospy.wait_for_service("/bench_trigger", timeout=20)
    proxy = rospy.ServiceProxy("/bench_trigger", Trigger, persistent=True)
    for _ in range(200):
        proxy()
    rtts = []
    for _ in range(int(count)):
        t0 = time.perf_counter()
        proxy()
        rtts.append(time.perf_counter() - t0)
    print(json.dumps({"p50_us": _pct(rtts, 0.5) * 1e6, "p99_us": _pct(rtts, 0.99) * 1e6}))
    rospy.signal_shutdown("done")


def init_only() -> None:
    import rospy

    rospy.init_node("init_only", anonymous=True)
    os._exit(0)  # measure start-up, not the teardown


def talker100() -> None:
    import rospy
    from std_msgs.msg import String

    rospy.init_node("talker100")
    pub = rospy.Publisher("/chatter100", String, queue_size=10)
    rate = rospy.Rate(100)
    print("ready", flush=True)
    while not rospy.is_shutdown():
        pub.publish(String("hello world %s" % time.time()))
        rate.sleep()


def _stream_msg(kind: str):
    """A 1 MB PointCloud2 (65,536 points of x, y, z, intensity) or a 640x480 rgb8 Image."""
    if kind == "cloud":
        from sensor_msgs.msg import PointCloud2, PointField

        fields = [
            PointField(n, 4 * i, PointField.FLOAT32, 1) for i, n in enumerate(("x", "y", "z", "intensity"))
        ]
        n = (1 << 20) // 16
        msg = PointCloud2(height=1, width=n, fields=fields, point_step=16, row_step=16 * n, is_dense=True)
        msg.data = bytes(range(256)) * ((1 << 20) // 256)
        return PointCloud2, msg
    from sensor_msgs.msg import Image

    data = bytes(range(256)) * (640 * 480 * 3 // 256)
    return Image, Image(height=480, width=640, encoding="rgb8", step=640 * 3, data=data)


def stream_pub(kind: str, seconds: str) -> None:
    """Publish ``kind`` back to back for ``seconds`` (queue_size=None: synchronous, full speed)."""
    import rospy

    rospy.init_node(f"stream_pub_{kind}")
    msg_class, msg = _stream_msg(kind)
    pub = rospy.Publisher(f"/stream_{kind}", msg_class, queue_size=None, tcp_nodelay=True)
    _wait_connections(pub)
    time.sleep(0.5)
    sent = 0
    t0 = time.perf_counter()
    end = time.monotonic() + float(seconds)
    while time.monotonic() < end:
        msg.header.stamp = rospy.Time.from_sec(time.time())
        pub.publish(msg)
        sent += 1
    print(json.dumps({"sent": sent, "rate": sent / (time.perf_counter() - t0)}), flush=True)
    time.sleep(2)
    rospy.signal_shutdown("done")


def stream_sub(kind: str, small: str = "0") -> None:
    """Subscribe to ``kind`` with queue_size=10; report callbacks/s and the longest gap while data
    flows. With ``small`` = 1 also subscribe to /small (100 Hz stamped Headers) in this process and
    report their one-way latency."""
    import rospy
    from std_msgs.msg import Header

    rospy.init_node(f"stream_sub_{kind}")
    msg_class, _ = _stream_msg(kind)
    stamps: list[float] = []
    small_lat: list[float] = []

    def cb(msg) -> None:
        stamps.append(time.perf_counter())

    def small_cb(msg: Header) -> None:
        small_lat.append(time.time() - msg.stamp.to_sec())

    rospy.Subscriber(f"/stream_{kind}", msg_class, cb, queue_size=10, buff_size=2**24, tcp_nodelay=True)
    if small == "1":
        rospy.Subscriber("/small", Header, small_cb, queue_size=10, tcp_nodelay=True)
    print("ready", flush=True)
    while not stamps or time.perf_counter() - stamps[-1] < 1.5:
        time.sleep(0.1)
    span = max(stamps[-1] - stamps[0], 1e-9)
    gap = max((b - a for a, b in zip(stamps, stamps[1:], strict=False)), default=float("nan"))
    result = {"received": len(stamps), "rate": (len(stamps) - 1) / span, "max_gap_ms": gap * 1e3}
    if small == "1":
        lat = small_lat[20:]
        result.update(small_n=len(lat), small_p50_ms=_pct(lat, 0.5) * 1e3, small_p99_ms=_pct(lat, 0.99) * 1e3)
        result["small_max_ms"] = max(lat) * 1e3 if lat else float("nan")
    print(json.dumps(result), flush=True)
    rospy.signal_shutdown("done")


def small_pub(seconds: str) -> None:
    """Stamped std_msgs/Header at 100 Hz on /small for ``seconds``."""
    import rospy
    from std_msgs.msg import Header

    rospy.init_node("small_pub")
    pub = rospy.Publisher("/small", Header, queue_size=10, tcp_nodelay=True)
    _wait_connections(pub)
    msg = Header()
    nxt = time.perf_counter()
    end = time.monotonic() + float(seconds)
    while time.monotonic() < end:
        msg.stamp = rospy.Time.from_sec(time.time())
        pub.publish(msg)
        nxt += 0.01
        delay = nxt - time.perf_counter()
        if delay > 0:
            time.sleep(delay)
    print(json.dumps({"done": True}), flush=True)
    time.sleep(2)
    rospy.signal_shutdown("done")


def _cpu() -> tuple[float, float]:
    t = os.times()
    return t.user, t.system


def pong_cpu(count: str) -> None:
    """``pong`` (queue_size=None) that reports its process's CPU time (user, system) per message over
    ``count`` messages after the first 1000: what one hop costs, whatever else the machine runs."""
    import rospy
    from std_msgs.msg import String

    rospy.init_node("pong")
    pub = rospy.Publisher("/pong", String, queue_size=None, tcp_nodelay=True)
    n, total, marks = [0], int(count), {}

    def cb(msg: String) -> None:
        n[0] += 1
        if n[0] == 1000:
            marks["a"] = _cpu()
        elif n[0] == 1000 + total:
            b = _cpu()
            print(json.dumps({"user_us": (b[0] - marks["a"][0]) / total * 1e6,
                              "sys_us": (b[1] - marks["a"][1]) / total * 1e6}), flush=True)  # fmt: skip
        pub.publish(msg)

    rospy.Subscriber("/ping", String, cb, tcp_nodelay=True)
    rospy.spin()


def ping_cpu(count: str) -> None:
    """``ping`` (queue_size=None) that reports its process's CPU time per round trip (1000 warm-up
    round trips, then ``count``) and the mean round trip."""
    import rospy
    from std_msgs.msg import String

    rospy.init_node("ping")
    got = threading.Event()
    rospy.Subscriber("/pong", String, lambda m: got.set(), tcp_nodelay=True)
    pub = rospy.Publisher("/ping", String, queue_size=None, tcp_nodelay=True)
    _wait_connections(pub)
    msg = String("x" * 64)
    deadline = time.monotonic() + 20
    while time.monotonic() < deadline:
        got.clear()
        pub.publish(msg)
        if got.wait(0.2):
            break
    for _ in range(998):
        got.clear()
        pub.publish(msg)
        got.wait(2.0)
    total = int(count)
    a, t0 = _cpu(), time.perf_counter()
    for _ in range(total + 2):  # the pong counts the 1000th to the (1000 + count)th
        got.clear()
        pub.publish(msg)
        got.wait(2.0)
    b, t1 = _cpu(), time.perf_counter()
    print(json.dumps({"user_us": (b[0] - a[0]) / total * 1e6, "sys_us": (b[1] - a[1]) / total * 1e6,
                      "rtt_us": (t1 - t0) / total * 1e6}), flush=True)  # fmt: skip
    time.sleep(0.5)
    rospy.signal_shutdown("done")


ROLES = {
    "pong_cpu": pong_cpu,
    "ping_cpu": ping_cpu,
    "pong": pong,
    "ping": ping,
    "flood": flood,
    "sink": sink,
    "camera": camera,
    "viewer": viewer,
    "fan_pub": fan_pub,
    "fan_sub": fan_sub,
    "trigger_server": trigger_server,
    "trigger_client": trigger_client,
    "init_only": init_only,
    "talker100": talker100,
    "stream_pub": stream_pub,
    "stream_sub": stream_sub,
    "small_pub": small_pub,
}

if __name__ == "__main__":
    ROLES[sys.argv[1]](*sys.argv[2:])
