"""Mapping for slam_gmapping: scan matching against the map built so far, and a hit/visit grid.

No ROS in here. This is not a Rao-Blackwellized particle filter: it keeps one trajectory, which is
enough to correct odometry drift in maps without large loops (the shipped worlds). Each processed
scan (after the robot moved ``linearUpdate`` metres or turned ``angularUpdate`` radians, as gmapping
decides) goes through:

1. prediction: the last corrected pose composed with the odometry step since then;
2. correlative scan matching: the beam endpoints are scored against a likelihood field of the map's
   occupied cells (``exp(-d^2 / 2 sigma^2)``) over a grid of poses around the prediction, coarse then
   fine (``srr``-free: the search window is ``search_xy`` x ``search_th``);
3. the map update: every beam counts a visit for the cells along it and a hit for its end cell, as
   gmapping's grid does; a cell is occupied (100) when hits / visits > ``occ_thresh``, free (0) when
   visited, unknown (-1) otherwise.

The correction ``map -> odom`` is the matched pose composed with the inverse of the odometry pose.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

import numpy as np

from ninjemys.nav.costmap import distance_transform


def compose(a: tuple[float, float, float], b: tuple[float, float, float]) -> tuple[float, float, float]:
    """Pose ``a`` then pose ``b`` expressed in ``a``'s frame."""
    c, s = math.cos(a[2]), math.sin(a[2])
    return a[0] + c * b[0] - s * b[1], a[1] + s * b[0] + c * b[1], _wrap(a[2] + b[2])


def inverse(a: tuple[float, float, float]) -> tuple[float, float, float]:
    c, s = math.cos(a[2]), math.sin(a[2])
    return -c * a[0] - s * a[1], s * a[0] - c * a[1], _wrap(-a[2])


def _wrap(a: float) -> float:
    return (a + math.pi) % (2 * math.pi) - math.pi


@dataclass
class SlamParams:
    """slam_gmapping's parameters that this mapper uses (same names)."""

    delta: float = 0.05
    xmin: float = -15.0
    ymin: float = -15.0
    xmax: float = 15.0
    ymax: float = 15.0
    maxUrange: float = 4.0  # noqa: N815 - gmapping's parameter names
    maxRange: float = 5.0  # noqa: N815
    linearUpdate: float = 0.2  # noqa: N815
    angularUpdate: float = 0.2  # noqa: N815
    occ_thresh: float = 0.25
    sigma: float = 0.05
    search_xy: float = 0.15
    search_th: float = 0.12
    max_beams: int = 120

    def update(self, values: dict[str, object]) -> None:
        for f in fields(self):
            if f.name in values:
                setattr(self, f.name, type(getattr(self, f.name))(values[f.name]))  # type: ignore[call-arg]


class ScanMatchMapper:
    """One trajectory's map: feed odometry poses and scans to :meth:`process`."""

    def __init__(self, params: SlamParams | None = None) -> None:
        self.params = p = params or SlamParams()
        self.width = int(round((p.xmax - p.xmin) / p.delta))
        self.height = int(round((p.ymax - p.ymin) / p.delta))
        self.hits = np.zeros((self.height, self.width), dtype=np.int32)
        self.visits = np.zeros((self.height, self.width), dtype=np.int32)
        self.pose: tuple[float, float, float] | None = None  # corrected pose of the last scan (map frame)
        self.odom: tuple[float, float, float] | None = None  # odometry pose of the last scan
        self.scans = 0

    # -- outputs ----------------------------------------------------------------------------------

    def occupancy(self) -> np.ndarray:
        """int8 (height, width) map as slam_gmapping publishes it."""
        out = np.full(self.hits.shape, -1, dtype=np.int8)
        seen = self.visits > 0
        ratio = np.zeros(self.hits.shape)
        ratio[seen] = self.hits[seen] / self.visits[seen]
        out[seen] = 0
        out[seen & (ratio > self.params.occ_thresh)] = 100
        return out

    def map_to_odom(self, odom_pose: tuple[float, float, float]) -> tuple[float, float, float]:
        """The correction for an odometry pose: map->odom such that map->odom->base = corrected."""
        if self.pose is None or self.odom is None:
            return (0.0, 0.0, 0.0)
        return compose(self.pose, inverse(self.odom))

    # -- processing -------------------------------------------------------------------------------

    def should_process(self, odom_pose: tuple[float, float, float]) -> bool:
        if self.odom is None:
            return True
        step = compose(inverse(self.odom), odom_pose)
        return (
            math.hypot(step[0], step[1]) >= self.params.linearUpdate
            or abs(step[2]) >= self.params.angularUpdate
        )

    def process(
        self,
        odom_pose: tuple[float, float, float],
        ranges: np.ndarray,
        angles: np.ndarray,
        laser_pose: tuple[float, float, float] = (0.0, 0.0, 0.0),
        range_max: float | None = None,
    ) -> tuple[float, float, float]:
        """Match one scan taken at ``odom_pose`` (laser angles in the laser frame), update the map,
        and return the corrected pose of the base in the map frame."""
        p = self.params
        ranges = np.asarray(ranges, dtype=float)
        angles = np.asarray(angles, dtype=float)
        limit = min(p.maxRange, range_max) if range_max else p.maxRange
        ok = ~np.isnan(ranges) & ~np.isneginf(ranges)  # NaN: no reading; -inf: closer than range_min
        ranges, angles = ranges[ok], angles[ok]
        ranges = np.where(np.isfinite(ranges), ranges, limit)  # +inf: no return, free up to maxUrange
        # beam endpoints in the base frame
        lx, ly, lth = laser_pose
        bx = lx + ranges * np.cos(lth + angles)
        by = ly + ranges * np.sin(lth + angles)
        if self.pose is None or self.odom is None:
            pose = odom_pose
        else:
            predicted = compose(self.pose, compose(inverse(self.odom), odom_pose))
            hit = ranges < min(limit, p.maxUrange)
            pose = self._match(predicted, bx[hit], by[hit]) if self.scans >= 1 else predicted
        self._integrate(pose, (lx, ly, lth), ranges, angles, limit)
        self.pose, self.odom = pose, odom_pose
        self.scans += 1
        return pose

    def _field(self) -> np.ndarray:
        occupied = self.occupancy() == 100
        reach = max(2, int(math.ceil(4 * self.params.sigma / self.params.delta)))
        d = distance_transform(occupied, reach) * self.params.delta
        return np.exp(-(d * d) / (2 * self.params.sigma**2))

    def _match(
        self, guess: tuple[float, float, float], bx: np.ndarray, by: np.ndarray
    ) -> tuple[float, float, float]:
        p = self.params
        if bx.size < 10:
            return guess
        if bx.size > p.max_beams:
            take = np.linspace(0, bx.size - 1, p.max_beams).astype(np.int64)
            bx, by = bx[take], by[take]
        field = self._field()
        best = guess
        xy, th = p.search_xy, p.search_th
        best_score = self._score(field, np.array([guess]), bx, by)[0]
        for _ in range(3):  # coarse to fine around the best so far
            dx = np.linspace(-xy, xy, 7)
            dth = np.linspace(-th, th, 7)
            gx, gy, gt = np.meshgrid(dx, dx, dth, indexing="ij")
            cands = np.column_stack([best[0] + gx.ravel(), best[1] + gy.ravel(), best[2] + gt.ravel()])
            scores = self._score(field, cands, bx, by)
            i = int(np.argmax(scores))
            if scores[i] > best_score:
                best_score = float(scores[i])
                best = (float(cands[i, 0]), float(cands[i, 1]), _wrap(float(cands[i, 2])))
            xy, th = xy / 3.0, th / 3.0
        return best

    def _score(self, field: np.ndarray, poses: np.ndarray, bx: np.ndarray, by: np.ndarray) -> np.ndarray:
        p = self.params
        c, s = np.cos(poses[:, 2])[:, None], np.sin(poses[:, 2])[:, None]
        mx = poses[:, 0:1] + c * bx - s * by
        my = poses[:, 1:2] + s * bx + c * by
        ix = np.floor((mx - p.xmin) / p.delta).astype(np.int64)
        iy = np.floor((my - p.ymin) / p.delta).astype(np.int64)
        inside = (ix >= 0) & (ix < self.width) & (iy >= 0) & (iy < self.height)
        vals = np.zeros(mx.shape)
        vals[inside] = field[iy[inside], ix[inside]]
        return vals.sum(axis=1)

    def _integrate(
        self,
        pose: tuple[float, float, float],
        laser: tuple[float, float, float],
        ranges: np.ndarray,
        angles: np.ndarray,
        limit: float,
    ) -> None:
        p = self.params
        sensor = compose(pose, laser)
        usable = np.minimum(ranges, p.maxUrange)
        hit = ranges < min(limit, p.maxUrange)
        world = sensor[2] + angles
        step = p.delta / 2
        n = int(math.ceil(p.maxUrange / step)) + 1
        t = np.arange(n) * step
        along = t[None, :] < (usable[:, None] - p.delta * 0.5)
        xs = sensor[0] + np.cos(world)[:, None] * t[None, :]
        ys = sensor[1] + np.sin(world)[:, None] * t[None, :]
        ix = np.floor((xs[along] - p.xmin) / p.delta).astype(np.int64)
        iy = np.floor((ys[along] - p.ymin) / p.delta).astype(np.int64)
        flat = self._flat_unique(ix, iy)
        self.visits.ravel()[flat] += 1
        # the hit cell is taken half a cell past the return, inside the surface it came from
        ex = sensor[0] + np.cos(world[hit]) * (ranges[hit] + p.delta / 2)
        ey = sensor[1] + np.sin(world[hit]) * (ranges[hit] + p.delta / 2)
        ix = np.floor((ex - p.xmin) / p.delta).astype(np.int64)
        iy = np.floor((ey - p.ymin) / p.delta).astype(np.int64)
        flat = self._flat_unique(ix, iy)
        self.visits.ravel()[flat] += 1
        self.hits.ravel()[flat] += 1

    def _flat_unique(self, ix: np.ndarray, iy: np.ndarray) -> np.ndarray:
        inside = (ix >= 0) & (ix < self.width) & (iy >= 0) & (iy < self.height)
        return np.unique(iy[inside] * self.width + ix[inside])
