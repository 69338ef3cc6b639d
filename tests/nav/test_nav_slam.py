"""The mapper: with drifting odometry, scan matching keeps the map true to the room."""

from __future__ import annotations

import math

import numpy as np

from ninjemys.nav.slam import ParticleMapper, SlamParams
from ninjemys.tf2.math import se2_compose, se2_inverse


def test_compose_inverse_roundtrip():
    a = (1.0, -2.0, 0.7)
    b = (0.3, 0.4, -1.2)
    back = se2_compose(se2_inverse(a), se2_compose(a, b))
    assert np.allclose(back, b)


def test_map_agrees_with_ground_truth_despite_drift(room, laser):
    angles, cast = laser
    rng = np.random.default_rng(7)
    mapper = ParticleMapper(
        SlamParams(xmin=-1, ymin=-1, xmax=7, ymax=7, maxUrange=4.5, maxRange=5.0, particles=8)
    )
    truth = np.array([1.0, 1.0, 0.0])
    odom = truth.copy()
    plan = [(0.05, 0.0)] * 60 + [(0.0, math.pi / 40)] * 20 + [(0.05, 0.0)] * 50 + [(0.0, math.pi / 40)] * 20
    plan += [(0.05, 0.0)] * 55
    worst_raw = worst_slam = 0.0
    for fwd, turn in plan:
        truth = np.array(se2_compose(tuple(truth), (fwd, 0.0, turn)))
        # odometry that over-reads distance by 8 % and turns 6 % too far: drift grows
        odom = np.array(se2_compose(tuple(odom), (fwd * 1.08, 0.0, turn * 1.06 + rng.normal(0, 0.002))))
        ranges = cast(room, tuple(truth), angles, 5.0) + rng.normal(0, 0.01, len(angles))
        ranges[::17] = np.nan
        if mapper.should_process(tuple(odom)):
            mapper.process(tuple(odom), ranges, angles, range_max=5.0)
        corrected = se2_compose(mapper.map_to_odom(tuple(odom)), tuple(odom))
        worst_raw = max(worst_raw, math.hypot(odom[0] - truth[0], odom[1] - truth[1]))
        worst_slam = max(worst_slam, math.hypot(corrected[0] - truth[0], corrected[1] - truth[1]))
    assert worst_raw > 0.3  # the odometry alone drifts far
    assert mapper.resamples > 0  # the weights degenerated and the particles were drawn again
    assert len({id(q.hits) for q in mapper.particles}) == len(mapper.particles)  # each its own map
    assert worst_slam < 0.12
    built = mapper.occupancy()
    p = mapper.params
    # compare on every cell the mapper knows with the truth (room cells shifted by the map's origin)
    off = int(round(1 / p.delta))
    truth_grid = np.full(built.shape, -1, dtype=np.int8)
    truth_grid[off : off + room.height, off : off + room.width] = np.where(room.data >= 50, 100, 0)
    known = (built >= 0) & (truth_grid >= 0)
    agree = (built[known] == truth_grid[known]).mean()
    assert known.sum() > 2000
    assert agree >= 0.95


def test_a_featureless_corridor_does_not_pull_the_pose_along_it(laser):
    """Walls that constrain only the across-corridor position: there the motion model holds the pose.
    The matcher this filter replaced took the best score anywhere in its window: the beams that end
    past the mapped part of the walls pulled it back towards the map, 3.2 m over these 6 m."""
    from ninjemys.maps.mapfile import GridMap

    angles, cast = laser
    data = np.zeros((40, 400), dtype=np.int8)  # 20 x 2 m, walls along its length only
    data[:2, :] = data[-2:, :] = 100
    corridor = GridMap(data, 0.05, (0.0, -1.0, 0.0))
    rng = np.random.default_rng(3)
    params = SlamParams(xmin=-1, ymin=-2, xmax=21, ymax=2, maxUrange=3.0, maxRange=3.5, particles=4)
    mapper = ParticleMapper(params)
    worst = 0.0
    for i in range(60):  # 6 m along the middle, perfect odometry, ends of the corridor out of range
        pose = (2.0 + 0.1 * i, 0.0, 0.0)
        ranges = cast(corridor, pose, angles, 3.5) + rng.normal(0, 0.01, len(angles))
        if mapper.should_process(pose):
            mapper.process(pose, ranges, angles, range_max=3.5)
        est = se2_compose(mapper.map_to_odom(pose), pose)
        worst = max(worst, math.hypot(est[0] - pose[0], est[1] - pose[1]))
    assert worst < 0.25


def test_entropy_of_the_particle_weights():
    mapper = ParticleMapper(SlamParams(xmin=-1, ymin=-1, xmax=1, ymax=1, particles=4))
    assert mapper.entropy() == 0.0  # no particles before the first scan
    angles = np.linspace(-math.pi, math.pi, 36, endpoint=False)
    mapper.process((0.0, 0.0, 0.0), np.full(36, 0.5), angles, range_max=5.0)
    assert math.isclose(mapper.entropy(), math.log(4))  # all alike
    for i, q in enumerate(mapper.particles):
        q.logw = 0.0 if i == 0 else -50.0
    assert mapper.entropy() < 1e-6  # one particle holds the weight


def test_parameters_out_of_range_are_named_and_ignored():
    p = SlamParams()
    rejected = p.update({"delta": 0.0, "particles": 0, "srr": 0.05, "xmin": 5.0, "xmax": 2.0, "lskip": -1})
    names = [name for name, _ in rejected]
    assert names == ["delta", "lskip", "particles", "xmax"]
    assert "must be > 0, got 0.0; using 0.05" in rejected[0][1]
    assert p.delta == 0.05 and p.particles == 30 and p.srr == 0.05 and p.lskip == 0
    assert (p.xmin, p.xmax) == (-15.0, 15.0)


def test_a_small_start_map_grows_to_what_the_laser_sees(laser):
    """turtlebot's gmapping launch file and its copies (ROS By Example, the ros_exploring book) start
    with ``xmin -1 .. xmax 1``: GMapping enlarges the map 10 m past any cell a scan writes outside it,
    and slam_gmapping publishes the grown map with its new origin. Ours stayed a 2 x 2 m map."""
    from ninjemys.maps.mapfile import GridMap

    from .conftest import room_map

    angles, cast = laser
    room = GridMap(room_map().data, 0.05, (-3.0, -3.0, 0.0))  # 6 x 6 m, the robot in its middle
    params = SlamParams(xmin=-1, ymin=-1, xmax=1, ymax=1, maxUrange=4.5, maxRange=5.0, particles=4)
    mapper = ParticleMapper(params)
    mapper.process((0.0, 0.0, 0.0), cast(room, (0.0, 0.0, 0.0), angles, 5.0), angles, range_max=5.0)
    # 10 m past the walls' returns (about 2.9 m out) on every side, on the start map's cell grid
    bounds = (params.xmin, params.ymin, params.xmax, params.ymax)
    assert all(12.8 <= abs(b) <= 13.0 for b in bounds), bounds
    assert all(abs((b - 1) / params.delta - round((b - 1) / params.delta)) < 1e-6 for b in bounds)
    grid = mapper.occupancy()
    size = (
        round((params.ymax - params.ymin) / params.delta),
        round((params.xmax - params.xmin) / params.delta),
    )
    assert grid.shape == (mapper.height, mapper.width) == size

    def cell(v: float, low: float) -> int:
        return int((v - low) / params.delta)

    # along +x and -y from the robot: free from the start map's edge out to the wall, then the wall
    row = grid[cell(0.0, params.ymin), cell(1.0, params.xmin) : cell(3.0, params.xmin)]
    col = grid[cell(-3.0, params.ymin) : cell(-1.0, params.ymin), cell(0.0, params.xmin)][::-1]
    for line in (row, col):
        assert (line[: cell(2.85, 1.0)] == 0).all() and 100 in line[cell(2.85, 1.0) :], line
    # a second scan from the same place grows nothing: the bounds stay
    mapper.process((0.6, 0.0, 0.0), cast(room, (0.6, 0.0, 0.0), angles, 5.0), angles, range_max=5.0)
    assert (params.xmin, params.ymin, params.xmax, params.ymax) == bounds and grid.shape == size
