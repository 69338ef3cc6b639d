"""``import rospy; rospy.init_node()`` process wall time, and the CPU of a 100 Hz talker.

Run: ``.venv/bin/python bench/node_startup.py``. Targets: init wall <= 0.10 s; talker CPU <= 0.5x rospy.
"""

from __future__ import annotations

import os
import statistics
import sys
import time

from node_common import IMPLS, OURS, Role, header, master, ratio, roles

TICKS = os.sysconf("SC_CLK_TCK")


def init_wall(uri: str, impl: str, runs: int) -> float:
    walls = []
    for _ in range(runs):
        t0 = time.perf_counter()
        role = Role(impl, uri, "init_only")
        role.proc.wait(60)
        walls.append(time.perf_counter() - t0)
        role.kill()
    return statistics.median(walls)


def _cpu_seconds(pid: int) -> float:
    with open(f"/proc/{pid}/stat") as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / TICKS


def talker_cpu(uri: str, impl: str, seconds: float) -> float:
    talker = Role(impl, uri, "talker100")
    with roles(talker):
        talker.ready()
        time.sleep(1.0)
        c0, t0 = _cpu_seconds(talker.proc.pid), time.monotonic()
        time.sleep(seconds)
        c1, t1 = _cpu_seconds(talker.proc.pid), time.monotonic()
    return (c1 - c0) / (t1 - t0) * 100


def main() -> None:
    runs = int(sys.argv[1]) if len(sys.argv) > 1 else 7
    header("start-up and idle cost")
    with master() as uri:
        walls = {impl: init_wall(uri, impl, runs) for impl in IMPLS}
        cpus = {impl: talker_cpu(uri, impl, 10.0) for impl in IMPLS}
    for impl in IMPLS:
        print(
            f"{impl:9s} import rospy + init_node process wall {walls[impl] * 1e3:7.1f} ms   100 Hz talker CPU {cpus[impl]:5.1f} %"
        )
    if len(IMPLS) > 1:
        print(
            f"ratio     init wall {ratio(walls[OURS], walls['rospy'])}   talker CPU {ratio(cpus[OURS], cpus['rospy'])}"
        )


if __name__ == "__main__":
    main()
