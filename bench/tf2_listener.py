"""CPU of a tf listener under /tf at 100 Hz with 50 transforms a message: ninjemys vs Debian's tf2_ros.

Run: ``.venv/bin/python bench/tf2_listener.py`` (``--seconds N``, default 10).

Two rounds: a listener that only listens, and one that also looks a transform up 20 times a second
(ours reads /tf lazily and decodes what arrived in batches when asked, so a node that asks more
often pays more).

One broadcaster (ours) publishes /tf; two listeners subscribe at the same time, each a process of
its own running this file as ``--listen``: ninjemys's ``tf2_ros.Buffer`` + ``TransformListener``
under the venv, and Debian's under /usr/bin/python3 (ROS 1's Python listener: genpy deserialization
and one ``set_transform`` call per transform, geometry2#513). Each measures its own CPU time
(user + system, ``time.process_time``) over the same window after the first transforms arrived,
and checks that the newest data really is in its buffer. The master is our roscore. The machine is
shared: the load average is printed with the figures.
"""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
import time

FRAMES = 50
RATE = 100.0


def listen(seconds: float, lookup_hz: float) -> dict[str, float]:
    import rospy
    import tf2_ros

    rospy.init_node("tf_bench_listener", anonymous=True)
    buf = tf2_ros.Buffer(debug=False)
    tf2_ros.TransformListener(buf)
    buf.can_transform("world", f"f{FRAMES - 1}", rospy.Time(0), rospy.Duration(30.0))
    time.sleep(1.0)  # let connection set-up settle
    cpu0, wall0 = time.process_time(), time.monotonic()
    if lookup_hz > 0:  # a node that also uses the data: one lookup per period
        end = wall0 + seconds
        while time.monotonic() < end:
            buf.lookup_transform("world", f"f{FRAMES - 1}", rospy.Time(0))
            time.sleep(1.0 / lookup_hz)
    else:
        time.sleep(seconds)
    cpu, wall = time.process_time() - cpu0, time.monotonic() - wall0
    latest = buf.lookup_transform("world", f"f{FRAMES - 1}", rospy.Time(0)).header.stamp.to_sec()
    return {"cpu": cpu, "wall": wall, "lag": time.time() - latest}


def broadcast() -> None:
    import rospy
    import tf2_ros

    rospy.init_node("tf_bench_broadcaster")
    br = tf2_ros.TransformBroadcaster()
    period = 1.0 / RATE
    next_t = time.monotonic()
    while not rospy.is_shutdown():
        now = time.time_ns()
        items = []
        for i in range(FRAMES):
            parent = "world" if i == 0 else f"f{(i - 1) // 2}"
            a = now * 1e-9 + i
            items.append(
                (
                    parent,
                    f"f{i}",
                    now,
                    math.cos(a),
                    math.sin(a),
                    0.1 * i,
                    0.0,
                    0.0,
                    math.sin(a / 2),
                    math.cos(a / 2),
                )
            )
        br.send_items(items)
        next_t += period
        time.sleep(max(0.0, next_t - time.monotonic()))


def main() -> int:
    seconds = float(sys.argv[sys.argv.index("--seconds") + 1]) if "--seconds" in sys.argv else 10.0
    if "--listen" in sys.argv:
        hz = float(sys.argv[sys.argv.index("--lookup-hz") + 1])
        print(json.dumps(listen(seconds, hz)), flush=True)
        return 0
    if "--broadcast" in sys.argv:
        broadcast()
        return 0
    here = os.path.abspath(__file__)
    sys.path.insert(0, os.path.join(os.path.dirname(here), "..", "src"))
    from ninjemys import testing

    with testing.run_master() as uri:
        env = dict(os.environ, ROS_MASTER_URI=uri)
        ros1_env = testing.ros1_env(uri)
        pub = subprocess.Popen([sys.executable, here, "--broadcast"], env=env)
        results = []
        try:
            for hz in (0.0, 20.0):
                args = ["--listen", "--seconds", str(seconds), "--lookup-hz", str(hz)]
                ours = subprocess.Popen(
                    [sys.executable, here, *args], env=env, stdout=subprocess.PIPE, text=True
                )
                ros1 = subprocess.Popen(
                    ["/usr/bin/python3", here, *args], env=ros1_env, stdout=subprocess.PIPE, text=True
                )
                a = json.loads(ours.communicate(timeout=seconds + 120)[0].strip().splitlines()[-1])
                b = json.loads(ros1.communicate(timeout=seconds + 120)[0].strip().splitlines()[-1])
                results.append((hz, a, b))
        finally:
            testing.kill_tree(pub)
    print(f"tf listener CPU, /tf at {RATE:g} Hz x {FRAMES} transforms, {seconds:g} s window")
    print(f"load average: {os.getloadavg()[0]:.2f} (2 cores, shared)")
    print(
        f"{'lookups/s':<11}{'ninjemys CPU %':>16}{'ROS 1 CPU %':>13}{'ratio':>8}{'lag ours / ROS 1 (s)':>24}"
    )
    for hz, a, b in results:
        print(
            f"{hz:<11g}{100 * a['cpu'] / a['wall']:>16.2f}{100 * b['cpu'] / b['wall']:>13.2f}"
            f"{a['cpu'] / b['cpu']:>8.2f}{a['lag']:>12.3f} / {b['lag']:.3f}"
        )
    print(
        "ratio = ninjemys / ROS 1 CPU (the target is <= 0.25); lag = age of the newest transform at the end"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
