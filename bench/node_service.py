"""Persistent std_srvs/Trigger service round trip, ninjemys vs rospy (and roscpp), two placements.

Run: ``.venv/bin/python bench/node_service.py [count] [rounds]``. Target: p50 <= 0.6x rospy.

Each round runs a fresh server and client of every implementation, one implementation after the
other, and rounds repeat. On a shared machine load comes and goes within seconds; interleaving makes
it hit every implementation alike instead of whichever happened to run during it. Printed per
implementation: the median over rounds of each run's p50 and p99, and the spread (lowest-highest
p50); the ratio is taken within each round (ours / rospy, same minute) and its median and range shown.
"""

from __future__ import annotations

import statistics
import sys

from node_common import CROSS_CPU, IMPLS_CPP, OURS, REAL, SAME_CPU, Role, header, master, roles


def run_once(uri: str, impl: str, cpus: tuple[str, str], count: str) -> dict:
    server = Role(impl, uri, "trigger_server", cpu=cpus[1])
    with roles(server):
        server.ready()
        client = Role(impl, uri, "trigger_client", count, cpu=cpus[0])
        with roles(client):
            return client.result()


def run(uri: str, impl: str, cpus: tuple[str, str], count: str) -> dict:
    """One measured pair; a run whose client gives no result (on a loaded machine a client can look
    the service up before the fresh server's registration replaced the killed one's) runs again once."""
    try:
        return run_once(uri, impl, cpus, count)
    except RuntimeError as exc:
        print(f"  ({impl}: {exc}; running it again)", file=sys.stderr)
        return run_once(uri, impl, cpus, count)


def report(name: str, rounds: list[dict[str, dict]]) -> None:
    for impl in IMPLS_CPP:
        p50s = [r[impl]["p50_us"] for r in rounds]
        p99 = statistics.median(r[impl]["p99_us"] for r in rounds)
        print(
            f"{name:12s} {impl:9s} p50 {statistics.median(p50s):7.1f} us"
            f" (spread {min(p50s):5.1f}-{max(p50s):5.1f})   p99 {p99:8.1f} us"
        )
    if REAL in IMPLS_CPP:
        ratios = [r[OURS]["p50_us"] / r[REAL]["p50_us"] for r in rounds]
        print(
            f"{name:12s} ratio     p50 {statistics.median(ratios):.2f}x"
            f" (rounds {min(ratios):.2f}-{max(ratios):.2f}x, {len(ratios)} rounds)"
        )


def main() -> None:
    count = sys.argv[1] if len(sys.argv) > 1 else "5000"
    n_rounds = int(sys.argv[2]) if len(sys.argv) > 2 else 3
    header(f"persistent Trigger service RTT, {count} calls, {n_rounds} interleaved rounds")
    with master() as uri:
        for name, cpus in (("same CPU", SAME_CPU), ("across CPUs", CROSS_CPU)):
            rounds = [{impl: run(uri, impl, cpus, count) for impl in IMPLS_CPP} for _ in range(n_rounds)]
            report(name, rounds)


if __name__ == "__main__":
    main()
