"""``Buffer.lookup_transform`` latency: ninjemys's tf2_ros vs Debian's tf2_ros (C++ core), same workload.

Run: ``.venv/bin/python bench/tf2_lookup.py`` (``--quick`` for fewer lookups).

Both run this file as a worker (``--worker``): ours under the venv's interpreter, Debian's under
/usr/bin/python3 with ROS 1's environment; each builds the same 100-frame random tree (fixed seed,
every link with 10 stamps 0.1 s apart, plus 10 static links) and times single ``lookup_transform``
calls between random frame pairs with ``time.perf_counter``; figures are medians (p50) and p90 in
microseconds. Scenarios:

- latest: ``rospy.Time(0)``, the buffer unchanged between lookups (a node between two /tf messages);
- latest+updates: the same, with a new stamp inserted on every link after each 100 lookups (/tf at
  100 Hz under ~10k lookups a second: our per-frame memo is invalidated that often);
- interpolated: a random time between two stamps for every call (our per-time memo never hits). Every
  link rotates about z only (a mobile robot's links mostly do): ours composes such "planar" links as
  complex numbers, and from the second lookup of a frame's side within one segment (two stamps) on,
  from a per-side composite (see docs/tf2.md);
- interpolated, 3D: the same with every link rotating about a tilted axis: the general path, a
  quaternion product per link.

The machine is shared: the load average is printed with the figures.
"""

from __future__ import annotations

import json
import os
import random
import subprocess
import sys
import time

FRAMES = 100
STATIC = 10
STAMPS = 10


def worker(n: int) -> dict[str, float]:
    import math

    import rospy
    import tf2_ros
    from geometry_msgs.msg import TransformStamped

    rnd = random.Random(42)
    names = [f"frame_{i}" for i in range(FRAMES)]
    parents = {names[i]: names[rnd.randrange(i)] for i in range(1, FRAMES)}
    links = {}
    for child, parent in parents.items():
        yaw = rnd.uniform(-3, 3)
        links[child] = (parent, rnd.uniform(-2, 2), rnd.uniform(-2, 2), rnd.uniform(-1, 1), yaw)
    buf = tf2_ros.Buffer(debug=False)
    tilted = tf2_ros.Buffer(debug=False)  # the same tree, rotating about a tilted axis
    axis = (0.36, -0.48, 0.8)  # unit length

    def insert(stamp: float, into=buf, about=(0.0, 0.0, 1.0)) -> None:
        for child, (parent, x, y, z, yaw) in links.items():
            if child in static:
                continue
            m = TransformStamped()
            m.header.frame_id, m.child_frame_id = parent, child
            m.header.stamp = rospy.Time.from_sec(stamp)
            m.transform.translation.x, m.transform.translation.y, m.transform.translation.z = (
                x,
                y,
                z + stamp * 0.01,
            )
            r, half = m.transform.rotation, yaw / 2 + stamp
            r.x, r.y, r.z, r.w = (
                about[0] * math.sin(half),
                about[1] * math.sin(half),
                about[2] * math.sin(half),
                math.cos(half),
            )
            into.set_transform(m, "bench")

    static = set(rnd.sample(sorted(links), STATIC))
    for child in static:
        parent, x, y, z, yaw = links[child]
        m = TransformStamped()
        m.header.frame_id, m.child_frame_id = parent, child
        m.transform.translation.x, m.transform.rotation.w = x, 1.0
        buf.set_transform_static(m, "bench")
        tilted.set_transform_static(m, "bench")
    stamp = 100.0
    for _ in range(STAMPS):
        insert(stamp)
        insert(stamp, tilted, axis)
        stamp += 0.1
    pairs = [(rnd.choice(names), rnd.choice(names)) for _ in range(n)]
    latest = rospy.Time(0)
    clock = time.perf_counter
    lookup = buf.lookup_transform
    results: dict[str, float] = {}

    def stats(name: str, samples: list[float]) -> None:
        samples.sort()
        results[name + "_p50"] = samples[len(samples) // 2] * 1e6
        results[name + "_p90"] = samples[len(samples) * 9 // 10] * 1e6

    for target, source in pairs[:1000]:  # warm up
        lookup(target, source, latest)
    samples = []
    for target, source in pairs:
        t0 = clock()
        lookup(target, source, latest)
        samples.append(clock() - t0)
    stats("latest", samples)

    samples = []
    for i, (target, source) in enumerate(pairs):
        if i % 100 == 99:
            insert(stamp)
            stamp += 0.1
        t0 = clock()
        lookup(target, source, latest)
        samples.append(clock() - t0)
    stats("updates", samples)

    newest = stamp - 0.1
    times = [rospy.Time.from_sec(newest - rnd.uniform(0.05, 0.85)) for _ in range(n)]
    samples = []
    for (target, source), t in zip(pairs, times, strict=True):
        t0 = clock()
        lookup(target, source, t)
        samples.append(clock() - t0)
    stats("interp", samples)

    times = [rospy.Time.from_sec(100.0 + (STAMPS - 1) * 0.1 - rnd.uniform(0.05, 0.85)) for _ in range(n)]
    lookup = tilted.lookup_transform
    for target, source in pairs[:1000]:  # warm up
        lookup(target, source, latest)
    samples = []
    for (target, source), t in zip(pairs, times, strict=True):
        t0 = clock()
        lookup(target, source, t)
        samples.append(clock() - t0)
    stats("interp3d", samples)
    return results


def run(cmd: list[str], env: dict[str, str]) -> dict[str, float]:
    done = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=600)
    if done.returncode != 0:
        raise SystemExit(f"{cmd[0]} failed:\n{done.stderr}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def main() -> int:
    n = 5_000 if "--quick" in sys.argv else 20_000
    if "--worker" in sys.argv:
        print(json.dumps(worker(n)))
        return 0
    here = os.path.abspath(__file__)
    args = ["--worker"] + (["--quick"] if "--quick" in sys.argv else [])
    ours = run([sys.executable, here, *args], dict(os.environ))
    ros1_env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV", "PYTHONHOME")}
    ros1_env["PATH"] = "/usr/bin:/bin"
    ros1 = run(["/usr/bin/python3", here, *args], ros1_env)
    print(f"tf2_ros Buffer.lookup_transform, {FRAMES}-frame tree, {n} random pairs (µs per call)")
    print(f"load average: {os.getloadavg()[0]:.2f} (2 cores, shared)")
    print(
        f"{'scenario':<18}{'ninjemys p50':>14}{'ROS 1 p50':>12}{'ratio':>8}{'ninjemys p90':>15}{'ROS 1 p90':>12}"
    )
    for key, label in (
        ("latest", "latest"),
        ("updates", "latest+updates"),
        ("interp", "interpolated"),
        ("interp3d", "interpolated, 3D"),
    ):
        a, b = ours[key + "_p50"], ros1[key + "_p50"]
        print(
            f"{label:<18}{a:>14.2f}{b:>12.2f}{a / b:>8.2f}{ours[key + '_p90']:>15.2f}{ros1[key + '_p90']:>12.2f}"
        )
    print("ratio = ninjemys / ROS 1 (lower is better; the target is <= 0.5 at p50)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
