"""The global planner: A* over an inflated costmap, as ROS's global_planner does it.

No ROS in here. A cell's traversal cost is ``neutral_cost + cost_factor * cost`` (global_planner's
defaults 50 and 3.0); cells at or above ``lethal_cost`` (253: inscribed or worse) cannot be entered,
unknown cells (255) can when ``allow_unknown``. Steps go to the 8 neighbours (diagonals cost
``sqrt(2)`` times more) and the heuristic is the octile distance times the neutral cost, so the path
is optimal for that cost. The cell path is then smoothed (a 5-point moving average, ends fixed) and
given orientations: each pose faces the next, the last takes the goal's.

The search runs on Python lists over a padded flat grid (one blocked border, so no bounds checks)
with ``heapq``; the numpy work (weights, padding) is done once per call.
"""

from __future__ import annotations

import heapq
import math

import numpy as np

SQRT2 = math.sqrt(2.0)


class PlanError(ValueError):
    """No plan: the text says why (start or goal blocked or off the map, goal unreachable)."""


def astar(
    costs: np.ndarray,
    start: tuple[int, int],
    goal: tuple[int, int],
    neutral_cost: float = 50.0,
    cost_factor: float = 3.0,
    lethal_cost: int = 253,
    allow_unknown: bool = True,
) -> list[tuple[int, int]]:
    """Cheapest 8-connected cell path (col, row) from ``start`` to ``goal`` on a uint8 costmap."""
    h, w = costs.shape
    for what, (cx, cy) in (("start", start), ("goal", goal)):
        if not (0 <= cx < w and 0 <= cy < h):
            raise PlanError(f"the {what} ({cx}, {cy}) is off the costmap ({w}x{h} cells)")
    weights = neutral_cost + cost_factor * costs.astype(np.float64)
    blocked = costs >= lethal_cost
    if allow_unknown:
        blocked &= costs != 255
    weights[blocked] = -1.0
    sc = costs[start[1], start[0]]
    if blocked[goal[1], goal[0]]:
        raise PlanError(
            f"the goal cell ({goal[0]}, {goal[1]}) is in an obstacle (cost {costs[goal[1], goal[0]]})"
        )
    weights[start[1], start[0]] = neutral_cost + cost_factor * min(int(sc), lethal_cost - 1)
    W = w + 2
    padded = np.full((h + 2, W), -1.0)
    padded[1:-1, 1:-1] = weights
    wl = padded.ravel().tolist()
    s = (start[1] + 1) * W + start[0] + 1
    g_idx = (goal[1] + 1) * W + goal[0] + 1
    # the octile heuristic of every cell at once (a list lookup per push beats arithmetic)
    dx = np.abs(np.arange(W) - (goal[0] + 1))[None, :]
    dy = np.abs(np.arange(h + 2) - (goal[1] + 1))[:, None]
    hk = neutral_cost * 1.0001  # a tiny tie-break towards the goal
    heur = (hk * (dx + dy) + (SQRT2 - 2.0) * hk * np.minimum(dx, dy)).ravel().tolist()
    n = len(wl)
    dist = [math.inf] * n
    parent = [-1] * n
    dist[s] = 0.0
    steps = (
        (1, 1.0),
        (-1, 1.0),
        (W, 1.0),
        (-W, 1.0),
        (W + 1, SQRT2),
        (W - 1, SQRT2),
        (-W + 1, SQRT2),
        (-W - 1, SQRT2),
    )
    heap = [(0.0, s)]
    pop, push = heapq.heappop, heapq.heappush
    found = False
    while heap:
        _, u = pop(heap)
        if wl[u] < 0.0:  # closed (or blocked): closing a cell marks its weight blocked
            continue
        if u == g_idx:
            found = True
            break
        wl[u] = -1.0
        du = dist[u]
        for off, length in steps:
            v = u + off
            wv = wl[v]
            if wv < 0.0:
                continue
            nd = du + wv * length
            if nd < dist[v]:
                dist[v] = nd
                parent[v] = u
                push(heap, (nd + heur[v], v))
    if not found:
        raise PlanError(f"no path from cell ({start[0]}, {start[1]}) to cell ({goal[0]}, {goal[1]})")
    path = []
    v = g_idx
    while v != -1:
        path.append((v % W - 1, v // W - 1))
        v = parent[v]
    path.reverse()
    return path


def smooth(points: np.ndarray) -> np.ndarray:
    """A 5-point moving average of a polyline (ends fixed): takes the grid's stair steps out."""
    if len(points) < 5:
        return points
    out = points.copy()
    kernel = np.ones(5) / 5.0
    for axis in (0, 1):
        out[2:-2, axis] = np.convolve(points[:, axis], kernel, mode="valid")
    return out


def orient(points: np.ndarray, goal_yaw: float) -> np.ndarray:
    """(n, 3) poses: each faces the next point, the last takes ``goal_yaw``."""
    yaw = np.empty(len(points))
    if len(points) > 1:
        d = np.diff(points, axis=0)
        yaw[:-1] = np.arctan2(d[:, 1], d[:, 0])
    yaw[-1] = goal_yaw
    return np.column_stack([points, yaw])


def plan_path(
    costs: np.ndarray,
    resolution: float,
    origin: tuple[float, float],
    start_xy: tuple[float, float],
    goal_pose: tuple[float, float, float],
    neutral_cost: float = 50.0,
    cost_factor: float = 3.0,
    lethal_cost: int = 253,
    allow_unknown: bool = True,
) -> np.ndarray:
    """World-frame plan (n, 3) of x, y, yaw from ``start_xy`` to ``goal_pose`` on the costmap."""
    ox, oy = origin

    def cell(x: float, y: float) -> tuple[int, int]:
        return int(math.floor((x - ox) / resolution)), int(math.floor((y - oy) / resolution))

    cells = astar(
        costs,
        cell(*start_xy),
        cell(goal_pose[0], goal_pose[1]),
        neutral_cost,
        cost_factor,
        lethal_cost,
        allow_unknown,
    )
    arr = np.asarray(cells, dtype=float)
    pts = np.column_stack([ox + (arr[:, 0] + 0.5) * resolution, oy + (arr[:, 1] + 0.5) * resolution])
    pts[0] = start_xy
    pts[-1] = goal_pose[:2]
    pts = smooth(pts)
    return orient(pts, goal_pose[2])
