"""costmap_2d's layers and values: static, obstacle marking/clearing, inflation, the publisher table."""

from __future__ import annotations

import math

import numpy as np

from ninjemys.nav.costmap import (
    INSCRIBED,
    LETHAL,
    NO_INFORMATION,
    Costmap,
    CostmapParams,
    distance_transform,
    footprint_radii,
    inflation_costs,
    parse_footprint,
    to_occupancy,
)


def test_occupancy_table_matches_costmap_2d():
    costs = np.arange(256, dtype=np.uint8)
    occ = to_occupancy(costs)
    assert occ[0] == 0 and occ[253] == 99 and occ[254] == 100 and occ[255] == -1
    assert occ[1] == 1 and occ[252] == 98
    assert np.all(np.diff(occ[1:253].astype(int)) >= 0)
    assert occ[1:253].min() >= 1 and occ[1:253].max() <= 98


def test_distance_transform_is_exact_within_reach():
    rng = np.random.default_rng(3)
    mask = rng.random((40, 50)) < 0.02
    d = distance_transform(mask, 12)
    pts = np.argwhere(mask)
    yy, xx = np.mgrid[0:40, 0:50]
    brute = np.sqrt((yy[..., None] - pts[:, 0]) ** 2 + (xx[..., None] - pts[:, 1]) ** 2).min(axis=2)
    near = brute <= 12
    assert np.allclose(d[near], brute[near])
    assert np.all(d[~near] > 12)


def test_inflation_uses_costmap_2d_cost_function():
    lethal = np.zeros((41, 41), dtype=bool)
    lethal[20, 20] = True
    res, inscribed, radius, scale = 0.05, 0.1, 0.5, 5.0
    cost = inflation_costs(lethal, res, inscribed, radius, scale)
    assert cost[20, 20] == LETHAL
    assert cost[20, 22] == INSCRIBED  # 0.10 m away: inside the inscribed radius
    d = 0.25
    assert cost[20, 25] == int(252 * math.exp(-scale * (d - inscribed)))
    assert cost[20, 30] == int(252 * math.exp(-scale * (0.5 - inscribed)))
    assert cost[20, 31] == 0  # beyond the inflation radius


def test_footprint_radii():
    assert footprint_radii(None, 0.2) == (0.2, 0.2)
    inscribed, circ = footprint_radii(
        parse_footprint("[[0.1, 0.08], [-0.1, 0.08], [-0.1, -0.08], [0.1, -0.08]]"), 0
    )
    assert math.isclose(inscribed, 0.08) and math.isclose(circ, math.hypot(0.1, 0.08))


def test_static_layer_unknown_and_lethal():
    data = np.array([[0, 100, -1, 99]], dtype=np.int8)
    cm = Costmap(CostmapParams(inflation_radius=0.0, robot_radius=0.0, track_unknown_space=True))
    cm.set_static_map(data, 0.05, 0.0, 0.0)
    assert cm.costs.tolist() == [[0, LETHAL, NO_INFORMATION, 0]]
    cm = Costmap(CostmapParams(inflation_radius=0.0, robot_radius=0.0, track_unknown_space=False))
    cm.set_static_map(data, 0.05, 0.0, 0.0)
    assert cm.costs.tolist() == [[0, LETHAL, 0, 0]]


def test_obstacle_layer_marks_clears_and_skips_nan():
    cm = Costmap(
        CostmapParams(inflation_radius=0.0, robot_radius=0.0, obstacle_range=2.0, raytrace_range=3.0)
    )
    cm.set_static_map(np.zeros((60, 60), dtype=np.int8), 0.05, 0.0, 0.0)
    cm.add_scan(0.525, 1.525, np.array([0.0]), np.array([1.0]), 5.0)
    cm.update()
    assert cm.cost_at(1.525, 1.525) == LETHAL
    cm.add_scan(0.525, 1.525, np.array([0.0, 0.1, 0.2]), np.array([np.inf, np.nan, 2.8]), 5.0)
    cm.update()
    assert cm.cost_at(1.525, 1.525) == 0  # an inf reading clears along its ray
    assert int((cm.costs == LETHAL).sum()) == 0  # 2.8 m is beyond obstacle_range: clears, no mark
    cm.add_scan(0.525, 1.525, np.array([0.0]), np.array([1.0]), 5.0)
    cm.clear_obstacles()
    assert int(cm.update().max()) == 0


def test_rolling_window_follows_the_robot_and_keeps_marks():
    cm = Costmap(
        CostmapParams(rolling_window=True, width=2.0, height=2.0, inflation_radius=0.0, robot_radius=0.0)
    )
    cm.update_origin(0.0, 0.0)
    cm.add_scan(0.0, 0.0, np.array([0.0]), np.array([0.5]), 5.0)
    cm.update()
    assert cm.cost_at(0.51, 0.01) == LETHAL
    cm.update_origin(0.3, 0.0)
    cm.update()
    assert cm.cost_at(0.51, 0.01) == LETHAL
    assert math.isclose(cm.origin_x, -0.7, abs_tol=1e-9)
    static = np.zeros((100, 100), dtype=np.int8)
    static[:, 50] = 100
    cm.set_static_map(static, 0.05, -2.5, -2.5)
    cm.update()
    assert cm.cost_at(0.01, 0.3) == LETHAL  # the static wall at x = 0 shows in the window


def reference_clear_cells(
    cm: Costmap, sx: float, sy: float, angles: np.ndarray, ranges: np.ndarray, rmax: float
):
    """The cells the obstacle layer clears, from the rays x steps grid (the straightforward form)."""
    p = cm.params
    keep = ~np.isnan(ranges)
    ranges, angles = ranges[keep], angles[keep]
    beyond = ~np.isfinite(ranges) | (ranges >= rmax)
    clear_len = np.minimum(np.where(beyond, p.raytrace_range, ranges), p.raytrace_range)
    step = cm.resolution / 2
    t = np.arange(int(math.ceil(p.raytrace_range / step)) + 1) * step
    valid = t[None, :] < (clear_len[:, None] - cm.resolution * 0.5)
    xs = sx + np.cos(angles)[:, None] * t[None, :]
    ys = sy + np.sin(angles)[:, None] * t[None, :]
    cx = np.floor((xs[valid] - cm.origin_x) / cm.resolution).astype(int)
    cy = np.floor((ys[valid] - cm.origin_y) / cm.resolution).astype(int)
    inside = (cx >= 0) & (cx < cm.size_x) & (cy >= 0) & (cy < cm.size_y)
    return set(zip(cy[inside].tolist(), cx[inside].tolist(), strict=True))


def test_incremental_update_equals_a_full_recompute(room, laser):
    """Scans from many poses (marks appear and are cleared again), people-like blobs, a cleared
    square: after every step the costs equal those of a costmap rebuilt from scratch."""
    angles, cast = laser
    params = dict(robot_radius=0.16, inflation_radius=0.4, cost_scaling_factor=8.0, track_unknown_space=True)
    static = room.data.copy()
    static[100:110, 10:20] = -1  # an unknown patch
    cm = Costmap(CostmapParams(**params))
    cm.set_static_map(static, room.resolution, 0.0, 0.0)
    rng = np.random.default_rng(5)
    for i in range(40):
        pose = (rng.uniform(0.5, 5.5), rng.uniform(0.5, 5.5), rng.uniform(-math.pi, math.pi))
        ranges = cast(room, pose, angles, 5.0)
        ranges = ranges - rng.uniform(0.0, 0.3, ranges.shape) * (rng.random(ranges.shape) < 0.2)  # "people"
        ranges[rng.random(ranges.shape) < 0.02] = np.nan
        before = cm.obstacles.copy()
        cm.add_scan(pose[0], pose[1], pose[2] + angles, ranges, 5.0)
        cleared = reference_clear_cells(cm, pose[0], pose[1], pose[2] + angles, ranges, 5.0)
        for cy, cx in cleared:
            before[cy, cx] = 0
        marked = cm.obstacles == LETHAL
        assert np.array_equal(cm.obstacles[~marked], before[~marked])  # cleared exactly those cells
        if i == 25:
            cm.obstacles[20:60, 20:60] = 0  # what a clearing recovery does
        fresh = Costmap(CostmapParams(**params))
        fresh.set_static_map(static, room.resolution, 0.0, 0.0)
        fresh.obstacles = cm.obstacles.copy()
        old = cm.costs
        assert np.array_equal(cm.update(), fresh.update()), i
        assert old is cm.costs or not np.shares_memory(old, cm.costs)  # replaced, never edited
