"""Persistent std_srvs/Trigger service round trip, ninjemys vs rospy, two placements.

Run: ``.venv/bin/python bench/node_service.py [count]``. Target: <= 0.6x rospy.
"""

from __future__ import annotations

import sys

from node_common import CROSS_CPU, IMPLS_CPP, OURS, SAME_CPU, Role, header, master, ratio, roles


def run(uri: str, impl: str, cpus: tuple[str, str], count: str) -> dict:
    server = Role(impl, uri, "trigger_server", cpu=cpus[1])
    with roles(server):
        server.ready()
        client = Role(impl, uri, "trigger_client", count, cpu=cpus[0])
        with roles(client):
            return client.result()


def main() -> None:
    count = sys.argv[1] if len(sys.argv) > 1 else "3000"
    header(f"persistent Trigger service RTT, {count} calls")
    with master() as uri:
        for name, cpus in (("same CPU", SAME_CPU), ("across CPUs", CROSS_CPU)):
            results = {impl: run(uri, impl, cpus, count) for impl in IMPLS_CPP}
            for impl, r in results.items():
                print(f"{name:12s} {impl:9s} p50 {r['p50_us']:8.1f} us   p99 {r['p99_us']:8.1f} us")
            if "rospy" in results:
                o, t = results[OURS], results["rospy"]
                print(
                    f"{name:12s} ratio     p50 {ratio(o['p50_us'], t['p50_us'])}   p99 {ratio(o['p99_us'], t['p99_us'])}"
                )


if __name__ == "__main__":
    main()
