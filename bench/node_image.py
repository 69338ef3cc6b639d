"""1920x1080 rgb8 sensor_msgs/Image (6.2 MB): one-way latency and bandwidth, ninjemys vs rospy.

Run: ``.venv/bin/python bench/node_image.py [count]``. Latency: images 100 ms apart, stamped at
publish and compared with the wall clock on receipt (same machine). Bandwidth: back-to-back
publishing with queue_size=None. Targets: one-way <= 4 ms, bandwidth >= 2x rospy.
"""

from __future__ import annotations

import sys

from node_common import CROSS_CPU, IMPLS, OURS, Role, header, master, ratio, roles


def run(uri: str, impl: str, count: str) -> dict:
    viewer = Role(impl, uri, "viewer", count, cpu=CROSS_CPU[1])
    with roles(viewer):
        viewer.ready()
        with roles(Role(impl, uri, "camera", count, cpu=CROSS_CPU[0])):
            return viewer.result(timeout=300)


def main() -> None:
    count = sys.argv[1] if len(sys.argv) > 1 else "30"
    header(f"1920x1080 rgb8 images, {count} for latency + {count} back to back, across CPUs")
    with master() as uri:
        results = {impl: run(uri, impl, count) for impl in IMPLS}
    for impl, r in results.items():
        print(f"{impl:9s} one-way p50 {r['latency_ms']:7.2f} ms   bandwidth {r['mb_per_s']:8.1f} MB/s")
    if len(results) > 1:
        o, t = results[OURS], results["rospy"]
        print(
            f"ratio     one-way {ratio(o['latency_ms'], t['latency_ms'])}   bandwidth {ratio(o['mb_per_s'], t['mb_per_s'])}"
        )


if __name__ == "__main__":
    main()
