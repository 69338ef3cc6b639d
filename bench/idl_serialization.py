"""Serialization throughput: ninjemys message classes vs genpy (Debian's real ROS 1), same workloads.

Run: ``.venv/bin/python bench/idl_serialization.py`` (add ``--quick`` for a shorter run).
genpy (Debian's ROS 1 classes) and ninjemys are timed in ONE ``/usr/bin/python3`` process (this file with
``--pair``), interleaved operation by operation, so both see the same interpreter build and the same
machine load; the venv's interpreter is timed too, for reference (it may be built differently). Each figure is the best of several
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


def _batch_size(timer: timeit.Timer) -> int:
    number = 1
    while timer.timeit(number) < MIN_TIME / 4:
        number *= 4
    return max(1, int(number * 4 * MIN_TIME / max(timer.timeit(number), 1e-9) / 4))


def best_times_interleaved(first: Callable[[], Any], second: Callable[[], Any]) -> tuple[float, float]:
    """Like best_time for two functions, alternating their batches so both see the same machine load."""
    timers = [timeit.Timer(fn, timer=time.process_time) for fn in (first, second)]
    numbers = [_batch_size(t) for t in timers]
    best = [float("inf"), float("inf")]
    for _ in range(REPEAT * 2):
        for i in (0, 1):
            best[i] = min(best[i], timers[i].timeit(numbers[i]) / numbers[i])
    return best[0], best[1]


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


def _genpy_ops(type_name: str) -> tuple[Any, dict[str, Callable[[], Any]]]:
    import importlib

    def get(name: str) -> Any:
        pkg, short = name.split("/")
        return getattr(importlib.import_module(f"{pkg}.msg"), short)

    msg = build(type_name, get)
    cls = type(msg)

    def ser(msg: Any = msg) -> bytes:
        buff = BytesIO()
        msg.serialize(buff)
        return buff.getvalue()

    data = ser()
    return data, {
        "ser": ser,
        "deser": lambda: cls().deserialize(data),
        "deser_read": lambda: read_all(cls().deserialize(data)),
    }


def _ninjemys_ops(type_name: str) -> tuple[Any, dict[str, Callable[[], Any]]]:
    from ninjemys.idl.loader import get_message_class

    msg = build(type_name, get_message_class)
    cls = type(msg)
    data = msg.serialize_to_bytes()
    return data, {
        "ser": msg.serialize_to_bytes,
        "deser": lambda: cls.deserialize_from(data),
        "deser_read": lambda: read_all(cls.deserialize_from(data)),
    }


def measure_pair() -> dict[str, dict[str, dict[str, float]]]:
    """genpy and ninjemys in ONE process (this interpreter), interleaved per operation."""
    results: dict[str, dict[str, dict[str, float]]] = {"genpy": {}, "ninjemys": {}}
    for type_name in WORKLOADS:
        g_data, g_ops = _genpy_ops(type_name)
        n_data, n_ops = _ninjemys_ops(type_name)
        if g_data != n_data:
            raise RuntimeError(f"{type_name}: ninjemys and genpy bytes differ")
        results["genpy"][type_name] = {"size": len(g_data)}
        results["ninjemys"][type_name] = {"size": len(n_data)}
        for op in ("ser", "deser", "deser_read"):
            g_time, n_time = best_times_interleaved(g_ops[op], n_ops[op])
            results["genpy"][type_name][op] = g_time
            results["ninjemys"][type_name][op] = n_time
    return results


def measure_ninjemys() -> dict[str, dict[str, float]]:
    results = {}
    for type_name in WORKLOADS:
        data, ops = _ninjemys_ops(type_name)
        results[type_name] = {op: best_time(fn) for op, fn in ops.items()}
        results[type_name]["size"] = len(data)
    return results


def fmt_time(seconds: float) -> str:
    if seconds < 1e-3:
        return f"{seconds * 1e6:.1f} us"
    return f"{seconds * 1e3:.2f} ms"


def _run_pair() -> dict[str, dict[str, dict[str, float]]]:
    """Run ``--pair`` under Debian's python3: its dist-packages (genpy, std_msgs...) first, our src last."""
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV", "PYTHONHOME")}
    env["PATH"] = "/usr/bin:/bin"
    args = ["/usr/bin/python3", os.path.abspath(__file__), "--pair"] + (
        ["--quick"] if "--quick" in sys.argv else []
    )
    done = subprocess.run(args, capture_output=True, text=True, env=env, check=False)
    if done.returncode != 0:
        raise RuntimeError(f"/usr/bin/python3 --pair failed: {done.stderr.strip()[-500:]}")
    return json.loads(done.stdout)


def main() -> int:
    global MIN_TIME, REPEAT
    if "--quick" in sys.argv:
        MIN_TIME, REPEAT = 0.05, 3
    if "--pair" in sys.argv:
        # appended, not prepended: `std_msgs` etc. must stay ROS 1's in this process
        sys.path.append(os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "src"))
        print(json.dumps(measure_pair()))
        return 0
    try:
        pair = _run_pair()
    except RuntimeError as exc:
        print(f"ERROR: {exc}", file=sys.stderr)
        return 1
    theirs, same = pair["genpy"], pair["ninjemys"]
    ours = measure_ninjemys()  # under this interpreter (the venv's), for reference
    print("genpy and 'ninjemys' run in one /usr/bin/python3 process, interleaved;")
    print(
        f"'ninjemys (this python)' runs on {sys.executable}. Times are CPU time per call (best of {REPEAT})."
    )
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
