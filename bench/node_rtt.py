"""Ping-pong round trip of a 64-byte std_msgs/String: ninjemys vs real rospy (and roscpp), two
placements, publishers with ``queue_size=10`` and ``queue_size=None``; plus ninjemys in one process.

Run: ``.venv/bin/python bench/node_rtt.py [count] [rounds] [--quick]`` (``--quick``: the one-CPU
``queue_size=10`` row only, with its floor, e.g. for ``bench/ab.py``); rounds interleave the implementations
(load on a shared machine then hits them alike), and the machine's floor (``floor_rtt.py``) is
measured in the same run. Targets: p50 <= 0.3x rospy on one CPU,
p99 <= rospy's and <= 150 us in every placement and queue_size mode; in-process (two Nodes of one
process, ``intraprocess=True``, subscribers ``direct=True``) p50 <= 10 us.
"""

from __future__ import annotations

import statistics
import sys
import threading
import time

import floor_rtt
from node_common import CPP, CROSS_CPU, IMPLS_CPP, OURS, SAME_CPU, Role, header, master, roles


def run(uri: str, impl: str, cpus: tuple[str, str], count: int, queue_size: str) -> dict:
    # roscpp's program has its queue of 10 built in
    args = () if impl == CPP else (queue_size,)
    with roles(Role(impl, uri, "pong", *args, cpu=cpus[1])) as (pong,):
        ping = Role(impl, uri, "ping", str(count), *args, cpu=cpus[0])
        with roles(ping):
            return ping.result()


def in_process(uri: str, count: int, direct: bool) -> dict:
    """Two Nodes of this process, both ends ``intraprocess=True``: the object is handed over. Each hop
    is one wake-up of the receiving handle's thread, or none with ``direct=True`` (the publishing
    thread calls an idle subscriber back itself, as a nodelet's publish does)."""
    from ninjemys.node import Node
    from std_msgs.msg import String

    ping_node = Node("inproc_ping", anonymous=True, master_uri=uri, rosout=False, logger_services=False)
    pong_node = Node("inproc_pong", anonymous=True, master_uri=uri, rosout=False, logger_services=False)
    try:
        back = pong_node.publisher("/inproc_pong", String, intraprocess=True)
        pong_node.subscriber("/inproc_ping", String, back.publish, intraprocess=True, direct=direct)
        got = threading.Event()
        ping_node.subscriber("/inproc_pong", String, lambda m: got.set(), intraprocess=True, direct=direct)
        pub = ping_node.publisher("/inproc_ping", String, intraprocess=True)
        msg = String("x" * 64)
        deadline = time.monotonic() + 20
        while time.monotonic() < deadline:
            got.clear()
            pub.publish(msg)
            if got.wait(0.2):
                break
        rtts = []
        for i in range(count + 200):
            got.clear()
            t0 = time.perf_counter()
            pub.publish(msg)
            if got.wait(2.0) and i >= 200:
                rtts.append(time.perf_counter() - t0)
        rtts.sort()
        return {"p50_us": rtts[len(rtts) // 2] * 1e6, "p99_us": rtts[int(len(rtts) * 0.99)] * 1e6}
    finally:
        pong_node.shutdown("bench over")
        ping_node.shutdown("bench over")


def report(label: str, rounds: list[dict[str, dict]]) -> None:
    """Median over rounds of each implementation's p50 and p99; the ratio taken within each round."""
    impls = list(rounds[0])
    for impl in impls:
        p50s = [r[impl]["p50_us"] for r in rounds]
        p99 = statistics.median(r[impl]["p99_us"] for r in rounds)
        print(
            f"{label:35s} {impl:9s} p50 {statistics.median(p50s):8.1f} us"
            f" (spread {min(p50s):6.1f}-{max(p50s):6.1f})   p99 {p99:8.1f} us"
        )
    if "rospy" in impls:
        r50 = [r[OURS]["p50_us"] / r["rospy"]["p50_us"] for r in rounds]
        r99 = [r[OURS]["p99_us"] / r["rospy"]["p99_us"] for r in rounds]
        print(
            f"{label:35s} ratio     p50 {statistics.median(r50):.2f}x (rounds {min(r50):.2f}-{max(r50):.2f})"
            f"   p99 {statistics.median(r99):.2f}x (rounds {min(r99):.2f}-{max(r99):.2f})"
        )


def main() -> None:
    args = [a for a in sys.argv[1:] if a != "--quick"]
    # --quick: only the target's row (one CPU, queue_size=10) and its floor, for A/B runs (bench/ab.py)
    quick = len(args) < len(sys.argv) - 1
    count = int(args[0]) if args else 5000
    n_rounds = int(args[1]) if len(args) > 1 else 3
    header(f"ping-pong RTT, {count} round trips, {n_rounds} interleaved rounds")
    placements = (("same CPU", SAME_CPU),) if quick else (("same CPU", SAME_CPU), ("across CPUs", CROSS_CPU))
    for name, cpus in placements:
        # the machine's floor in the same run: a bare Python ping-pong, and the ping role's shape
        # (a receiving thread that wakes the main thread with an Event), over a Unix socket
        for shape in ("bare", "thread+event"):
            p50, p99 = floor_rtt.run(shape, cpus, count)
            print(f"{'floor ' + shape + ', ' + name:35s} {'python':9s} p50 {p50:8.1f} us   p99 {p99:8.1f} us")
    with master() as uri:
        for queue_size in ("10",) if quick else ("10", "None"):
            for name, cpus in (
                ("same CPU (taskset -c 0)", SAME_CPU),
                ("across CPUs (-c 0 / -c 1)", CROSS_CPU),
            )[: 1 if quick else 2]:
                label = f"{name} q={queue_size}"
                impls = [i for i in IMPLS_CPP if i != CPP or queue_size == "10"]
                rounds = [
                    {impl: run(uri, impl, cpus, count, queue_size) for impl in impls} for _ in range(n_rounds)
                ]
                report(label, rounds)
        for direct in () if quick else (False, True):
            r = in_process(uri, count, direct)
            label = "in one process, direct=True" if direct else "in one process (intraprocess=True)"
            print(f"{label:35s} {OURS:9s} p50 {r['p50_us']:8.1f} us   p99 {r['p99_us']:8.1f} us")


if __name__ == "__main__":
    main()
