"""A* on a 400 x 400 inflated costmap, corner to corner (the issue's target: at most 50 ms).

Debian ships no navigation stack, so there is no ROS 1 run beside ours; the reference printed is the
target set for ROS 1's C++ global planners (navfn / global_planner) in the issue. Two maps: an
office-like floor (rooms and doors) and a field of 60 random boxes. Run alone:
``.venv/bin/python bench/nav_astar.py``.
"""

from __future__ import annotations

import os
import time

import numpy as np

from ninjemys.nav.costmap import inflation_costs
from ninjemys.nav.planner import astar

TARGET_MS = 50.0


def office_floor() -> np.ndarray:
    occ = np.zeros((400, 400), dtype=bool)
    occ[[0, -1], :] = occ[:, [0, -1]] = True
    for k in range(1, 4):  # three walls across, each with two 1 m doors
        occ[k * 100, :] = True
        occ[k * 100, 40 + 60 * k : 60 + 60 * k] = False
        occ[k * 100, 300 - 30 * k : 320 - 30 * k] = False
    for k in range(1, 4):
        occ[:, k * 100] |= np.arange(400) % 100 > 70  # partial walls along
    occ[:10, :10] = occ[-10:, -10:] = False
    return occ


def random_boxes(seed: int = 1) -> np.ndarray:
    rng = np.random.default_rng(seed)
    occ = np.zeros((400, 400), dtype=bool)
    occ[[0, -1], :] = occ[:, [0, -1]] = True
    for _ in range(60):
        x, y = rng.integers(20, 380, 2)
        occ[y : y + rng.integers(3, 30), x : x + rng.integers(3, 30)] = True
    occ[:12, :12] = occ[-12:, -12:] = False
    return occ


def main() -> None:
    print(f"load average {os.getloadavg()[0]:.2f} (2 cores shared)")
    for name, occ in (("office floor", office_floor()), ("random boxes", random_boxes())):
        costs = inflation_costs(occ, 0.05, 0.12, 0.5, 10.0)
        times = []
        for _ in range(5):
            t = time.perf_counter()
            path = astar(costs, (5, 5), (394, 394))
            times.append((time.perf_counter() - t) * 1000)
        best = min(times)
        print(
            f"A* 400x400 {name:13s}: {best:6.1f} ms best, {np.median(times):6.1f} ms median, {len(path)} cells"
            f"  | target {TARGET_MS:.0f} ms  ratio {best / TARGET_MS:.2f}"
        )


if __name__ == "__main__":
    main()
