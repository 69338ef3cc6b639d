"""Shared pieces of the navigation tests: a small grid world and a numpy laser for it."""

from __future__ import annotations

import math

import numpy as np
import pytest

from ninjemys.nav.mapio import GridMap


def room_map(size: float = 6.0, res: float = 0.05) -> GridMap:
    """A square room with walls and two boxes (the shapes break the symmetry for localization)."""
    n = int(round(size / res))
    data = np.zeros((n, n), dtype=np.int8)
    data[:2, :] = data[-2:, :] = data[:, :2] = data[:, -2:] = 100
    data[30:45, 90:105] = 100  # a box
    data[80:90, 70:110] = 100  # a long low box
    data[60:62, 2:50] = 100  # a wall stub from the left
    return GridMap(data, res, (0.0, 0.0, 0.0))


def cast(grid: GridMap, pose: tuple[float, float, float], angles: np.ndarray, max_range: float) -> np.ndarray:
    """Ranges from ``pose`` along ``angles`` (robot frame) to the first occupied cell, or inf."""
    step = grid.resolution / 4
    t = np.arange(0.0, max_range, step)
    world = pose[2] + angles
    xs = pose[0] + np.cos(world)[:, None] * t[None, :]
    ys = pose[1] + np.sin(world)[:, None] * t[None, :]
    ix = np.floor((xs - grid.origin[0]) / grid.resolution).astype(int)
    iy = np.floor((ys - grid.origin[1]) / grid.resolution).astype(int)
    inside = (ix >= 0) & (ix < grid.width) & (iy >= 0) & (iy < grid.height)
    occ = np.ones(xs.shape, dtype=bool)
    occ[inside] = grid.data[iy[inside], ix[inside]] >= 50
    first = np.argmax(occ, axis=1)
    hit = occ.any(axis=1)
    return np.where(hit, t[first], np.inf)


@pytest.fixture
def room() -> GridMap:
    return room_map()


@pytest.fixture
def laser():
    """(angles, cast) for a 360-beam laser with 5 m range."""
    angles = np.linspace(-math.pi, math.pi, 360, endpoint=False)
    return angles, cast
