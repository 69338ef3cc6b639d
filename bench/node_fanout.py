"""Fan-out 1 -> 10 subscriber processes of std_msgs/Header at 1 kHz: latency p50/p99 over all.

Run: ``.venv/bin/python bench/node_fanout.py [seconds]``. Latency is the receive wall time minus the
stamp set just before publish. Target: p99 <= 0.5 ms.
"""

from __future__ import annotations

import sys

from node_common import IMPLS, OURS, Role, header, master, ratio, roles

SUBSCRIBERS = 10


def _pct(values: list[float], q: float) -> float:
    values = sorted(values)
    return values[min(len(values) - 1, int(q * len(values)))] if values else float("nan")


def run(uri: str, impl: str, seconds: str) -> tuple[float, float, int]:
    subs = [Role(impl, uri, "fan_sub", str(i)) for i in range(SUBSCRIBERS)]
    with roles(*subs):
        for sub in subs:
            sub.ready()
        with roles(Role(impl, uri, "fan_pub", str(SUBSCRIBERS), seconds)):
            lat = [x for sub in subs for x in sub.result(timeout=120)["latencies_us"]]
    return _pct(lat, 0.5), _pct(lat, 0.99), len(lat)


def main() -> None:
    seconds = sys.argv[1] if len(sys.argv) > 1 else "3"
    header(f"fan-out 1 -> {SUBSCRIBERS} at 1 kHz for {seconds} s")
    with master() as uri:
        results = {impl: run(uri, impl, seconds) for impl in IMPLS}
    for impl, (p50, p99, n) in results.items():
        print(f"{impl:9s} p50 {p50:8.1f} us   p99 {p99:8.1f} us   ({n} deliveries)")
    if len(results) > 1:
        print(
            f"ratio     p50 {ratio(results[OURS][0], results['rospy'][0])}   p99 {ratio(results[OURS][1], results['rospy'][1])}"
        )


if __name__ == "__main__":
    main()
