"""``Buffer.lookup_transform`` latency: ninjemys's tf2_ros vs Debian's tf2_ros (C++ core), same workload.

Run: ``.venv/bin/python bench/tf2_lookup.py`` (``--quick`` for fewer lookups).

Both run this file as a worker (``--worker SHAPE``): ours under the venv's interpreter, Debian's under
/usr/bin/python3 with ROS 1's environment. Each builds the same 100-frame tree (fixed seed, every
dynamic link with 10 stamps 0.1 s apart) and times single ``lookup_transform`` calls with
``time.perf_counter``; figures are medians (p50) and p90 in microseconds. Two shapes:

- random: each frame's parent is a random earlier frame (depth ~5, as a robot's tree is shallow),
  10 of the links static, lookups between random frame pairs;
- chain: frame_i's parent is frame_(i-1) (depth 99), lookups between random pairs and, as a separate
  row, from the deepest frame to the root.

Scenarios:

- latest: ``rospy.Time(0)``, the buffer unchanged between lookups (a node between two /tf messages);
- stamp: one past stamp for every call (a node transforming a batch of data stamped alike);
- updates: latest, with a new stamp on every link after each 100 lookups (/tf at 100 Hz under ~10k
  lookups a second);
- stream: latest, with a new stamp on every link before every lookup (a node that looks up once per
  /tf message: no cache of ours can help, each lookup composes its links afresh);
- interpolated: a random time between two stamps for every call. Links rotate about z only (a mobile
  robot's links mostly do): ours composes such "planar" links as complex numbers (see docs/tf2.md);
- interpolated, 3D: the random tree with every link rotating about a tilted axis: the general path.

The machine is shared: the load average is printed with the figures.
"""

from __future__ import annotations

import json
import math
import os
import random
import subprocess
import sys
import time

FRAMES = 100
STATIC = 10
STAMPS = 10
TILTED = (0.36, -0.48, 0.8)  # a unit rotation axis for the 3D case


def worker(shape: str, n: int) -> dict[str, float]:
    import rospy
    import tf2_ros
    from geometry_msgs.msg import TransformStamped

    rnd = random.Random(42)
    names = [f"frame_{i}" for i in range(FRAMES)]
    if shape == "chain":
        parents = {names[i]: names[i - 1] for i in range(1, FRAMES)}
    else:
        parents = {names[i]: names[rnd.randrange(i)] for i in range(1, FRAMES)}
    links = {
        child: (parent, rnd.uniform(-2, 2), rnd.uniform(-2, 2), rnd.uniform(-1, 1), rnd.uniform(-3, 3))
        for child, parent in parents.items()
    }
    static = set(rnd.sample(sorted(links), STATIC)) if shape == "random" else set()

    def messages(stamp: float, about: tuple[float, float, float] = (0.0, 0.0, 1.0)) -> list:
        out = []
        for child, (parent, x, y, z, yaw) in links.items():
            if child in static:
                continue
            m = TransformStamped()
            m.header.frame_id, m.child_frame_id = parent, child
            m.header.stamp = rospy.Time.from_sec(stamp)
            tr = m.transform.translation
            tr.x, tr.y, tr.z = x, y, z + stamp * 0.01
            r, half = m.transform.rotation, yaw / 2 + stamp
            s = math.sin(half)
            r.x, r.y, r.z, r.w = about[0] * s, about[1] * s, about[2] * s, math.cos(half)
            out.append(m)
        return out

    def make_buffer(about: tuple[float, float, float] = (0.0, 0.0, 1.0)) -> tuple[object, float]:
        buf = tf2_ros.Buffer(debug=False)
        for child in static:
            parent, x, y, z, yaw = links[child]
            m = TransformStamped()
            m.header.frame_id, m.child_frame_id = parent, child
            m.transform.translation.x, m.transform.rotation.w = x, 1.0
            buf.set_transform_static(m, "bench")
        stamp = 100.0
        for _ in range(STAMPS):
            for m in messages(stamp, about):
                buf.set_transform(m, "bench")
            stamp += 0.1
        return buf, stamp

    buf, stamp = make_buffer()
    pairs = [(rnd.choice(names), rnd.choice(names)) for _ in range(n)]
    pair_sets = {"": pairs}
    if shape == "chain":
        pair_sets[" end-root"] = [(names[0], names[-1])] * n
    latest = rospy.Time(0)
    clock = time.perf_counter
    results: dict[str, float] = {}

    def stats(name: str, samples: list[float]) -> None:
        samples.sort()
        results[name + "_p50"] = samples[len(samples) // 2] * 1e6
        results[name + "_p90"] = samples[len(samples) * 9 // 10] * 1e6

    def timed(lookup, pairs, times) -> list[float]:  # noqa: ANN001 (both libraries' Buffer)
        samples = []
        for (target, source), t in zip(pairs, times, strict=True):
            t0 = clock()
            lookup(target, source, t)
            samples.append(clock() - t0)
        return samples

    lookup = buf.lookup_transform
    for target, source in pairs[:1000]:  # warm up
        lookup(target, source, latest)
    for suffix, chosen in pair_sets.items():
        stats("latest" + suffix, timed(lookup, chosen, [latest] * n))
        stats("stamp" + suffix, timed(lookup, chosen, [rospy.Time.from_sec(stamp - 0.55)] * n))
        samples = []
        for i, (target, source) in enumerate(chosen):
            if i % 100 == 99:
                for m in messages(stamp):
                    buf.set_transform(m, "bench")
                stamp += 0.1
            t0 = clock()
            lookup(target, source, latest)
            samples.append(clock() - t0)
        stats("updates" + suffix, samples)
        samples = []
        for target, source in chosen[: n // 10]:
            for m in messages(stamp):
                buf.set_transform(m, "bench")
            stamp += 0.1
            t0 = clock()
            lookup(target, source, latest)
            samples.append(clock() - t0)
        stats("stream" + suffix, samples)
        newest = stamp - 0.1
        times = [rospy.Time.from_sec(newest - rnd.uniform(0.05, 0.85)) for _ in range(n)]
        stats("interp" + suffix, timed(lookup, chosen, times))
    if shape == "random":
        tilted, stamp = make_buffer(TILTED)
        lookup = tilted.lookup_transform
        for target, source in pairs[:1000]:  # warm up
            lookup(target, source, latest)
        newest = stamp - 0.1
        times = [rospy.Time.from_sec(newest - rnd.uniform(0.05, 0.85)) for _ in range(n)]
        stats("interp3d", timed(lookup, pairs, times))
    return results


def run(cmd: list[str], env: dict[str, str]) -> dict[str, float]:
    done = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=900)
    if done.returncode != 0:
        raise SystemExit(f"{cmd[0]} failed:\n{done.stderr}")
    return json.loads(done.stdout.strip().splitlines()[-1])


ROWS = (
    ("latest", "latest"),
    ("stamp", "one past stamp"),
    ("updates", "latest+updates"),
    ("stream", "latest, stream"),
    ("interp", "interpolated"),
    ("interp3d", "interpolated, 3D"),
)


def main() -> int:
    quick = "--quick" in sys.argv
    n = 5_000 if quick else 20_000
    if "--worker" in sys.argv:
        print(json.dumps(worker(sys.argv[sys.argv.index("--worker") + 1], n)))
        return 0
    here = os.path.abspath(__file__)
    ros1_env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV", "PYTHONHOME")}
    ros1_env["PATH"] = "/usr/bin:/bin"
    print(f"tf2_ros Buffer.lookup_transform, {FRAMES}-frame trees, {n} lookups a row (µs per call)")
    print(f"load average: {os.getloadavg()[0]:.2f} (2 cores, shared)")
    print(
        f"{'tree / scenario':<34}{'ninjemys p50':>13}{'ROS 1 p50':>11}{'ratio':>7}{'ours p90':>10}{'ROS 1 p90':>11}"
    )
    for shape in ("random", "chain"):
        args = ["--worker", shape] + (["--quick"] if quick else [])
        ours = run([sys.executable, here, *args], dict(os.environ))
        ros1 = run(["/usr/bin/python3", here, *args], ros1_env)
        for suffix in ("", " end-root"):
            for key, label in ROWS:
                key += suffix
                if key + "_p50" not in ours:
                    continue
                a, b = ours[key + "_p50"], ros1[key + "_p50"]
                pa, pb = ours[key + "_p90"], ros1[key + "_p90"]
                print(
                    f"{shape + suffix + ' / ' + label:<34}{a:>13.2f}{b:>11.2f}{a / b:>7.2f}{pa:>10.2f}{pb:>11.2f}"
                )
    print("ratio = ninjemys / ROS 1 (lower is better; the target is <= 0.5 at p50)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
