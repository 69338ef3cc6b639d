"""Read throughput of a large bag: ninjemys vs real rosbag (Debian, /usr/bin/python3) vs rosbags.

    .venv/bin/python bench/bag_read.py [--mb 256] [--size 1024] [--repeat 3]

Writes one bag of SIZE-byte std_msgs/String-like messages per compression (none, lz4), about MB
megabytes each, then times a full read of every message as bytes (no deserialization: raw=True in
rosbag, the reader's bytes in rosbags and ninjemys) and prints msgs/s, MB/s and ratios.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from ninjemys.bag.reader import BagReader
from ninjemys.bag.writer import BagWriter
from ninjemys.testing import ROS1_PYTHON, have_ros1

HEADER = {
    "type": b"std_msgs/String",
    "md5sum": b"992ce8a1687cec8c8bd883ec73ca41d1",
    "message_definition": b"string data\n",
}

REAL_ROSBAG = """
import sys, time, rosbag
t0 = time.perf_counter()
n = 0
size = 0
with rosbag.Bag(sys.argv[1]) as bag:
    if sys.argv[2] == "raw":
        for topic, raw, t in bag.read_messages(raw=True):
            n += 1
            size += len(raw[1])
    else:
        for topic, msg, t in bag.read_messages():
            n += 1
            size += len(msg.data) + 4
print(n, size, time.perf_counter() - t0)
"""


def make_bag(path: Path, compression: str, total_mb: int, size: int) -> int:
    count = total_mb * 1024 * 1024 // (size + 30)
    # hex text of random bytes: compresses about 2:1, like typical mixed sensor data
    pool = os.urandom(1 << 20).hex().encode()
    length = (size - 4).to_bytes(4, "little")
    with BagWriter(path, compression=compression) as w:
        a = w.connection("/a", HEADER)
        b = w.connection("/b", HEADER)
        t = 1_700_000_000 * 10**9
        for i in range(count):
            off = (i * 7919) % (len(pool) - size)
            w.write(a if i % 2 else b, t + i * 100_000, length + pool[off : off + size - 4])
    return count


def time_ninjemys(path: Path) -> tuple[int, int, float]:
    t0 = time.perf_counter()
    n = size = 0
    with BagReader(path) as r:
        for m in r.read():
            n += 1
            size += len(m.data)
    return n, size, time.perf_counter() - t0


def time_ninjemys_api(path: Path) -> tuple[int, int, float]:
    import rosbag

    t0 = time.perf_counter()
    n = size = 0
    with rosbag.Bag(str(path)) as bag:
        for _topic, raw, _t in bag.read_messages(raw=True):
            n += 1
            size += len(raw[1])
    return n, size, time.perf_counter() - t0


def time_ninjemys_decoded(path: Path) -> tuple[int, int, float]:
    import rosbag

    t0 = time.perf_counter()
    n = size = 0
    with rosbag.Bag(str(path)) as bag:
        for _topic, msg, _t in bag.read_messages():
            n += 1
            size += len(msg.data) + 4
    return n, size, time.perf_counter() - t0


def time_rosbags_decoded(path: Path) -> tuple[int, int, float]:
    from rosbags.rosbag1 import Reader
    from rosbags.typesys import Stores, get_typestore

    store = get_typestore(Stores.ROS1_NOETIC)
    t0 = time.perf_counter()
    n = size = 0
    with Reader(path) as r:
        for _c, _t, data in r.messages():
            msg = store.deserialize_ros1(data, "std_msgs/msg/String")
            n += 1
            size += len(msg.data) + 4
    return n, size, time.perf_counter() - t0


def time_rosbags(path: Path) -> tuple[int, int, float]:
    from rosbags.rosbag1 import Reader

    t0 = time.perf_counter()
    n = size = 0
    with Reader(path) as r:
        for _c, _t, data in r.messages():
            n += 1
            size += len(data)
    return n, size, time.perf_counter() - t0


def time_real(path: Path, mode: str = "raw") -> tuple[int, int, float] | None:
    if not have_ros1():
        return None
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV")}
    out = subprocess.run(
        [ROS1_PYTHON, "-c", REAL_ROSBAG, str(path), mode], capture_output=True, text=True, env=env, check=True
    )
    n, size, secs = out.stdout.split()
    return int(n), int(size), float(secs)


def best_of(fn, repeat: int) -> tuple[int, int, float] | None:
    runs = [fn() for _ in range(max(repeat, 1))]
    if runs[0] is None:
        return None
    return min(runs, key=lambda r: r[2])


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--mb", type=int, default=256, help="bag size in MB (default 256; the issue asks 1024)")
    ap.add_argument(
        "--repeat", type=int, default=3, help="runs per reader; the fastest counts (shared machine)"
    )
    ap.add_argument("--size", type=int, default=1024, help="message size in bytes (default 1024)")
    ap.add_argument("--json", action="store_true", help="print results as JSON too")
    args = ap.parse_args()
    results = []
    with tempfile.TemporaryDirectory(prefix="bag_read_") as tmp:
        for compression in ("none", "lz4"):
            path = Path(tmp) / f"{compression}.bag"
            count = make_bag(path, compression, args.mb, args.size)
            print(
                f"# {compression}: {count} messages of {args.size} B, file {path.stat().st_size / 1e6:.0f} MB",
                flush=True,
            )
            runners = {
                "ninjemys BagReader": lambda p=path: time_ninjemys(p),
                "ninjemys rosbag.Bag raw": lambda p=path: time_ninjemys_api(p),
                "rosbags": lambda p=path: time_rosbags(p),
                "ROS 1 rosbag raw": lambda p=path: time_real(p),
                "ninjemys rosbag.Bag decoded": lambda p=path: time_ninjemys_decoded(p),
                "rosbags decoded": lambda p=path: time_rosbags_decoded(p),
                "ROS 1 rosbag decoded": lambda p=path: time_real(p, "decoded"),
            }
            rows = {name: best_of(fn, args.repeat) for name, fn in runners.items()}
            for name, res in rows.items():
                base = rows["ROS 1 rosbag decoded" if "decoded" in name else "ROS 1 rosbag raw"]
                if res is None:
                    print(f"{compression:5} {name:28} (not available)")
                    continue
                n, size, secs = res
                assert n == count, f"{name} read {n} of {count} messages"
                ratio = f"  x{base[2] / secs:5.2f} vs ROS 1" if base else ""
                print(
                    f"{compression:5} {name:26} {n / secs:12,.0f} msgs/s {size / secs / 1e6:9.1f} MB/s{ratio}",
                    flush=True,
                )
                results.append(
                    {
                        "compression": compression,
                        "reader": name,
                        "msgs_per_s": n / secs,
                        "mb_per_s": size / secs / 1e6,
                    }
                )
            path.unlink()
    if args.json:
        print(json.dumps(results))
    return 0


if __name__ == "__main__":
    sys.exit(main())
