"""The worker's shorter scheduler slice (``ninjemys.node.slices``) on and off, in one run: the ping-pong of
``node_rtt.py`` (ours, ``queue_size=10``), rounds alternating ``NINJEMYS_WORKER_SLICE=0`` and the
default, each with its RTT p50 / p99 and what both processes spent per round trip: context switches
(voluntary + involuntary) and CPU time (both processes' whole lives, start-up included: compare the
sides, not the absolute figure). The counts hold on a loaded machine where the latencies do
not: they are the evidence, the latencies the effect.

Run: ``.venv/bin/python bench/node_rtt_slices.py [count] [rounds] [--across]`` (one CPU unless
``--across``).
"""

from __future__ import annotations

import os
import resource
import statistics
import sys

from node_common import CROSS_CPU, OURS, SAME_CPU, Role, header, master, roles


def one(uri: str, cpus: tuple[str, str], count: int) -> dict[str, float]:
    """One ping-pong; both role processes are waited for inside, so the children's usage is theirs."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    with roles(Role(OURS, uri, "pong", "10", cpu=cpus[1])):
        ping = Role(OURS, uri, "ping", str(count), "10", cpu=cpus[0])
        with roles(ping):
            got = ping.result()
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    trips = count + 200  # the ping's warm-up round trips count too
    switches = (after.ru_nvcsw + after.ru_nivcsw) - (before.ru_nvcsw + before.ru_nivcsw)
    cpu = (after.ru_utime + after.ru_stime) - (before.ru_utime + before.ru_stime)
    return {
        "p50": got["p50_us"],
        "p99": got["p99_us"],
        "switches": switches / trips,
        "involuntary": (after.ru_nivcsw - before.ru_nivcsw) / trips,
        "cpu": cpu / trips * 1e6,
    }


def main() -> None:
    args = [a for a in sys.argv[1:] if a != "--across"]
    across = len(args) < len(sys.argv) - 1
    count = int(args[0]) if args else 5000
    n_rounds = int(args[1]) if len(args) > 1 else 3
    cpus = CROSS_CPU if across else SAME_CPU
    place = "across CPUs" if across else "one CPU"
    header(f"worker slice off/on, ping-pong {place}, {count} round trips, {n_rounds} alternating rounds")
    results: dict[str, list[dict[str, float]]] = {"off": [], "on": []}
    with master() as uri:
        for n in range(n_rounds):
            for side in ("off", "on") if n % 2 == 0 else ("on", "off"):
                os.environ["NINJEMYS_WORKER_SLICE"] = "0" if side == "off" else "1"
                r = one(uri, cpus, count)
                results[side].append(r)
                print(
                    f"round {n + 1} slice {side:3s} p50 {r['p50']:6.1f} us  p99 {r['p99']:7.1f} us"
                    f"  per round trip: {r['switches']:.2f} context switches ({r['involuntary']:.2f}"
                    f" involuntary), CPU {r['cpu']:5.1f} us  (load {os.getloadavg()[0]:.1f})",
                    flush=True,
                )
    os.environ.pop("NINJEMYS_WORKER_SLICE", None)
    for side, rows in results.items():
        med = {k: statistics.median(r[k] for r in rows) for k in rows[0]}
        print(
            f"median slice {side:3s} p50 {med['p50']:6.1f} us  p99 {med['p99']:7.1f} us  per round trip:"
            f" {med['switches']:.2f} context switches, CPU {med['cpu']:5.1f} us"
        )


if __name__ == "__main__":
    main()
