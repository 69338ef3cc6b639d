"""The global planner: paths that avoid obstacles, are optimal against an exact search, and say why they fail.

The planner's stages (row sweeps, column sweeps, the heap repair, the plain A* fallback, the
predecessor-table walk) are each forced in turn by lowering their thresholds, so every one of them
is checked against the brute-force Dijkstra below on maps made to need it.
"""

from __future__ import annotations

import heapq
import math

import numpy as np
import pytest

from ninjemys.nav import planner
from ninjemys.nav.costmap import inflation_costs
from ninjemys.nav.planner import PlanError, astar, plan_path

#: the planner's step costs are rounded to 1 / 2**20 of a cost unit (the module docstring's bound)
QUANTUM = 2.0**-20


def dijkstra_cost(costs, start, goal, neutral=50.0, factor=3.0, allow_unknown=False):
    """Brute-force reference: Dijkstra over every cell with the planner's cost model."""
    h, w = costs.shape
    weight = neutral + factor * costs.astype(float)
    ok = (costs < 253) | ((costs == 255) & allow_unknown)
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
                if (dx or dy) and 0 <= nx < w and 0 <= ny < h and ok[ny, nx]:
                    nd = d + weight[ny, nx] * (math.sqrt(2) if dx and dy else 1.0)
                    if nd < dist.get((nx, ny), math.inf):
                        dist[(nx, ny)] = nd
                        heapq.heappush(heap, (nd, (nx, ny)))
    return math.inf


def path_cost(costs, path, neutral=50.0, factor=3.0):
    total = 0.0
    for (x0, y0), (x1, y1) in zip(path, path[1:], strict=False):
        assert max(abs(x1 - x0), abs(y1 - y0)) == 1, f"not a step: {(x0, y0)} -> {(x1, y1)}"
        total += (neutral + factor * float(costs[y1, x1])) * (math.sqrt(2) if x0 != x1 and y0 != y1 else 1.0)
    return total


def check_plan(costs, start, goal, neutral=50.0, factor=3.0, allow_unknown=True, quantum=QUANTUM):
    """Plan, and check the path against the exact search: valid steps, no blocked cell, cost bound."""
    ref = dijkstra_cost(costs, start, goal, neutral, factor, allow_unknown)
    if math.isinf(ref):
        with pytest.raises(PlanError, match="no path"):
            astar(costs, start, goal, neutral, factor, allow_unknown=allow_unknown)
        return None
    path = astar(costs, start, goal, neutral, factor, allow_unknown=allow_unknown)
    assert path[0] == start and path[-1] == goal
    assert all(costs[y, x] < 253 or (allow_unknown and costs[y, x] == 255) for x, y in path[1:])
    # optimal for the step costs rounded to ``quantum``: within half a quantum per step of either
    # path (the optimal one has at most ref / neutral steps)
    bound = (len(path) - 1 + ref / neutral) * quantum / 2
    assert path_cost(costs, path, neutral, factor) <= ref + bound + 1e-12 * ref
    return path


@pytest.fixture(params=["default", "sweeps", "columns", "budget", "fresh", "table"])
def stage(request, monkeypatch):
    """Force one stage of the planner: the defaults, sweeps until settled (no repair), the column
    sweeps first of all, heap searches cut short after one cell (sweeping on in between), the plain
    A* fallback, or the predecessor-table walk from the first step."""
    if request.param == "sweeps":
        monkeypatch.setattr(planner, "_REPAIR_CELLS", 0)
    elif request.param == "columns":
        monkeypatch.setattr(planner, "_REPAIR_CELLS", 0)
        monkeypatch.setattr(planner, "_MAX_PAIRS", 30)
    elif request.param == "budget":
        monkeypatch.setattr(planner, "_REPAIR_CELLS", 10**9)
        monkeypatch.setattr(planner, "_REPAIR_POPS", 1)
    elif request.param == "fresh":
        monkeypatch.setattr(planner, "_REPAIR_CELLS", -1)
    elif request.param == "table":
        monkeypatch.setattr(planner, "_WALK_STEPS", 0)
        monkeypatch.setattr(planner, "_TABLE_CELLS", 10**9)
    return request.param


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


def test_planner_matches_the_exact_search_on_random_maps(stage):
    rng = np.random.default_rng(11)
    for _ in range(80):
        h, w = (int(v) for v in rng.integers(1, 28, 2))
        occ = rng.random((h, w)) < rng.uniform(0.0, 0.35)
        costs = inflation_costs(occ, 0.05, 0.0, float(rng.uniform(0.0, 0.3)), 10.0)
        if rng.random() < 0.4:
            costs[rng.random((h, w)) < 0.15] = 255
        start = (int(rng.integers(0, w)), int(rng.integers(0, h)))
        goal = (int(rng.integers(0, w)), int(rng.integers(0, h)))
        allow = bool(rng.random() < 0.7)
        blocked = costs[goal[1], goal[0]] >= 253 and not (allow and costs[goal[1], goal[0]] == 255)
        if blocked:
            with pytest.raises(PlanError, match="in an obstacle"):
                astar(costs, start, goal, allow_unknown=allow)
            continue
        check_plan(costs, start, goal, allow_unknown=allow)


def serpentine(n, gap, vertical):
    """Walls every 6 cells with a ``gap``-cell opening at alternate ends: the path winds n/6 times."""
    costs = np.zeros((n, n), dtype=np.uint8)
    for k, x in enumerate(range(3, n - 2, 6)):
        costs[:, x] = 254
        if k % 2:
            costs[:gap, x] = 0
        else:
            costs[-gap:, x] = 0
    return costs if vertical else np.ascontiguousarray(costs.T)


@pytest.mark.parametrize("vertical", [True, False])
def test_winding_detours_need_both_sweep_directions(stage, vertical):
    # a path that goes down, up, down...: row sweeps alone settle it one bend per pair; the column
    # sweeps (or the repair) must finish it. One-cell openings are what a coarse grid would close.
    costs = serpentine(48, 1, vertical)
    path = check_plan(costs, (0, 0), (47, 47))
    assert len(path) > 48 * 5  # it really winds


def test_spiral_and_narrow_doors(stage):
    # a spiral of walls, each opened by a single free cell: the only way in is the whole spiral
    n = 41
    costs = np.zeros((n, n), dtype=np.uint8)
    for k, r in enumerate(range(2, n // 2, 3)):
        lo, hi = r, n - 1 - r
        costs[lo, lo : hi + 1] = costs[hi, lo : hi + 1] = 254
        costs[lo : hi + 1, lo] = costs[lo : hi + 1, hi] = 254
        door = (lo, lo + 1 + k % (hi - lo - 1)) if k % 2 else (hi, hi - 1 - k % (hi - lo - 1))
        costs[door] = 0
    check_plan(costs, (0, 0), (n // 2, n // 2))
    # inflated cost gradients around the walls change nothing about validity or optimality
    grad = np.where(costs == 254, 254, (np.arange(n)[None, :] * 7 % 200)).astype(np.uint8)
    check_plan(grad, (0, n - 1), (n // 2, n // 2))


def test_a_goal_walled_off_or_in_an_unknown_pocket_has_no_path(stage):
    costs = np.zeros((30, 30), dtype=np.uint8)
    costs[10:20, 10] = costs[10:20, 19] = costs[10, 10:20] = costs[19, 10:20] = 254
    with pytest.raises(PlanError, match=r"no path from cell \(0, 0\) to cell \(15, 15\)"):
        astar(costs, (0, 0), (15, 15))
    costs[19, 15] = 255  # a door of unknown space: open by default, closed without allow_unknown
    check_plan(costs, (0, 0), (15, 15), allow_unknown=True)
    check_plan(costs, (0, 0), (15, 15), allow_unknown=False)


def test_large_costs_and_a_start_inside_an_obstacle(stage):
    rng = np.random.default_rng(2)
    costs = (rng.random((25, 25)) * 252).astype(np.uint8)
    costs[rng.random((25, 25)) < 0.2] = 254
    costs[24, 24] = 0
    # costs far above the defaults: the planner lowers its rounding scale, the path stays optimal
    check_plan(costs, (0, 0), (24, 24), neutral=1e6, factor=1e5, quantum=2.0**-16)
    costs[3, 3] = 254  # the robot's cell inflated to lethal: it still gets out
    check_plan(costs, (3, 3), (24, 24))
    assert astar(costs, (3, 3), (3, 3) if costs[3, 3] < 253 else (24, 24))[0] == (3, 3)


def test_a_bench_sized_office_is_planned_exactly():
    # the benchmark's kind of map, scaled down so the brute-force reference stays quick
    occ = np.zeros((120, 120), dtype=bool)
    occ[[0, -1], :] = occ[:, [0, -1]] = True
    for k in (30, 60, 90):
        occ[k, :] = True
        occ[k, k - 20 : k - 14] = False
        occ[:, k] |= np.arange(120) % 30 > 21
    costs = inflation_costs(occ, 0.05, 0.12, 0.5, 10.0)
    check_plan(costs, (5, 5), (114, 114))
    check_plan(costs, (114, 5), (5, 114))
