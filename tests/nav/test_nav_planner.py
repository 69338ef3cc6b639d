"""The global planner: paths that avoid obstacles, are optimal on a small grid, and say why they fail."""

from __future__ import annotations

import heapq
import math

import numpy as np
import pytest

from ninjemys.nav.costmap import inflation_costs
from ninjemys.nav.planner import PlanError, astar, plan_path


def dijkstra_cost(costs, start, goal):
    """Brute-force reference: Dijkstra over every cell with the planner's cost model."""
    h, w = costs.shape
    weight = 50.0 + 3.0 * costs
    dist = {start: 0.0}
    heap = [(0.0, start)]
    while heap:
        d, (x, y) = heapq.heappop(heap)
        if (x, y) == goal:
            return d
        if d > dist[(x, y)]:
            continue
        for dx in (-1, 0, 1):
            for dy in (-1, 0, 1):
                nx, ny = x + dx, y + dy
                if (dx or dy) and 0 <= nx < w and 0 <= ny < h and costs[ny, nx] < 253:
                    nd = d + weight[ny, nx] * (math.sqrt(2) if dx and dy else 1.0)
                    if nd < dist.get((nx, ny), math.inf):
                        dist[(nx, ny)] = nd
                        heapq.heappush(heap, (nd, (nx, ny)))
    return math.inf


def path_cost(costs, path):
    total = 0.0
    for (x0, y0), (x1, y1) in zip(path, path[1:], strict=False):
        total += (50.0 + 3.0 * costs[y1, x1]) * (math.sqrt(2) if x0 != x1 and y0 != y1 else 1.0)
    return total


def test_astar_is_optimal_and_avoids_obstacles():
    rng = np.random.default_rng(5)
    occ = rng.random((30, 30)) < 0.15
    occ[0, 0] = occ[29, 29] = False
    costs = inflation_costs(occ, 0.05, 0.0, 0.15, 10.0)
    costs[0, 0] = costs[29, 29] = 0
    ref = dijkstra_cost(costs, (0, 0), (29, 29))
    if math.isinf(ref):
        with pytest.raises(PlanError, match="no path"):
            astar(costs, (0, 0), (29, 29))
        return
    path = astar(costs, (0, 0), (29, 29))
    assert path[0] == (0, 0) and path[-1] == (29, 29)
    assert all(costs[y, x] < 253 for x, y in path)
    assert math.isclose(path_cost(costs, path), ref, rel_tol=1e-9)


def test_plan_goes_around_a_wall_with_orientations():
    occ = np.zeros((60, 60), dtype=bool)
    occ[10:50, 30] = True
    costs = inflation_costs(occ, 0.05, 0.1, 0.3, 10.0)
    plan = plan_path(costs, 0.05, (0.0, 0.0), (0.5, 1.5), (2.5, 1.5, 1.0))
    assert np.allclose(plan[0, :2], (0.5, 1.5)) and np.allclose(plan[-1], (2.5, 1.5, 1.0))
    cells = np.floor(plan[:, :2] / 0.05).astype(int)
    assert costs[cells[:, 1], cells[:, 0]].max() < 253
    assert plan[:, 1].min() < 0.5 or plan[:, 1].max() > 2.5  # it went round an end of the wall
    d = np.diff(plan[:-1, :2], axis=0)
    assert np.allclose(plan[:-2, 2], np.arctan2(d[:, 1], d[:, 0]))


def test_plan_errors_name_the_reason():
    costs = np.zeros((20, 20), dtype=np.uint8)
    costs[5, 5] = 254
    with pytest.raises(PlanError, match="in an obstacle"):
        astar(costs, (0, 0), (5, 5))
    with pytest.raises(PlanError, match="off the costmap"):
        astar(costs, (0, 0), (25, 5))
    costs[:, 10] = 254
    with pytest.raises(PlanError, match="no path"):
        astar(costs, (0, 0), (15, 5))
    costs[:, 10] = 255
    assert astar(costs, (0, 0), (15, 5))[-1] == (15, 5)  # unknown is allowed by default
    with pytest.raises(PlanError):
        astar(costs, (0, 0), (15, 5), allow_unknown=False)
