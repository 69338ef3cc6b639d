"""Sensor models on top of the ray caster: what sensors see (:class:`Scene`), lidar ranges, IMU readings.

No ROS in here: arrays in, arrays out. The RGB-D camera, which draws the same scenes, is
:mod:`ninjemys.sim.camera`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ninjemys.sim.lighting import SceneLook
from ninjemys.sim.raycast import SegmentSet, cast_beams, cast_circles, prepare_segments, ray_directions

_ALL = np.logical_and.reduce  # ``a.all()`` without numpy's Python-level wrapper


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
    #: per segment: which obstacle's outline it belongs to (-1: none known); the camera pairs the
    #: side a ray enters a shape by with the side it leaves by (a lid seen between them)
    owners: np.ndarray | None = None
    #: the world's lights and round obstacles, for the camera (None: Gazebo's default sun, every
    #: side flat); see :mod:`ninjemys.sim.lighting`
    look: SceneLook | None = None
    #: the array whose rows ``segments`` starts with (the world's static segments, the same object at
    #: every step; the moving obstacles' follow), or None: lets the camera tell that the world's part
    #: of the scene is unchanged without comparing it value by value at every frame
    prefix: np.ndarray | None = None


@dataclass
class FloorPaint:
    """Floor markings rasterized once: ``texture[row, col]`` is 0 (bare floor) or 1 + a palette index."""

    texture: np.ndarray  # uint8 (rows, cols), row 0 at origin_y
    palette: np.ndarray  # (K, 3) uint8
    origin_x: float
    origin_y: float
    resolution: float


class LidarCache:
    """What a simulation's lidar scans share from one scan to the next (kept by the simulation, one
    for all its lidars): the beams' angles from the first and, per lidar height, the static world's
    segments that lidar sees (:attr:`Scene.prefix`, as tall as the lidar and standing on the floor
    below it) made ready to cast against; a scan then costs what depends on where the lidar is."""

    #: the most lidar heights kept (robots standing on table tops carry theirs higher)
    HEIGHTS = 8

    def __init__(self) -> None:
        self._offsets: dict[tuple[float, int], np.ndarray] = {}
        #: per lidar height: the arrays it was made from (by identity), the prepared segments and
        #: which moving ones it sees (None: all)
        self._static: dict[float, tuple[tuple[object, ...], SegmentSet, np.ndarray | None]] = {}

    def offsets(self, increment: float, beams: int) -> np.ndarray:
        """``increment * arange(beams)``: each beam's angle from the first (never written to)."""
        key = (increment, beams)
        found = self._offsets.get(key)
        if found is None:
            found = self._offsets[key] = increment * np.arange(beams)
        return found

    def segments(self, scene: Scene, z: float) -> tuple[SegmentSet, np.ndarray | None]:
        """What a lidar at height ``z`` casts against in ``scene``: the static segments it sees,
        prepared (kept while the scene's static world is the same arrays), and the moving ones it
        sees after them (None if there are none), as (k, 4)."""
        prefix = scene.prefix
        if prefix is None:  # no static world named: all of it, prepared for this scan only
            return _seen(scene.segments, scene.heights, scene.bases, scene.facing, z), None
        k = len(prefix)
        made = (prefix, scene.heights, scene.bases, scene.facing)
        found = self._static.get(z)
        if found is None or any(a is not b for a, b in zip(found[0], made, strict=True)):
            if len(self._static) >= self.HEIGHTS:
                self._static.clear()
            heights, bases, facing = scene.heights[:k], scene.bases, scene.facing
            seen = _seen(
                prefix,
                heights,
                None if bases is None else bases[:k],
                None if facing is None else facing[:k],
                z,
            )
            # the moving segments (after the prefix) it sees: their heights and bases do not move
            tall = _tall(scene.heights[k:], None if bases is None else bases[k:], z)
            found = self._static[z] = (made, seen, None if _ALL(tall) else tall)
        moving = scene.segments[k:]
        if not len(moving):
            return found[1], None
        return found[1], (moving if found[2] is None else moving[found[2]])


def _tall(heights: np.ndarray, bases: np.ndarray | None, z: float) -> np.ndarray:
    """Which segments a planar lidar at height ``z`` sees: as tall as it and, if held above the
    floor, reaching down to it."""
    tall = heights >= z
    if bases is not None:
        tall &= bases <= z
    return tall


def _seen(
    segments: np.ndarray, heights: np.ndarray, bases: np.ndarray | None, facing: np.ndarray | None, z: float
) -> SegmentSet:
    """The segments a planar lidar at height ``z`` sees, prepared: as tall as it, and of those
    held above the floor only the ones reaching down to it."""
    tall = _tall(heights, bases, z)
    if not _ALL(tall):
        segments = segments[tall]
        facing = facing[tall] if facing is not None else None
    return prepare_segments(segments, facing)


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
    cache: LidarCache | None = None,
) -> np.ndarray:
    """float32 ranges (REP 117: +inf no return within range_max, -inf closer than range_min).

    Only obstacles at least as tall as the lidar (``z``) are seen, as with a real planar lidar, and
    of those held above the floor (``scene.bases``) only the ones reaching down to it. ``cache``:
    what the caller's earlier scans left to reuse (a scan with none makes its own).
    """
    if cache is None:
        cache = LidarCache()
    angles = yaw + angle_min + cache.offsets(increment, beams)
    static, moving = cache.segments(scene, z)
    dirs = ray_directions(angles)
    dist = cast_beams(x, y, angles, static, range_max, dirs, moving, increment > 0)
    if len(scene.circles):
        tall_c = scene.circle_heights >= z
        cd, _ = cast_circles(x, y, angles, scene.circles[tall_c], scene.radii[tall_c], range_max, dirs)
        dist = np.minimum(dist, cd)
    if noise > 0:
        dist = dist + rng.normal(0.0, noise, beams)
    out = dist.astype(np.float32)
    out[out > range_max] = np.inf
    out[out < range_min] = -np.inf
    return out


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
