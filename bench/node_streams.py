"""Sustained streams of mid-size messages: ninjemys vs real rospy, one process per CPU.

Run: ``.venv/bin/python bench/node_streams.py [seconds]``.

* 1 MB sensor_msgs/PointCloud2 and 640x480 rgb8 sensor_msgs/Image, published back to back
  (``queue_size=None``) to a subscriber with ``queue_size=10``: callbacks per second and the longest
  gap between two callbacks while the stream runs. Target: >= 2x rospy for both.
* The image stream and a 100 Hz std_msgs/Header subscription in one subscriber process: one-way
  latency of the small messages (publish stamp to callback). Target: a few ms at most.
* 64-byte ping-pong RTT with ``queue_size=None`` publishers, across CPUs. Target: p99 <= rospy's.
"""

from __future__ import annotations

import sys

from node_common import CROSS_CPU, IMPLS, OURS, Role, header, master, ratio, roles


def stream(uri: str, impl: str, kind: str, seconds: str, small: bool = False) -> dict:
    sub = Role(impl, uri, "stream_sub", kind, "1" if small else "0", cpu=CROSS_CPU[1])
    with roles(sub):
        sub.ready()
        pubs = [Role(impl, uri, "stream_pub", kind, seconds, cpu=CROSS_CPU[0])]
        if small:
            pubs.append(Role(impl, uri, "small_pub", seconds, cpu=CROSS_CPU[0]))
        with roles(*pubs):
            sent = pubs[0].result(timeout=60 + float(seconds))
            got = sub.result(timeout=60)
    got["sent_rate"] = sent["rate"]
    return got


def rtt(uri: str, impl: str, count: str) -> dict:
    with roles(Role(impl, uri, "pong", "None", cpu=CROSS_CPU[1])):
        ping = Role(impl, uri, "ping", count, "None", cpu=CROSS_CPU[0])
        with roles(ping):
            return ping.result()


def main() -> None:
    seconds = sys.argv[1] if len(sys.argv) > 1 else "4"
    header(
        f"sustained streams, {seconds} s each, publisher queue_size=None, subscriber queue_size=10, across CPUs"
    )
    with master() as uri:
        for kind, title in (("cloud", "PointCloud2 1 MB"), ("image", "Image 640x480 rgb8")):
            results = {impl: stream(uri, impl, kind, seconds) for impl in IMPLS}
            for impl, r in results.items():
                print(
                    f"{title:20s} {impl:9s} {r['rate']:7.1f} msgs/s delivered (published {r['sent_rate']:7.1f}/s)"
                    f"   longest gap {r['max_gap_ms']:7.1f} ms"
                )
            if len(results) > 1:
                print(f"{title:20s} ratio     {ratio(results[OURS]['rate'], results['rospy']['rate'])}")
        results = {impl: stream(uri, impl, "image", seconds, small=True) for impl in IMPLS}
        for impl, r in results.items():
            print(
                f"{'image + 100 Hz small':20s} {impl:9s} image {r['rate']:7.1f} msgs/s   small one-way p50 "
                f"{r['small_p50_ms']:6.2f} ms  p99 {r['small_p99_ms']:6.2f} ms  max {r['small_max_ms']:6.2f} ms"
                f"  ({r['small_n']} msgs)"
            )
        results = {impl: rtt(uri, impl, "3000") for impl in IMPLS}
        for impl, r in results.items():
            print(
                f"{'RTT, queue_size=None':20s} {impl:9s} p50 {r['p50_us']:8.1f} us   p99 {r['p99_us']:8.1f} us"
            )
        if len(results) > 1:
            o, t = results[OURS], results["rospy"]
            print(
                f"{'RTT, queue_size=None':20s} ratio     p50 {ratio(o['p50_us'], t['p50_us'])}   p99 {ratio(o['p99_us'], t['p99_us'])}"
            )


if __name__ == "__main__":
    main()
