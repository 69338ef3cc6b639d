"""Ping-pong round trip of a 64-byte std_msgs/String: ninjemys vs real rospy, two placements.

Run: ``.venv/bin/python bench/node_rtt.py [count]``. Targets: p50 <= 0.5x rospy on one CPU,
<= 0.8x across CPUs, p99 <= 150 us.
"""

from __future__ import annotations

import sys

from node_common import CROSS_CPU, IMPLS_CPP, OURS, SAME_CPU, Role, header, master, ratio, roles


def run(uri: str, impl: str, cpus: tuple[str, str], count: int) -> dict:
    with roles(Role(impl, uri, "pong", cpu=cpus[1])) as (pong,):
        ping = Role(impl, uri, "ping", str(count), cpu=cpus[0])
        with roles(ping):
            return ping.result()


def main() -> None:
    count = int(sys.argv[1]) if len(sys.argv) > 1 else 5000
    header(f"ping-pong RTT, {count} round trips")
    with master() as uri:
        for name, cpus in (("same CPU (taskset -c 0)", SAME_CPU), ("across CPUs (-c 0 / -c 1)", CROSS_CPU)):
            results = {impl: run(uri, impl, cpus, count) for impl in IMPLS_CPP}
            for impl, r in results.items():
                print(f"{name:28s} {impl:9s} p50 {r['p50_us']:8.1f} us   p99 {r['p99_us']:8.1f} us")
            if "rospy" in results:
                o, t = results[OURS], results["rospy"]
                print(
                    f"{name:28s} ratio     p50 {ratio(o['p50_us'], t['p50_us'])}   p99 {ratio(o['p99_us'], t['p99_us'])}"
                )


if __name__ == "__main__":
    main()
