"""CPU time per small-message round trip, ninjemys vs real rospy, queue_size=None, both placements.

Run: ``.venv/bin/python bench/node_cpu_rtt.py [count] [rounds]``. Each process of the ping-pong
reports its own CPU time (user and system, ``os.times``) over ``count`` round trips: unlike the wall
time of ``node_rtt.py`` this hardly moves with what else the shared machine runs, so it shows what a
change to the per-message path saves (issue 25: the publish path's Python calls). On one CPU the mean
round trip is about the two processes' CPU time added up: that is what a p50 ratio can be at best.
The ticks are 10 ms: keep ``count`` at 20000 or more.
"""

from __future__ import annotations

import statistics
import sys

from node_common import CROSS_CPU, IMPLS, SAME_CPU, Role, header, master, roles


def run(uri: str, impl: str, cpus: tuple[str, str], count: int) -> dict[str, float]:
    pong = Role(impl, uri, "pong_cpu", str(count), cpu=cpus[1])
    with roles(pong):
        ping = Role(impl, uri, "ping_cpu", str(count), cpu=cpus[0])
        with roles(ping):
            a, b = ping.result(), pong.result()
    return {
        "rtt": a["rtt_us"],
        "ping": a["user_us"] + a["sys_us"],
        "pong": b["user_us"] + b["sys_us"],
        "pong_user": b["user_us"],
    }


def main() -> None:
    count = int(sys.argv[1]) if len(sys.argv) > 1 else 20000
    n_rounds = int(sys.argv[2]) if len(sys.argv) > 2 else 2
    header(f"CPU per round trip, {count} round trips, {n_rounds} interleaved rounds, queue_size=None")
    with master() as uri:
        for name, cpus in (("same CPU", SAME_CPU), ("across CPUs", CROSS_CPU)):
            rounds = [{impl: run(uri, impl, cpus, count) for impl in IMPLS} for _ in range(n_rounds)]
            for impl in IMPLS:
                med = {k: statistics.median(r[impl][k] for r in rounds) for k in rounds[0][impl]}
                print(
                    f"{name:12s} {impl:9s} CPU per round trip: ping {med['ping']:5.1f} us,"
                    f" pong {med['pong']:5.1f} us (user {med['pong_user']:5.1f})   mean RTT {med['rtt']:6.1f} us"
                )
            if len(IMPLS) > 1:
                ours, real = IMPLS[0], IMPLS[1]
                r = statistics.median(
                    (x[ours]["ping"] + x[ours]["pong"]) / (x[real]["ping"] + x[real]["pong"]) for x in rounds
                )
                print(f"{name:12s} ratio     CPU per round trip (both processes) {r:.2f}x")


if __name__ == "__main__":
    main()
