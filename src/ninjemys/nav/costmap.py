"""costmap_2d in numpy: a layered cost grid with static, obstacle and inflation layers.

No ROS in here. Cell values are costmap_2d's: 0 free, 1..252 inflated, 253 inscribed (the robot's
centre there means a collision), 254 lethal, 255 no information. :func:`to_occupancy` maps them to
``nav_msgs/OccupancyGrid`` values exactly as costmap_2d's publisher does.

- The static layer takes an OccupancyGrid: values >= ``lethal_cost_threshold`` are lethal, -1 is
  unknown (255 with ``track_unknown_space``, else free), the rest free (``trinary_costmap``).
- The obstacle layer marks laser hits closer than ``obstacle_range`` and clears, by ray tracing, the
  cells between the sensor and each reading up to ``raytrace_range`` (readings at or beyond the
  sensor's maximum clear without marking; NaN readings are dropped).
- The inflation layer spreads cost around lethal cells with costmap_2d's function:
  ``253`` within the inscribed radius, ``(253 - 1) * exp(-cost_scaling_factor * (d - inscribed))``
  beyond it, up to ``inflation_radius``.

A rolling window (the local costmap) follows the robot by whole cells; what scrolled out is lost.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

FREE = 0
INSCRIBED = 253
LETHAL = 254
NO_INFORMATION = 255


def to_occupancy(costs: np.ndarray) -> np.ndarray:
    """costmap_2d's cost -> OccupancyGrid table: 0->0, 253->99, 254->100, 255->-1, 1..252 -> 1..98."""
    table = np.zeros(256, dtype=np.int8)
    table[1:253] = 1 + (97 * (np.arange(1, 253) - 1)) // 251
    table[253] = 99
    table[254] = 100
    table[255] = -1
    return table[costs]


def distance_transform(mask: np.ndarray, max_cells: int) -> np.ndarray:
    """Euclidean distance in cells from each cell to the nearest True cell of ``mask``, capped.

    Exact within ``max_cells`` (anything farther reads ``max_cells + 1``): a row pass gives the
    horizontal distance to the nearest marked cell in the row (running max/min of indices), then a
    column pass takes the minimum of ``dx^2 + dy^2`` over the rows within reach.
    """
    h, w = mask.shape
    big = max_cells + 1
    if not mask.any():
        return np.full(mask.shape, float(big))
    idx = np.arange(w)
    left = np.where(mask, idx, -(10**6))
    left = np.maximum.accumulate(left, axis=1)
    right = np.where(mask, idx, 10**7)
    right = np.minimum.accumulate(right[:, ::-1], axis=1)[:, ::-1]
    dx = np.minimum(idx - left, right - idx).astype(np.float64)
    np.minimum(dx, big, out=dx)
    d2 = dx * dx
    best = d2.copy()
    for dy in range(1, min(max_cells, h - 1) + 1):
        add = float(dy * dy)
        np.minimum(best[dy:], d2[:-dy] + add, out=best[dy:])
        np.minimum(best[:-dy], d2[dy:] + add, out=best[:-dy])
    out = np.sqrt(best)
    np.minimum(out, big, out=out)
    return out


def inflation_costs(
    lethal: np.ndarray, resolution: float, inscribed_radius: float, inflation_radius: float, scaling: float
) -> np.ndarray:
    """The inflation layer's costs (uint8) for a lethal mask, with costmap_2d's cost function."""
    reach = max(0, int(math.ceil(inflation_radius / resolution)))
    dist = distance_transform(lethal, reach) * resolution
    factor = np.exp(-scaling * (dist - inscribed_radius))
    cost = ((INSCRIBED - 1) * factor).astype(np.uint8)
    cost[dist <= inscribed_radius] = INSCRIBED
    cost[dist > inflation_radius] = FREE
    cost[lethal] = LETHAL
    return cost


def footprint_radii(footprint: list[tuple[float, float]] | None, robot_radius: float) -> tuple[float, float]:
    """(inscribed, circumscribed) radius of a footprint polygon, or of a round robot."""
    if not footprint:
        return robot_radius, robot_radius
    pts = np.asarray(footprint, dtype=float)
    circ = float(np.hypot(pts[:, 0], pts[:, 1]).max())
    inscribed = math.inf
    for (x1, y1), (x2, y2) in zip(pts, np.roll(pts, -1, axis=0), strict=True):
        dx, dy = x2 - x1, y2 - y1
        seg = dx * dx + dy * dy
        t = 0.0 if seg == 0 else max(0.0, min(1.0, -(x1 * dx + y1 * dy) / seg))
        inscribed = min(inscribed, math.hypot(x1 + t * dx, y1 + t * dy))
    return float(inscribed), circ


def parse_footprint(value: object) -> list[tuple[float, float]]:
    """A footprint parameter (a list of [x, y], or costmap_2d's string form "[[x, y], ...]")."""
    if isinstance(value, str):
        import yaml

        value = yaml.safe_load(value)
    if not isinstance(value, list) or len(value) < 3:
        raise ValueError(f"footprint must be a list of at least 3 [x, y] points, got {value!r}")
    points = []
    for p in value:
        if not isinstance(p, list | tuple) or len(p) != 2:
            raise ValueError(f"footprint point {p!r} is not [x, y]")
        points.append((float(p[0]), float(p[1])))
    return points


@dataclass
class CostmapParams:
    """costmap_2d's main parameters (names as in ROS 1's costmap YAMLs)."""

    resolution: float = 0.05
    width: float = 3.0  # metres, for a rolling window
    height: float = 3.0
    rolling_window: bool = False
    robot_radius: float = 0.12
    footprint: list[tuple[float, float]] | None = None
    footprint_padding: float = 0.0
    inflation_radius: float = 0.4
    cost_scaling_factor: float = 10.0
    obstacle_range: float = 2.5
    raytrace_range: float = 3.0
    track_unknown_space: bool = False
    lethal_cost_threshold: int = 100
    use_static: bool = True
    use_obstacles: bool = True

    @property
    def radii(self) -> tuple[float, float]:
        inscribed, circ = footprint_radii(self.footprint, self.robot_radius)
        return inscribed + self.footprint_padding, circ + self.footprint_padding


@dataclass
class Costmap:
    """A layered costmap: ``costs`` (uint8, row 0 at ``origin_y``) is the master grid after update()."""

    params: CostmapParams
    size_x: int = 0
    size_y: int = 0
    origin_x: float = 0.0
    origin_y: float = 0.0
    static: np.ndarray | None = None  # uint8 static-layer costs aligned with the grid (global only)
    static_grid: tuple[np.ndarray, float, float, float] | None = None  # (cells, res, ox, oy) for rolling
    static_costs: np.ndarray | None = None  # the static layer inflated, without sensor marks (global only)
    obstacles: np.ndarray = field(default_factory=lambda: np.zeros((0, 0), dtype=np.uint8))
    costs: np.ndarray = field(default_factory=lambda: np.zeros((0, 0), dtype=np.uint8))

    # -- geometry ---------------------------------------------------------------------------------

    @property
    def resolution(self) -> float:
        return self.params.resolution

    def world_to_cell(self, x: float, y: float) -> tuple[int, int]:
        return (
            int(math.floor((x - self.origin_x) / self.resolution)),
            int(math.floor((y - self.origin_y) / self.resolution)),
        )

    def cell_to_world(self, cx: float, cy: float) -> tuple[float, float]:
        return self.origin_x + (cx + 0.5) * self.resolution, self.origin_y + (cy + 0.5) * self.resolution

    def inside(self, cx: int, cy: int) -> bool:
        return 0 <= cx < self.size_x and 0 <= cy < self.size_y

    def cost_at(self, x: float, y: float) -> int:
        cx, cy = self.world_to_cell(x, y)
        return int(self.costs[cy, cx]) if self.inside(cx, cy) else NO_INFORMATION

    # -- layers -----------------------------------------------------------------------------------

    def set_static_map(self, cells: np.ndarray, resolution: float, origin_x: float, origin_y: float) -> None:
        """Take an OccupancyGrid's data (int8 (h, w)). A global costmap resizes to it."""
        p = self.params
        unknown = NO_INFORMATION if p.track_unknown_space else FREE
        static = np.where(cells >= p.lethal_cost_threshold, LETHAL, np.where(cells < 0, unknown, FREE))
        static = static.astype(np.uint8)
        if p.rolling_window:
            self.static_grid = (static, resolution, origin_x, origin_y)
            if self.size_x == 0:
                self._resize_rolling(origin_x, origin_y)
            return
        self.params.resolution = resolution
        self.size_y, self.size_x = static.shape
        self.origin_x, self.origin_y = origin_x, origin_y
        self.static = static
        inscribed, _ = p.radii
        self.static_costs = inflation_costs(
            static == LETHAL, resolution, inscribed, p.inflation_radius, p.cost_scaling_factor
        )
        if self.obstacles.shape != static.shape:
            self.obstacles = np.zeros(static.shape, dtype=np.uint8)
        self.update()

    def _resize_rolling(self, cx: float, cy: float) -> None:
        p = self.params
        self.size_x = max(1, int(round(p.width / p.resolution)))
        self.size_y = max(1, int(round(p.height / p.resolution)))
        self.origin_x = self._snap(cx - p.width / 2)
        self.origin_y = self._snap(cy - p.height / 2)
        self.obstacles = np.zeros((self.size_y, self.size_x), dtype=np.uint8)
        self.costs = np.zeros((self.size_y, self.size_x), dtype=np.uint8)

    def _snap(self, v: float) -> float:
        return math.floor(v / self.resolution) * self.resolution

    def update_origin(self, robot_x: float, robot_y: float) -> None:
        """Rolling window: centre on the robot, keeping obstacle marks that stay inside."""
        if not self.params.rolling_window:
            return
        if self.size_x == 0:
            self._resize_rolling(robot_x, robot_y)
            return
        new_ox = self._snap(robot_x - self.size_x * self.resolution / 2)
        new_oy = self._snap(robot_y - self.size_y * self.resolution / 2)
        sx = int(round((new_ox - self.origin_x) / self.resolution))
        sy = int(round((new_oy - self.origin_y) / self.resolution))
        if sx == 0 and sy == 0:
            return
        moved = np.zeros_like(self.obstacles)
        h, w = moved.shape
        src_x0, src_y0 = max(0, sx), max(0, sy)
        dst_x0, dst_y0 = max(0, -sx), max(0, -sy)
        nx, ny = w - abs(sx), h - abs(sy)
        if nx > 0 and ny > 0:
            moved[dst_y0 : dst_y0 + ny, dst_x0 : dst_x0 + nx] = self.obstacles[
                src_y0 : src_y0 + ny, src_x0 : src_x0 + nx
            ]
        self.obstacles = moved
        self.origin_x, self.origin_y = new_ox, new_oy

    def _static_window(self) -> np.ndarray:
        """The static layer's costs over this grid (rolling windows sample the static map)."""
        if self.static is not None and not self.params.rolling_window:
            return self.static
        out = np.zeros((self.size_y, self.size_x), dtype=np.uint8)
        if self.static_grid is None or not self.params.use_static:
            return out
        cells, res, ox, oy = self.static_grid
        xs = self.origin_x + (np.arange(self.size_x) + 0.5) * self.resolution
        ys = self.origin_y + (np.arange(self.size_y) + 0.5) * self.resolution
        ci = np.floor((xs - ox) / res).astype(np.int64)
        ri = np.floor((ys - oy) / res).astype(np.int64)
        okx = (ci >= 0) & (ci < cells.shape[1])
        oky = (ri >= 0) & (ri < cells.shape[0])
        sub = cells[np.clip(ri, 0, cells.shape[0] - 1)][:, np.clip(ci, 0, cells.shape[1] - 1)]
        unknown = NO_INFORMATION if self.params.track_unknown_space else FREE
        sub = np.where(oky[:, None] & okx[None, :], sub, unknown)
        return sub.astype(np.uint8)

    def add_scan(
        self,
        sensor_x: float,
        sensor_y: float,
        angles: np.ndarray,
        ranges: np.ndarray,
        range_max: float,
    ) -> None:
        """Clear along each reading's ray, then mark each hit (angles in the world frame)."""
        if not self.params.use_obstacles or self.size_x == 0:
            return
        p = self.params
        ranges = np.asarray(ranges, dtype=float)
        angles = np.asarray(angles, dtype=float)
        keep = ~np.isnan(ranges)
        ranges, angles = ranges[keep], angles[keep]
        beyond = ~np.isfinite(ranges) | (ranges >= range_max)
        clear_len = np.minimum(np.where(beyond, p.raytrace_range, ranges), p.raytrace_range)
        # clear: sample every ray at half-cell steps, stopping short of the hit cell
        step = self.resolution / 2
        # no sample beyond the grid's farthest corner from the sensor can land in it (a rolling
        # window is much smaller than raytrace_range: this is most of the local costmap's work)
        x0, y0 = self.origin_x - sensor_x, self.origin_y - sensor_y
        x1, y1 = x0 + self.size_x * self.resolution, y0 + self.size_y * self.resolution
        reach = math.sqrt(max(x0 * x0, x1 * x1) + max(y0 * y0, y1 * y1))
        n = int(math.ceil(min(p.raytrace_range, reach) / step)) + 1
        t = np.arange(n) * step
        cos, sin = np.cos(angles), np.sin(angles)
        valid = t[None, :] < (clear_len[:, None] - self.resolution * 0.5)
        xs = sensor_x + cos[:, None] * t[None, :]
        ys = sensor_y + sin[:, None] * t[None, :]
        cx = np.floor((xs[valid] - self.origin_x) / self.resolution).astype(np.int64)
        cy = np.floor((ys[valid] - self.origin_y) / self.resolution).astype(np.int64)
        inside = (cx >= 0) & (cx < self.size_x) & (cy >= 0) & (cy < self.size_y)
        self.obstacles[cy[inside], cx[inside]] = 0
        # mark
        mark = ~beyond & (ranges <= p.obstacle_range)
        hx = sensor_x + cos[mark] * ranges[mark]
        hy = sensor_y + sin[mark] * ranges[mark]
        cx = np.floor((hx - self.origin_x) / self.resolution).astype(np.int64)
        cy = np.floor((hy - self.origin_y) / self.resolution).astype(np.int64)
        inside = (cx >= 0) & (cx < self.size_x) & (cy >= 0) & (cy < self.size_y)
        self.obstacles[cy[inside], cx[inside]] = LETHAL

    def clear_obstacles(self) -> None:
        """What the clear_costmaps service and the clearing recovery do: forget every sensor mark."""
        self.obstacles[:] = 0

    def update(self) -> np.ndarray:
        """Combine the layers into ``costs`` and return it."""
        if self.size_x == 0:
            return self.costs
        base = self._static_window()
        if base.shape != self.obstacles.shape:
            self.obstacles = np.zeros(base.shape, dtype=np.uint8)
        lethal = (base == LETHAL) | (self.obstacles == LETHAL)
        inscribed, _ = self.params.radii
        inflated = inflation_costs(
            lethal, self.resolution, inscribed, self.params.inflation_radius, self.params.cost_scaling_factor
        )
        unknown = (base == NO_INFORMATION) & ~lethal
        costs = np.where(unknown & (inflated == FREE), NO_INFORMATION, inflated).astype(np.uint8)
        self.costs = costs
        return costs
