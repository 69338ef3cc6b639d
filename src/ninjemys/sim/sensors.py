"""Sensor models on top of the ray caster: what sensors see (:class:`Scene`), lidar ranges, IMU readings.

No ROS in here: arrays in, arrays out. The RGB-D camera, which draws the same scenes, is
:mod:`ninjemys.sim.camera`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ninjemys.sim.lighting import SceneLook
from ninjemys.sim.raycast import cast_circles, cast_segments


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
