"""Small-message throughput (std_msgs/String, 16 bytes) from one publisher to one subscriber.

Run: ``.venv/bin/python bench/node_throughput.py [seconds]``, across two CPUs and on one. The
publisher publishes as fast as it can for a few seconds; the subscriber reports how many messages it received per second while data
was flowing, and the loss. Targets: >= 500k msgs/s with no loss at queue_size=10000 (issue 25),
>= 400k msgs/s with queue_size=None (lossless).
"""

from __future__ import annotations

import sys

from node_common import CROSS_CPU, IMPLS, OURS, SAME_CPU, Role, header, master, ratio, roles


def run(
    uri: str, impl: str, queue_size: str, seconds: str, cpus: tuple[str, str]
) -> tuple[float, float, float]:
    """Delivered rate, loss, and the publisher's own rate (what it published per second: a publisher
    slower than the target cannot be made up for by the subscriber)."""
    sink = Role(impl, uri, "sink", cpu=cpus[1])
    with roles(sink):
        sink.ready()
        flood = Role(impl, uri, "flood", queue_size, seconds, cpu=cpus[0])
        with roles(flood):
            sent = flood.result()["sent"]
            got = sink.result()
    return got["rate"], 1.0 - got["received"] / max(sent, 1), sent / float(seconds)


def main() -> None:
    seconds = sys.argv[1] if len(sys.argv) > 1 else "3"
    header(f"throughput, 16-byte String, {seconds} s of publishing, both placements")
    with master() as uri:
        for place, cpus in (("across CPUs", CROSS_CPU), ("same CPU", SAME_CPU)):
            for qs in ("10000", "None"):
                results = {impl: run(uri, impl, qs, seconds, cpus) for impl in IMPLS}
                label = f"{place:11s} queue_size={qs:6s}"
                for impl, (rate, loss, published) in results.items():
                    print(
                        f"{label} {impl:9s} {rate / 1e3:8.1f} k msgs/s delivered   loss {loss * 100:5.1f} %"
                        f"   (published {published / 1e3:6.1f} k/s)"
                    )
                if len(results) > 1:
                    print(f"{label} ratio     {ratio(results[OURS][0], results['rospy'][0])}")


if __name__ == "__main__":
    main()
