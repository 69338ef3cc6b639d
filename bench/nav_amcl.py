"""One amcl update (motion + likelihood-field sensor model + KLD resampling + estimate) with 500
particles and 60 beams, on the office map (the issue's target: at most 20 ms); then the one-off first
update after ``global_localization`` with the shipped ``global_candidates`` (100000 candidates weighed,
5000 kept), which has no target of its own.

Debian ships no amcl, so there is no ROS 1 run beside ours; the reference printed is the issue's
target for ROS 1's C++ amcl. Run alone: ``.venv/bin/python bench/nav_amcl.py``.
"""

from __future__ import annotations

import math
import os
import time
from pathlib import Path

import numpy as np

from ninjemys.maps.mapfile import load_map
from ninjemys.nav.amcl import AMCLParams, ParticleFilter

TARGET_MS = 20.0
MAP = Path(__file__).resolve().parents[1] / "src/ninjemys/packages/share/puzzlebot_sim/maps/office.yaml"


def cast(grid, pose: tuple[float, float, float], angles: np.ndarray, max_range: float) -> np.ndarray:
    """Ranges from ``pose`` to the first occupied cell (a plain numpy ray march)."""
    t = np.arange(0.0, max_range, grid.resolution / 4)
    xs = pose[0] + np.cos(pose[2] + angles)[:, None] * t
    ys = pose[1] + np.sin(pose[2] + angles)[:, None] * t
    ix = np.floor((xs - grid.origin[0]) / grid.resolution).astype(int)
    iy = np.floor((ys - grid.origin[1]) / grid.resolution).astype(int)
    inside = (ix >= 0) & (ix < grid.width) & (iy >= 0) & (iy < grid.height)
    occ = np.ones(xs.shape, dtype=bool)
    occ[inside] = grid.data[iy[inside], ix[inside]] >= 50
    return np.where(occ.any(axis=1), t[np.argmax(occ, axis=1)], np.inf)


def main() -> None:
    print(f"load average {os.getloadavg()[0]:.2f} (2 cores shared)")
    grid = load_map(MAP)
    params = AMCLParams(min_particles=500, max_particles=500, laser_max_beams=60, kld_err=0.01)
    pf = ParticleFilter(grid, params, seed=1)
    pf.init_gaussian((0.0, 0.0, 0.0), 0.1, 0.1, 0.05)
    angles = np.linspace(-math.pi, math.pi, 360, endpoint=False)
    parts = {"motion": [], "sensor": [], "resample": [], "estimate": [], "total": []}
    odom = (0.0, 0.0, 0.0)
    for i in range(30):
        new = (odom[0] + 0.1, odom[1], 0.0)  # along the office corridor
        ranges = cast(grid, new, angles, 12.0)
        t0 = time.perf_counter()
        pf.motion_update(odom, new)
        t1 = time.perf_counter()
        pf.sensor_update(ranges, angles, 12.0)
        t2 = time.perf_counter()
        pf.resample()
        t3 = time.perf_counter()
        pf.estimate()
        t4 = time.perf_counter()
        odom = new
        if i >= 5:
            for key, dt in zip(parts, (t1 - t0, t2 - t1, t3 - t2, t4 - t3, t4 - t0), strict=True):
                parts[key].append(dt * 1000)
    n = len(pf.poses)
    line = ", ".join(f"{k} {np.median(v):.2f}" for k, v in parts.items())
    best = float(np.median(parts["total"]))
    print(
        f"amcl update, {n} particles x 60 beams: {line} ms (median)  | target {TARGET_MS:.0f} ms  ratio {best / TARGET_MS:.2f}"
    )
    spread = AMCLParams(max_particles=5000, global_candidates=100000, laser_max_beams=60, kld_err=0.05)
    gl = ParticleFilter(grid, spread, seed=2)
    ranges = cast(grid, (1.5, 0.2, 0.3), angles, 12.0)
    times = []
    for _ in range(5):
        gl.init_global()
        t0 = time.perf_counter()
        gl.sensor_update(ranges, angles, 12.0)
        gl.estimate()
        gl.resample()
        times.append((time.perf_counter() - t0) * 1000)
    print(
        f"first update after global_localization, {spread.global_candidates} candidates -> "
        f"{spread.max_particles} particles x 60 beams: {np.median(times):.0f} ms (median of 5, once per call)"
    )


if __name__ == "__main__":
    main()
