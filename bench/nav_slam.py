"""slam_gmapping's filter on a drive down the office corridor and back: milliseconds per processed
scan, worst pose error and agreement with the ground-truth map, for 1, 8 (the shipped
``gmapping_params.yaml``) and 30 (gmapping's default) particles.

Odometry over-reads distance by 5 % and turns 4 % too far, and the laser has 1 cm noise. Debian
ships no gmapping, so no ROS 1 run sits beside ours. The reference printed is the odometry alone,
the error that the filter has to remove. Run alone: ``.venv/bin/python bench/nav_slam.py``.
"""

from __future__ import annotations

import math
import os
import time

import numpy as np

from nav_amcl import MAP, cast  # the office map and its plain numpy ray march
from ninjemys.maps.mapfile import load_map
from ninjemys.nav.slam import ParticleMapper, SlamParams, compose


def drive() -> list[tuple[float, float]]:
    """(forward m, turn rad) steps of 0.05 m / 0.1 rad: east 10 m, turn around, west 8 m."""
    return [(0.05, 0.0)] * 200 + [(0.0, math.pi / 30)] * 30 + [(0.05, 0.0)] * 160


def agreement(mapper: ParticleMapper, truth) -> float:
    """The share of cells known in both maps on which they agree (occupied or not), as the test."""
    p = mapper.params
    built = mapper.occupancy()
    rows, cols = np.nonzero(built >= 0)
    tc = np.floor((p.xmin + (cols + 0.5) * p.delta - truth.origin[0]) / truth.resolution).astype(int)
    tr = np.floor((p.ymin + (rows + 0.5) * p.delta - truth.origin[1]) / truth.resolution).astype(int)
    inside = (tc >= 0) & (tc < truth.width) & (tr >= 0) & (tr < truth.height)
    mine = built[rows[inside], cols[inside]] >= 50
    theirs = truth.data[tr[inside], tc[inside]]
    known = theirs >= 0
    return float(np.mean(mine[known] == (theirs[known] >= 50)))


def run(particles: int, truth, scans: list) -> tuple[float, float, float]:
    params = SlamParams(maxUrange=6.0, maxRange=12.0, particles=particles)
    mapper = ParticleMapper(params)
    angles = np.linspace(-math.pi, math.pi, 360, endpoint=False)
    spent, count, worst = 0.0, 0, 0.0
    for true_pose, odom, ranges in scans:
        if mapper.should_process(odom):
            start = time.perf_counter()
            mapper.process(odom, ranges, angles, range_max=12.0)
            spent += time.perf_counter() - start
            count += 1
        est = compose(mapper.map_to_odom(odom), odom)
        worst = max(worst, math.hypot(est[0] - true_pose[0], est[1] - true_pose[1]))
    return 1000.0 * spent / max(count, 1), worst, agreement(mapper, truth)


def main() -> None:
    print(f"load average {os.getloadavg()[0]:.2f} (2 cores shared)")
    truth = load_map(MAP)
    rng = np.random.default_rng(1)
    angles = np.linspace(-math.pi, math.pi, 360, endpoint=False)
    true_pose, odom = (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)
    scans, odom_worst = [], 0.0
    for fwd, turn in drive():
        true_pose = compose(true_pose, (fwd, 0.0, turn))
        odom = compose(odom, (fwd * 1.05, 0.0, turn * 1.04))
        ranges = cast(truth, true_pose, angles, 12.0) + rng.normal(0.0, 0.01, angles.size)
        scans.append((true_pose, odom, ranges))
        odom_worst = max(odom_worst, math.hypot(odom[0] - true_pose[0], odom[1] - true_pose[1]))
    print(f"reference, odometry alone: worst position error {odom_worst:.3f} m")
    for particles in (1, 8, 30):
        ms, worst, agree = run(particles, truth, scans)
        print(
            f"particles {particles:2d}: {ms:6.1f} ms per processed scan, worst position error "
            f"{worst:.3f} m ({worst / odom_worst:.2f} x odometry's), agreement {agree:.4f}"
        )


if __name__ == "__main__":
    main()
