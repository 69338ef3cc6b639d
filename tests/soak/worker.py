"""One soak process: the nodes a JSON spec names, all in this process, publishing, subscribing,
serving and calling under a steady load until SIGTERM.

    python worker.py SPEC.json

The spec is ``{"rate": HZ, "nodes": [{"name", "pub": [[topic, type]], "sub": [[topic, type]],
"srv": [name], "call": [name]}]}``. Every message carries this process's pid (the publisher's
incarnation) and a per-topic sequence number, so the soak can tell from a bag which messages of
which incarnation it holds and whether any went missing in the middle of a stream. The process
prints ``ready NAME URI`` per node, ``up`` when all are started, and ``stats ...`` every 2 s.
"""

from __future__ import annotations

import json
import os
import signal
import sys
import threading
import time
from typing import Any

from ninjemys.errors import NinjemysError
from ninjemys.idl.loader import get_message_class, get_service_class
from ninjemys.node import Node

PID = os.getpid()


def make_message(type_name: str, seq: int) -> Any:
    """A message of one of the soak's three types, carrying (pid, seq)."""
    cls = get_message_class(type_name)
    msg = cls()
    if type_name == "std_msgs/String":
        msg.data = f"{PID} {seq} " + "x" * 200
    elif type_name == "geometry_msgs/Twist":
        msg.linear.x, msg.linear.y, msg.angular.z = float(PID), float(seq), 0.5
    elif type_name == "sensor_msgs/LaserScan":
        msg.header.frame_id = f"{PID} {seq}"
        msg.angle_increment, msg.range_max = 0.0175, 10.0
        msg.ranges = [1.0 + (seq % 7) * 0.1] * 360
    else:
        raise NinjemysError(f"soak worker: no message recipe for {type_name}")
    return msg


def identity(type_name: str, msg: Any) -> tuple[int, int]:
    """(pid, seq) of a soak message (also used by the soak to read its bag)."""
    if type_name == "std_msgs/String":
        pid, seq = msg.data.split()[:2]
        return int(pid), int(seq)
    if type_name == "geometry_msgs/Twist":
        return int(msg.linear.x), int(msg.linear.y)
    pid, seq = msg.header.frame_id.split()
    return int(pid), int(seq)


class Counters:
    def __init__(self) -> None:
        self.lock = threading.Lock()
        self.received = 0
        self.published = 0
        self.calls_ok = 0
        self.calls_failed = 0


def _trace_memory(stop: threading.Event) -> None:
    """Diagnosis (``soak.py --trace-memory``): snapshot Python's allocations 20 s after start; on
    SIGUSR1 print the 15 lines of code whose allocations grew most since (lines ``TM ...``)."""
    import tracemalloc

    tracemalloc.start(5)
    first: list[Any] = []

    def take() -> None:
        if not stop.wait(20.0):
            first.append(tracemalloc.take_snapshot())

    def dump(*_: object) -> None:
        import gc

        from ninjemys.node.subscriber import SubConnection

        conns = [o for o in gc.get_objects() if isinstance(o, SubConnection)]
        closed = [c for c in conns if c.closed]
        print(f"TM SubConnection objects: {len(conns)}, closed {len(closed)}", flush=True)
        for c in closed[:3]:
            for ref in gc.get_referrers(c):
                if ref is not conns and ref is not closed:
                    print(
                        f"TM   closed {c.sub.topic} held by {type(ref).__name__} {str(ref)[:160]}", flush=True
                    )
        if first:
            for stat in tracemalloc.take_snapshot().compare_to(first[0], "traceback")[:15]:
                print(f"TM {stat.size_diff / 1024:+.1f} KiB {stat.count_diff:+d} blocks", flush=True)
                for frame in stat.traceback.format()[-6:]:
                    print(f"TM    {frame.strip()}", flush=True)

    threading.Thread(target=take, daemon=True).start()
    signal.signal(signal.SIGUSR1, dump)


def main() -> None:
    spec = json.loads(open(sys.argv[1]).read())
    period = 1.0 / float(spec["rate"])
    stop = threading.Event()
    for sig in (signal.SIGTERM, signal.SIGINT):
        signal.signal(sig, lambda *_: stop.set())
    counters = Counters()
    trigger = get_service_class("std_srvs/Trigger")

    def on_message(_msg: Any) -> None:
        with counters.lock:
            counters.received += 1

    nodes: list[Node] = []
    pubs: list[tuple[Any, str]] = []
    proxies: list[Any] = []
    for entry in spec["nodes"]:
        node = Node(entry["name"], rosout=False, logger_services=False)
        nodes.append(node)
        for topic, type_name in entry["pub"]:
            pubs.append((node.publisher(topic, get_message_class(type_name), queue_size=200), type_name))
        for topic, type_name in entry["sub"]:
            node.subscriber(topic, get_message_class(type_name), on_message)
        for name in entry["srv"]:
            served = [0]

            def handle(_req: Any, served: list[int] = served, who: str = node.name) -> Any:
                served[0] += 1
                return trigger._response_class(success=True, message=f"{who} {PID} {served[0]}")

            node.service(name, trigger, handle)
        for name in entry["call"]:
            proxies.append(node.service_proxy(name, trigger))
        print(f"ready {node.name} {node.uri}", flush=True)
    print("up", flush=True)
    if os.environ.get("SOAK_TRACE_MEMORY"):
        _trace_memory(stop)

    def call_loop() -> None:
        while not stop.wait(0.5):
            for proxy in proxies:
                try:
                    ok = proxy().success
                except NinjemysError:
                    ok = False
                with counters.lock:
                    if ok:
                        counters.calls_ok += 1
                    else:
                        counters.calls_failed += 1

    caller = threading.Thread(target=call_loop, name="soak calls", daemon=True)
    caller.start()
    seq = 0
    next_tick = time.monotonic()
    last_stats = next_tick
    while not stop.is_set():
        for pub, type_name in pubs:
            pub.publish(make_message(type_name, seq))
        seq += 1
        with counters.lock:
            counters.published += len(pubs)
        now = time.monotonic()
        if now - last_stats >= 2.0:
            last_stats = now
            with counters.lock:
                print(
                    f"stats seq={seq} published={counters.published} received={counters.received} "
                    f"calls_ok={counters.calls_ok} calls_failed={counters.calls_failed}",
                    flush=True,
                )
        next_tick += period
        stop.wait(max(0.0, next_tick - time.monotonic()))
    caller.join(5.0)
    for node in nodes:
        node.shutdown("soak over")
    print(f"done seq={seq}", flush=True)


if __name__ == "__main__":
    main()
