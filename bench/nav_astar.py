"""The global planner on a 400 x 400 inflated costmap, corner to corner (the issue's target: 50 ms).

Debian ships no navigation stack, so there is no ROS 1 run beside ours; the reference printed is the
target set for ROS 1's C++ global planners (navfn / global_planner) in the issue. Beside the planner
runs the exact heap A* it replaced (the same cost model, Python lists and ``heapq``), to show the
gain and that both find paths of the same cost. Three maps: an office-like floor (rooms and doors),
a field of 60 random boxes, and a serpentine of walls with 1-cell openings (a path that winds 65
times: the planner's hard case). Run alone: ``.venv/bin/python bench/nav_astar.py``.
"""

from __future__ import annotations

import heapq
import math
import os
import time

import numpy as np

from ninjemys.nav.costmap import inflation_costs
from ninjemys.nav.planner import astar

TARGET_MS = 50.0
SQRT2 = math.sqrt(2.0)


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


def serpentine() -> np.ndarray:
    """Walls every 6 cells, each opened by one cell at alternate ends (not inflated: 1-cell doors)."""
    costs = np.zeros((400, 400), dtype=np.uint8)
    for k, x in enumerate(range(3, 398, 6)):
        costs[:, x] = 254
        costs[(0 if k % 2 else -1), x] = 0
    return costs


def heap_astar(costs: np.ndarray, start: tuple[int, int], goal: tuple[int, int]) -> list[tuple[int, int]]:
    """The planner this replaced: exact A* (octile heuristic) with heapq over a padded flat list."""
    h, w = costs.shape
    wp = w + 2
    padded = np.full((h + 2, wp), -1.0)
    padded[1:-1, 1:-1] = np.where(costs >= 253, -1.0, 50.0 + 3.0 * costs)
    weights = padded.ravel().tolist()
    s, g = (start[1] + 1) * wp + start[0] + 1, (goal[1] + 1) * wp + goal[0] + 1
    dx = np.abs(np.arange(wp) - (goal[0] + 1))[None, :]
    dy = np.abs(np.arange(h + 2) - (goal[1] + 1))[:, None]
    heur = (50.0 * (dx + dy) + (SQRT2 - 2.0) * 50.0 * np.minimum(dx, dy)).ravel().tolist()
    dist = [math.inf] * len(weights)
    parent = [-1] * len(weights)
    dist[s] = 0.0
    steps = [(1, 1.0), (-1, 1.0), (wp, 1.0), (-wp, 1.0)] + [
        (o, SQRT2) for o in (wp + 1, wp - 1, 1 - wp, -1 - wp)
    ]
    heap = [(0.0, s)]
    while heap:
        _, u = heapq.heappop(heap)
        if weights[u] < 0.0:
            continue
        if u == g:
            break
        weights[u] = -1.0  # closed
        for off, length in steps:
            v = u + off
            if weights[v] >= 0.0 and dist[u] + weights[v] * length < dist[v]:
                dist[v] = dist[u] + weights[v] * length
                parent[v] = u
                heapq.heappush(heap, (dist[v] + heur[v], v))
    path = []
    while g != -1:
        path.append((g % wp - 1, g // wp - 1))
        g = parent[g]
    return path[::-1]


def path_cost(costs: np.ndarray, path: list[tuple[int, int]]) -> float:
    a = np.asarray(path)
    diagonal = np.all(np.diff(a, axis=0) != 0, axis=1)
    return float(np.sum((50.0 + 3.0 * costs[a[1:, 1], a[1:, 0]]) * np.where(diagonal, SQRT2, 1.0)))


def timed(fn, runs: int) -> tuple[list[float], list[tuple[int, int]]]:
    times = []
    for _ in range(runs):
        t = time.perf_counter()
        path = fn()
        times.append((time.perf_counter() - t) * 1000)
    return times, path


def main() -> None:
    print(f"load average {os.getloadavg()[0]:.2f} (2 cores shared)")
    maps = (
        ("office floor", inflation_costs(office_floor(), 0.05, 0.12, 0.5, 10.0)),
        ("random boxes", inflation_costs(random_boxes(), 0.05, 0.12, 0.5, 10.0)),
        ("serpentine", serpentine()),
    )
    for name, costs in maps:
        new, path = timed(lambda c=costs: astar(c, (5, 5), (394, 394)), 7)
        old, ref = timed(lambda c=costs: heap_astar(c, (5, 5), (394, 394)), 2)
        best = min(new)
        print(
            f"400x400 {name:12s}: planner {best:6.1f} ms best, {np.median(new):6.1f} median | heap A* "
            f"{min(old):6.1f} ms ({min(old) / best:4.1f}x) | path cost {path_cost(costs, path):.2f} vs "
            f"{path_cost(costs, ref):.2f}, {len(path)} cells | target {TARGET_MS:.0f} ms, ratio {best / TARGET_MS:.2f}"
        )
    print(f"load average {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
