"""Sensor models on top of the ray caster: lidar ranges, the RGB-D camera's images, IMU readings.

No ROS in here: arrays in, arrays out. The camera casts one ray per image column (the world is 2D
with heights), then fills each column: wall between the floor and the hit obstacle's top, floor
below (shaded with distance), sky above; the depth image holds the optical-axis depth in
millimetres (16UC1, as RealSense's ``depth/image_rect_raw``), 0 where there is no return.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from ninjemys.sim.raycast import cast_circles, cast_segments, circle_pairs, nearest_hits, segment_pairs

#: what :meth:`Camera.render` returns for an image it was asked not to draw
_EMPTY_RGB = np.zeros((0, 0, 3), dtype=np.uint8)
_EMPTY_DEPTH = np.zeros((0, 0), dtype=np.uint16)
FLOOR_RGB = np.array([176, 170, 160], dtype=np.float32)
SKY_RGB = np.array([206, 220, 235], dtype=np.float32)


@dataclass
class Scene:
    """What sensors see at one instant: solid segments with heights and colours, and round bodies."""

    segments: np.ndarray  # (N, 4)
    heights: np.ndarray  # (N,)
    colors: np.ndarray  # (N, 3) uint8
    circles: np.ndarray  # (M, 2) centres
    radii: np.ndarray  # (M,)
    circle_heights: np.ndarray  # (M,)
    circle_colors: np.ndarray  # (M, 3) uint8
    floor: FloorPaint | None = None  # markings painted on the floor
    #: per segment: +1/-1 when it is a side of a convex outline going counter-/clockwise, 0 otherwise
    #: (None: unknown, every side is cast); casts skip the sides facing away (see Obstacle.facing)
    facing: np.ndarray | None = None
    #: per segment: the height its obstacle starts at (None: everything stands on the floor); a
    #: planar lidar below a table top held in the air sees under it
    bases: np.ndarray | None = None


@dataclass
class FloorPaint:
    """Floor markings rasterized once: ``texture[row, col]`` is 0 (bare floor) or 1 + a palette index."""

    texture: np.ndarray  # uint8 (rows, cols), row 0 at origin_y
    palette: np.ndarray  # (K, 3) uint8
    origin_x: float
    origin_y: float
    resolution: float


def lidar_ranges(
    scene: Scene,
    x: float,
    y: float,
    z: float,
    yaw: float,
    angle_min: float,
    increment: float,
    beams: int,
    range_min: float,
    range_max: float,
    noise: float,
    rng: np.random.Generator,
) -> np.ndarray:
    """float32 ranges (REP 117: +inf no return within range_max, -inf closer than range_min).

    Only obstacles at least as tall as the lidar (``z``) are seen, as with a real planar lidar, and
    of those held above the floor (``scene.bases``) only the ones reaching down to it.
    """
    angles = yaw + angle_min + increment * np.arange(beams)
    tall = scene.heights >= z
    if scene.bases is not None:
        tall &= scene.bases <= z
    segments, facing = scene.segments, scene.facing
    if not tall.all():
        segments = segments[tall]
        facing = facing[tall] if facing is not None else None
    dist, _ = cast_segments(x, y, angles, segments, range_max, facing)
    if len(scene.circles):
        tall_c = scene.circle_heights >= z
        cd, _ = cast_circles(x, y, angles, scene.circles[tall_c], scene.radii[tall_c], range_max)
        dist = np.minimum(dist, cd)
    if noise > 0:
        dist = dist + rng.normal(0.0, noise, beams)
    out = dist.astype(np.float32)
    out[out > range_max] = np.inf
    out[out < range_min] = -np.inf
    return out


class _Crossings:
    """Every crossing of the camera's column rays with the scene's obstacles within ``far``: the
    column (``ray_of``), the obstacle (``item_of``, an index into ``heights``/``colors``: segments
    first, then round bodies) and the distance (``t``, inf for a pair that does not meet).

    Round bodies are listed first, segments after them: :func:`nearest_hits` lets the pair listed
    last win an exact tie, so a segment wins over a body and, among segments, the same one as
    :func:`cast_segments` picks."""

    def __init__(self, scene: Scene, x: float, y: float, angles: np.ndarray, far: float) -> None:
        ray_s, seg_s, t_s = segment_pairs(x, y, angles, scene.segments, far, scene.facing)
        self.heights = scene.heights
        self.colors = scene.colors
        if len(scene.circles):
            ray_c, circle_c, t_c = circle_pairs(x, y, angles, scene.circles, scene.radii, far)
            n = len(scene.segments)
            ray_s = np.concatenate([ray_c, ray_s])
            seg_s = np.concatenate([circle_c + n, seg_s])
            t_s = np.concatenate([t_c, t_s])
            self.heights = np.concatenate([scene.heights, scene.circle_heights])
            self.colors = np.concatenate([scene.colors, scene.circle_colors])
        if not len(self.heights):  # an empty scene: lookups of "no hit" (-1) must still work
            self.heights, self.colors = np.zeros(1), np.zeros((1, 3), dtype=np.uint8)
        self.ray_of, self.item_of, self.t = ray_s, seg_s, t_s


class Camera:
    """A pinhole RGB-D camera rendered by column ray casting; the per-row tables are built once."""

    def __init__(self, width: int, height: int, hfov_deg: float, cam_z: float, depth_max: float) -> None:
        self.width = width
        self.height = height
        self.fx = (width / 2.0) / math.tan(math.radians(hfov_deg) / 2.0)
        self.fy = self.fx  # square pixels
        self.cx = (width - 1) / 2.0
        self.cy = (height - 1) / 2.0
        self.cam_z = cam_z
        self.depth_max = depth_max
        u = np.arange(width)
        self.col_angles = np.arctan((self.cx - u) / self.fx)  # left of the image is +y (counter-clockwise)
        self.col_cos = np.cos(self.col_angles)
        v = np.arange(height)
        self.row_slope = (self.cy - v) / self.fy  # tan of the elevation of each row's ray
        below = self.row_slope < -1e-9
        floor_depth = np.zeros(height)
        floor_depth[below] = cam_z / -self.row_slope[below]
        floor_depth[floor_depth > depth_max] = 0.0
        self.floor_depth_mm = np.rint(floor_depth * 1000).astype(np.uint16)
        # static background: floor shaded with distance, sky above the horizon
        shade = np.clip(1.15 - floor_depth / 12.0, 0.55, 1.0)[:, None] * FLOOR_RGB[None, :]
        bg = np.where(below[:, None], shade, SKY_RGB[None, :]).astype(np.uint8)
        self._floor_rows = np.flatnonzero(floor_depth > 0)  # rows that see the floor within range
        forward = floor_depth[self._floor_rows][:, None]
        #: where each floor pixel meets the floor, in the camera's horizontal frame (x ahead, y left)
        self._floor_points = (
            np.broadcast_to(forward, (len(self._floor_rows), width)).astype(np.float32),
            (forward * ((self.cx - u) / self.fx)[None, :]).astype(np.float32),
        )
        self._neg_slope = -self.row_slope
        # a column's wall rows are top <= v < bottom, with top and bottom in [0, height]: held in the
        # narrowest unsigned type that holds them (uint8 up to 255 rows), and tested as one wrapping
        # subtraction and one comparison per pixel, (v - top) mod 2^bits < bottom - top
        self._row_type = np.uint8 if height <= 255 else np.uint16
        self._rows = np.arange(height, dtype=self._row_type)[:, None]
        self._background = np.ascontiguousarray(np.broadcast_to(bg[:, None, :], (height, width, 3)))
        self._floor_depth_image = np.ascontiguousarray(
            np.broadcast_to(self.floor_depth_mm[:, None], (height, width))
        )
        # scratch, reused by every frame (render runs on one thread at a time: the node's lock)
        self._offset = np.empty((height, width), dtype=self._row_type)
        self._mask = np.empty((height, width), dtype=bool)

    def render(
        self,
        scene: Scene,
        x: float,
        y: float,
        yaw: float,
        colour: bool = True,
        depth: bool = True,
    ) -> tuple[np.ndarray, np.ndarray]:
        """(rgb8 image (H, W, 3), depth in mm uint16 (H, W)) from a camera at (x, y, cam_z) facing ``yaw``.

        Each column shows the nearest obstacle its rays meet between floor and top, and above that
        obstacle whatever taller one stands behind it (a wall behind a cone): the nearest obstacle of
        each height class (at least as tall as a threshold, :func:`layer_thresholds`) is one layer,
        and a farther layer shows only above the nearer layers' tops. All layers come from one ray
        cast: every (column, obstacle) crossing is computed once, the first layer is the nearest
        crossing per column, each further layer the nearest crossing of a taller class.

        ``colour=False`` or ``depth=False`` leaves that image out (an empty array in its place):
        a camera whose depth stream nobody reads (or that has none) does not draw it.
        """
        return self._render(scene, x, y, yaw, colour, depth)

    def _render(
        self, scene: Scene, x: float, y: float, yaw: float, want_rgb: bool, want_depth: bool
    ) -> tuple[np.ndarray, np.ndarray]:
        angles = yaw + self.col_angles
        far = self.depth_max / float(self.col_cos.min())
        hits = _Crossings(scene, x, y, angles, far)
        dist, item = nearest_hits(self.width, hits.ray_of, hits.item_of, hits.t)
        found, depth, top, bottom, colors, _heights = self._layer(hits, dist, item, None)
        rgb, depth_mm, wall = _EMPTY_RGB, _EMPTY_DEPTH, None
        if not (want_rgb or want_depth):
            return rgb, depth_mm
        mask = self._span_mask(top, bottom, 0, self.height)
        if want_depth:
            wall_mm = np.rint(np.where(found, depth, 0.0) * 1000.0).astype(np.uint16)
            depth_mm = self._floor_depth_image.copy()
            self._paint(depth_mm, wall_mm, mask)
        if want_rgb:
            light = np.clip(1.1 - depth / 15.0, 0.45, 1.0)  # flat shading, darker with distance
            rgb = self._background.copy()
            self._paint(rgb, (colors * light[:, None]).astype(np.uint8), mask)
            if scene.floor is not None:
                wall = mask.astype(bool)  # where the floor markings may not show (grows with each layer)
        thresholds = layer_thresholds(scene, self.cam_z)
        if thresholds:
            self._farther_layers(hits, thresholds, found, item, top, rgb, depth_mm, wall)
        if wall is not None:
            assert scene.floor is not None
            self._paint_floor(rgb, wall, scene.floor, x, y, yaw)
        return rgb, depth_mm

    def _span_mask(self, top: np.ndarray, bottom: np.ndarray, r0: int, r1: int) -> np.ndarray:
        """uint8 (r1 - r0, width): 1 at the rows v in [r0, r1) of each column u with
        top[u] <= v < bottom[u] (none where bottom <= top), as (v - top) mod 2^bits < bottom - top:
        a row above top wraps around to at least 2^bits - top, more than any span below ``height``."""
        span = np.subtract(bottom, top, dtype=self._row_type)
        span[bottom <= top] = 0
        offset, mask = self._offset[: r1 - r0], self._mask[: r1 - r0]
        np.subtract(self._rows[r0:r1], top, out=offset)
        np.less(offset, span, out=mask)
        return mask.view(np.uint8)

    def _paint(self, image: np.ndarray, per_column: np.ndarray, mask: np.ndarray) -> None:
        """Set ``image``'s pixels under ``mask`` (uint8, ``image``'s rows and columns) to their
        column's value (``per_column``: one value or pixel per column), in place (OpenCV's masked
        copy, a few times faster than numpy's ``where`` or ``copyto(where=)`` here; the column values
        repeated down the rows by OpenCV too, a third faster than a contiguous copy of a broadcast)."""
        cv2 = _opencv()
        full = cv2.repeat(np.ascontiguousarray(per_column)[None], image.shape[0], 1)
        cv2.copyTo(full, mask, image)

    def _farther_layers(
        self,
        hits: _Crossings,
        thresholds: list[float],
        found: np.ndarray,
        item: np.ndarray,
        top: np.ndarray,
        rgb: np.ndarray,
        depth_mm: np.ndarray,
        wall: np.ndarray | None,
    ) -> None:
        """Draw, above the first layer, the farther obstacles of taller classes.

        An obstacle's class is how many thresholds its height reaches. Per column, the next layer
        is the nearest crossing of a class above every nearer layer's (only columns whose layers so
        far are all shorter than some threshold have one); it shows in the rows between its own top
        and its foot, cut at the nearer layers' tops. A crossing beyond the depth range ends the
        column, as a layer found there would (no data there)."""
        level = np.searchsorted(np.asarray(thresholds), hits.heights, "right")  # class per obstacle
        # the class each column has reached; a column with nothing in range takes no further layer
        reached = np.where(found, level[np.maximum(item, 0)], len(thresholds) + 1)
        ray_of, item_of, t = hits.ray_of, hits.item_of, hits.t
        pair_level = level[item_of]
        keep = pair_level > reached[ray_of]
        keep &= t != np.inf  # pairs that do not meet
        keep = np.flatnonzero(keep)
        if not len(keep):
            return
        ray_of, item_of, t, pair_level = ray_of[keep], item_of[keep], t[keep], pair_level[keep]
        # rows at or below a nearer layer's top are that layer's (or the floor in front of it)
        cut = top.copy()
        while len(t):
            dist, nearest = nearest_hits(self.width, ray_of, item_of, t)
            cols = np.flatnonzero(nearest >= 0)
            found_c, depth_c, top_c, bottom_c, colors_c, _heights = self._layer(
                hits, dist[cols], nearest[cols], cols
            )
            bottom_c = np.minimum(bottom_c, cut[cols])
            visible = found_c & (top_c < bottom_c)
            # a layer beyond the depth range ends its column (nothing farther is in range either)
            reached[cols] = np.where(found_c, level[nearest[cols]], len(thresholds) + 1)
            if visible.any():
                # the layer's visible rows lie in one band: masked copies over that band's rows only
                vis = cols[visible]
                top_v, bottom_v = top_c[visible], bottom_c[visible]
                r0, r1 = int(top_v.min()), int(bottom_v.max())
                band_top = np.zeros(self.width, dtype=self._row_type)
                band_bottom = np.zeros(self.width, dtype=self._row_type)  # other columns: no span
                band_top[vis], band_bottom[vis] = top_v, bottom_v
                mask = self._span_mask(band_top, band_bottom, r0, r1)
                depth_v = depth_c[visible]
                if rgb.size:
                    light_v = np.clip(1.1 - depth_v / 15.0, 0.45, 1.0)
                    colour = np.zeros((self.width, 3), dtype=np.uint8)
                    colour[vis] = (colors_c[visible] * light_v[:, None]).astype(np.uint8)
                    self._paint(rgb[r0:r1], colour, mask)
                if depth_mm.size:
                    mm = np.zeros(self.width, dtype=np.uint16)
                    mm[vis] = np.rint(depth_v * 1000.0).astype(np.uint16)
                    self._paint(depth_mm[r0:r1], mm, mask)
                if wall is not None:
                    wall[r0:r1] |= mask.view(bool)
            cut[cols] = np.minimum(cut[cols], top_c)
            more = np.flatnonzero(pair_level > reached[ray_of])
            ray_of, item_of, t, pair_level = ray_of[more], item_of[more], t[more], pair_level[more]

    def _layer(
        self, hits: _Crossings, dist: np.ndarray, item: np.ndarray, cols: np.ndarray | None
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Per column (all, or ``cols``), from its chosen crossing (``dist`` along the ray, obstacle
        ``item``, -1 for none): whether an obstacle is seen, its depth along the optical axis, its
        top and foot rows (``top <= v < bottom``), its colour and its height."""
        found = item >= 0
        # a column with no hit (-1) reads the last obstacle's: never drawn, ``found`` masks it out
        heights, colors = hits.heights[item], hits.colors[item]
        depth = dist * (self.col_cos if cols is None else self.col_cos[cols])  # along the optical axis
        found &= depth <= self.depth_max
        # rows v whose ray meets the column's obstacle between its foot and its top:
        # 0 <= cam_z + slope_v * depth <= height, i.e. slope_v in [-cam_z / depth, (height - cam_z) / depth]
        with np.errstate(divide="ignore", invalid="ignore"):
            lo_slope = np.where(found, -self.cam_z / depth, np.inf)
            hi_slope = np.where(found, (heights - self.cam_z) / depth, -np.inf)
        # row_slope decreases with v: searchsorted on its negation
        top = np.searchsorted(self._neg_slope, -hi_slope, "left").astype(self._row_type)
        bottom = np.searchsorted(self._neg_slope, -lo_slope, "right").astype(self._row_type)
        return found, depth, top, bottom, colors, heights

    def _paint_floor(
        self, rgb: np.ndarray, wall: np.ndarray, paint: FloorPaint, x: float, y: float, yaw: float
    ) -> None:
        """Draw the floor markings (the course's 1 m square) where floor pixels see them: each floor
        pixel's point on the floor looked up in the markings' texture."""
        rows = self._floor_rows
        forward, lateral = self._floor_points
        c, s = np.float32(math.cos(yaw) / paint.resolution), np.float32(math.sin(yaw) / paint.resolution)
        col = (c * forward - s * lateral + np.float32((x - paint.origin_x) / paint.resolution)).astype(
            np.int32
        )
        row = (s * forward + c * lateral + np.float32((y - paint.origin_y) / paint.resolution)).astype(
            np.int32
        )
        th, tw = paint.texture.shape
        inside = (col >= 0) & (col < tw) & (row >= 0) & (row < th) & ~wall[rows]
        if not inside.any():
            return
        r_idx, c_idx = np.nonzero(inside)
        ink = paint.texture[row[r_idx, c_idx], col[r_idx, c_idx]]
        painted = ink > 0
        rgb[rows[r_idx[painted]], c_idx[painted]] = paint.palette[ink[painted] - 1]

    def intrinsics(self) -> tuple[float, float, float, float]:
        return self.fx, self.fy, self.cx, self.cy


#: at most this many extra layers (height classes) per frame: a scene with many distinct heights
#: gets the tallest ones and evenly spaced ones between (exact for the classes kept)
MAX_EXTRA_LAYERS = 3


def layer_thresholds(scene: Scene, cam_z: float) -> list[float]:
    """Heights above which a farther obstacle can show over a nearer, shorter one: the scene's
    distinct obstacle heights but the lowest (that class is everything: the first layer), thinned
    to :data:`MAX_EXTRA_LAYERS`. None when all obstacles are equally tall (the common case).

    Remembered per set of heights: a scene is rebuilt every frame, its heights rarely change."""
    heights = (
        scene.heights if not len(scene.circles) else np.concatenate([scene.heights, scene.circle_heights])
    )
    if not len(heights):
        return []
    return list(_thresholds(np.ascontiguousarray(heights, dtype=np.float64).tobytes(), MAX_EXTRA_LAYERS))


@functools.lru_cache(maxsize=16)
def _thresholds(heights: bytes, most: int) -> tuple[float, ...]:
    distinct = np.unique(np.frombuffer(heights, dtype=np.float64))[1:]
    if len(distinct) > most:
        picks = np.linspace(0, len(distinct) - 1, most).round().astype(int)
        distinct = distinct[np.unique(picks)]
    return tuple(float(h) for h in distinct)


@functools.cache
def _opencv() -> Any:
    """OpenCV (a runtime dependency), imported at the first frame drawn: not at import time, nor
    when a robot is spawned (its 25-80 ms would delay the first scan after a spawn)."""
    import cv2

    return cv2


def imu_reading(
    yaw: float,
    v: float,
    w: float,
    v_prev: float,
    dt: float,
    gyro_noise: float,
    accel_noise: float,
    rng: np.random.Generator,
) -> tuple[float, float, float, float]:
    """(yaw, angular velocity z, linear acceleration x, y) of a planar robot, with gyro/accel noise.

    The accelerometer reads the body's acceleration: tangential ``dv/dt`` along x, centripetal
    ``v w`` along y (gravity on z is added by the caller's message)."""
    ax = (v - v_prev) / dt if dt > 0 else 0.0
    ay = v * w
    if gyro_noise > 0:
        w = w + float(rng.normal(0.0, gyro_noise))
    if accel_noise > 0:
        ax += float(rng.normal(0.0, accel_noise))
        ay += float(rng.normal(0.0, accel_noise))
    return yaw, w, ax, ay
