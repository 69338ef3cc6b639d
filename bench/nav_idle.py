"""CPU of the whole navigation launch at rest: simulator + map_server + amcl + move_base + safety
monitor, robot standing, no goal (the issue's target: at most 30 % of one core).

Starts our roscore and ``roslaunch puzzlebot_navigation navigation.launch gui:=false`` in its own
process group, waits for it to settle, then sums user+system CPU time of roslaunch and every process under it
over a window. Debian ships no navigation stack, so the reference printed is the issue's target.
Run alone: ``.venv/bin/python bench/nav_idle.py [seconds]``.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time

from ninjemys.testing import ninjemys_bin, run_master

TARGET = 30.0
TICK = os.sysconf("SC_CLK_TCK")


def tree_cpu(root: int) -> float:
    """Seconds of CPU used so far by ``root`` and every live descendant of it."""
    stats: dict[int, tuple[int, float]] = {}
    for pid in os.listdir("/proc"):
        if not pid.isdigit():
            continue
        try:
            with open(f"/proc/{pid}/stat") as f:
                fields = f.read().rsplit(")", 1)[1].split()
        except OSError:
            continue
        stats[int(pid)] = (int(fields[1]), (int(fields[11]) + int(fields[12])) / TICK)  # ppid, utime+stime
    family, total, grew = {root}, 0.0, True
    while grew:
        grew = False
        for pid, (ppid, _) in stats.items():
            if ppid in family and pid not in family:
                family.add(pid)
                grew = True
    for pid in family:
        total += stats.get(pid, (0, 0.0))[1]
    return total


def main() -> None:
    window = float(sys.argv[1]) if len(sys.argv) > 1 else 30.0
    with run_master() as uri:
        env = dict(os.environ, ROS_MASTER_URI=uri)
        proc = subprocess.Popen(
            [ninjemys_bin("roslaunch"), "puzzlebot_navigation", "navigation.launch", "gui:=false"],
            env=env,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
            start_new_session=True,
        )
        try:
            time.sleep(20.0)  # start-up: imports, map loading, first costmaps
            c0, t0 = tree_cpu(proc.pid), time.monotonic()
            time.sleep(window)
            c1, t1 = tree_cpu(proc.pid), time.monotonic()
        finally:
            os.killpg(proc.pid, signal.SIGINT)
            try:
                proc.wait(15)
            except subprocess.TimeoutExpired:
                os.killpg(proc.pid, signal.SIGKILL)
    share = 100.0 * (c1 - c0) / (t1 - t0)
    print(f"load average {os.getloadavg()[0]:.2f} (2 cores shared)")
    print(
        f"navigation launch idle: {share:.1f} % of one core over {window:.0f} s  | target {TARGET:.0f} %  ratio {share / TARGET:.2f}"
    )


if __name__ == "__main__":
    main()
