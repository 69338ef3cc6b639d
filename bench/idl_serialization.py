"""Serialization throughput: ninjemys message classes vs genpy (Debian's real ROS 1), same workloads.

Run: ``.venv/bin/python bench/idl_serialization.py`` (add ``--quick`` for a shorter run).
This process times ninjemys; the genpy figures come from the same file run under ``/usr/bin/python3``
with ``--genpy`` (ROS 1's classes, no ninjemys on the path). Each figure is the best of several
repetitions of a loop that runs for at least ``MIN_TIME`` seconds of this process's CPU time (CPU time,
not wall time, so that other load on a shared machine disturbs the figures less); treat them as
indicative. ninjemys deserializes large arrays as views (see ``ninjemys.idl.arrays``), the
``deser+read`` column adds reading every array element once, to show the cost when all data is used.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
import timeit
import zlib
from collections.abc import Callable
from io import BytesIO
from typing import Any

MIN_TIME = 0.2
REPEAT = 5
WORKLOADS = [
    "std_msgs/String",
    "geometry_msgs/PoseStamped",
    "sensor_msgs/LaserScan",
    "sensor_msgs/Image",
    "sensor_msgs/PointCloud2",
    "nav_msgs/Path",
]
LABELS = {
    "std_msgs/String": "std_msgs/String (11 chars)",
    "geometry_msgs/PoseStamped": "geometry_msgs/PoseStamped",
    "sensor_msgs/LaserScan": "sensor_msgs/LaserScan (720 ranges + 720 intensities)",
    "sensor_msgs/Image": "sensor_msgs/Image 1920x1080 rgb8 (6.2 MB)",
    "sensor_msgs/PointCloud2": "sensor_msgs/PointCloud2 (1 MB)",
    "nav_msgs/Path": "nav_msgs/Path (1000 poses)",
}


def build(type_name: str, get: Callable[[str], Any]) -> Any:
    """The same message in either implementation (``get`` returns a class for a type name)."""
    cls = get(type_name)
    msg = cls()
    if type_name == "std_msgs/String":
        msg.data = "hello world"
    elif type_name == "geometry_msgs/PoseStamped":
        msg.header.seq = 7
        msg.header.frame_id = "map"
        msg.pose.position.x, msg.pose.position.y, msg.pose.orientation.w = 1.0, 2.0, 1.0
    elif type_name == "sensor_msgs/LaserScan":
        msg.header.frame_id = "laser"
        msg.angle_min, msg.angle_max, msg.angle_increment = -3.14, 3.14, 6.28 / 720
        msg.range_min, msg.range_max = 0.1, 30.0
        msg.ranges = [1.0 + (i % 100) * 0.01 for i in range(720)]
        msg.intensities = [float(i % 7) for i in range(720)]
    elif type_name == "sensor_msgs/Image":
        msg.header.frame_id = "camera"
        msg.height, msg.width, msg.encoding, msg.step = 1080, 1920, "rgb8", 1920 * 3
        msg.data = bytes(range(256)) * (1920 * 1080 * 3 // 256)
    elif type_name == "sensor_msgs/PointCloud2":
        field_cls = get("sensor_msgs/PointField")
        msg.header.frame_id = "lidar"
        msg.height, msg.width = 1, 65536
        msg.fields = [field_cls(name, 4 * i, 7, 1) for i, name in enumerate(("x", "y", "z", "intensity"))]
        msg.point_step, msg.row_step, msg.is_dense = 16, 16 * 65536, True
        msg.data = bytes(range(256)) * (16 * 65536 // 256)
    elif type_name == "nav_msgs/Path":
        pose_cls = get("geometry_msgs/PoseStamped")
        msg.header.frame_id = "map"
        poses = []
        for i in range(1000):
            p = pose_cls()
            p.header.seq = i
            p.header.frame_id = "map"
            p.pose.position.x = float(i)
            p.pose.orientation.w = 1.0
            poses.append(p)
        msg.poses = poses
    return msg


def best_time(fn: Callable[[], Any]) -> float:
    """Seconds per call: best of REPEAT batches, each sized to run at least MIN_TIME of CPU time."""
    timer = timeit.Timer(fn, timer=time.process_time)
    number = 1
    while timer.timeit(number) < MIN_TIME / 4:
        number *= 4
    number = max(1, int(number * 4 * MIN_TIME / max(timer.timeit(number), 1e-9) / 4))
    return min(timer.repeat(repeat=REPEAT, number=number)) / number


def read_all(msg: Any) -> float:
    """Touch every array element once (what a callback that uses all the data pays on top)."""
    total = 0.0
    for name in ("ranges", "intensities"):
        if hasattr(msg, name):
            total += sum(getattr(msg, name))
    if hasattr(msg, "data") and not isinstance(msg.data, str):
        total += zlib.crc32(msg.data)  # one pass over the bytes at C speed, for any buffer type
    if hasattr(msg, "poses"):
        total += sum(p.pose.position.x for p in msg.poses)
    return total


def measure_genpy() -> dict[str, dict[str, float]]:
    import importlib

    def get(type_name: str) -> Any:
        pkg, name = type_name.split("/")
        return getattr(importlib.import_module(f"{pkg}.msg"), name)

    results = {}
    for type_name in WORKLOADS:
        msg = build(type_name, get)
        cls = type(msg)

        def ser(msg: Any = msg) -> bytes:
            buff = BytesIO()
            msg.serialize(buff)
            return buff.getvalue()

        data = ser()
        results[type_name] = {
            "ser": best_time(ser),
            "deser": best_time(lambda cls=cls, data=data: cls().deserialize(data)),
            "deser_read": best_time(lambda cls=cls, data=data: read_all(cls().deserialize(data))),
            "size": len(data),
        }
    return results


def measure_ninjemys() -> dict[str, dict[str, float]]:
    from ninjemys.idl.loader import get_message_class

    results = {}
    for type_name in WORKLOADS:
        msg = build(type_name, get_message_class)
        cls = type(msg)
        data = msg.serialize_to_bytes()
        results[type_name] = {
            "ser": best_time(msg.serialize_to_bytes),
            "deser": best_time(lambda cls=cls, data=data: cls.deserialize_from(data)),
            "deser_read": best_time(lambda cls=cls, data=data: read_all(cls.deserialize_from(data))),
            "size": len(data),
        }
    return results


def fmt_time(seconds: float) -> str:
    if seconds < 1e-3:
        return f"{seconds * 1e6:.1f} us"
    return f"{seconds * 1e3:.2f} ms"


def _run_side(flag: str, python: str, pythonpath: str | None) -> dict[str, dict[str, float]]:
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV", "PYTHONHOME")}
    env["PATH"] = "/usr/bin:/bin"
    if pythonpath:
        env["PYTHONPATH"] = pythonpath
    args = [python, os.path.abspath(__file__), flag] + (["--quick"] if "--quick" in sys.argv else [])
    done = subprocess.run(args, capture_output=True, text=True, env=env, check=False)
    if done.returncode != 0:
        raise RuntimeError(f"{python} {flag} failed: {done.stderr.strip()[-500:]}")
    return json.loads(done.stdout)


def main() -> int:
    global MIN_TIME, REPEAT
    if "--quick" in sys.argv:
        MIN_TIME, REPEAT = 0.05, 3
    if "--genpy" in sys.argv:
        print(json.dumps(measure_genpy()))
        return 0
    if "--ninjemys" in sys.argv:
        print(json.dumps(measure_ninjemys()))
        return 0
    src = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "src")
    try:
        theirs = _run_side("--genpy", "/usr/bin/python3", None)
        # the fair comparison: our code under the very interpreter genpy runs on (Debian's python3)
        same = _run_side("--ninjemys", "/usr/bin/python3", src)
    except RuntimeError as exc:
        print(f"ERROR: {exc}", file=sys.stderr)
        return 1
    ours = measure_ninjemys()  # and under this interpreter (the venv's), for reference
    for type_name in WORKLOADS:
        if ours[type_name]["size"] != theirs[type_name]["size"]:
            print(f"ERROR: {type_name}: wire sizes differ", file=sys.stderr)
            return 1
    print(f"genpy and 'ninjemys' run on /usr/bin/python3; 'ninjemys (this python)' on {sys.executable}")
    print("| message | op | genpy | ninjemys | speed-up | ninjemys (this python) |")
    print("|---|---|---|---|---|---|")
    for type_name in WORKLOADS:
        for op, label in (("ser", "serialize"), ("deser", "deserialize"), ("deser_read", "deser+read")):
            g, n, v = theirs[type_name][op], same[type_name][op], ours[type_name][op]
            print(
                f"| {LABELS[type_name]} | {label} | {fmt_time(g)} | {fmt_time(n)} | {g / n:.1f}x | {fmt_time(v)} |"
            )
    return 0


if __name__ == "__main__":
    sys.exit(main())
