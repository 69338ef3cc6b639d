"""What realsense2_camera publishes, computed from frames as numpy arrays: no ROS node, no pyrealsense2.

The numbers follow ROS 1's realsense2_camera (2.3): CameraInfo from the stream's intrinsics (K and P
from fx, fy, ppx, ppy; ``plumb_bob`` or ``equidistant`` for Kannala-Brandt), the static transforms
from ``<camera>_link`` to each stream's frame (the extrinsics to the depth stream, turned from the
camera's optical axes into ROS's body axes) and on to its optical frame, and the point cloud (x, y, z
in float32 with one float of padding, then ``rgb`` packed as B, G, R bytes; unordered clouds keep only
points with depth and, unless ``allow_no_texture_points``, a colour).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

#: the optical frame's rotation from the stream's body frame: RPY (-pi/2, 0, -pi/2), as x, y, z, w
OPTICAL = (-0.5, 0.5, -0.5, 0.5)


@dataclass(frozen=True)
class Intrinsics:
    width: int
    height: int
    fx: float
    fy: float
    ppx: float
    ppy: float
    model: str = "plumb_bob"  # or "equidistant" (Kannala-Brandt)
    coeffs: tuple[float, ...] = (0.0, 0.0, 0.0, 0.0, 0.0)


def camera_info_fields(intr: Intrinsics, frame_id: str) -> dict:
    """The fields of a sensor_msgs/CameraInfo for these intrinsics (the stereo Tx/Ty terms stay 0,
    as realsense2_camera sets them for depth when colour is on, and for colour itself)."""
    n = 4 if intr.model == "equidistant" else 5
    return {
        "frame_id": frame_id,
        "width": intr.width,
        "height": intr.height,
        "distortion_model": intr.model,
        "D": [float(c) for c in intr.coeffs[:n]] + [0.0] * (n - len(intr.coeffs[:n])),
        "K": [intr.fx, 0.0, intr.ppx, 0.0, intr.fy, intr.ppy, 0.0, 0.0, 1.0],
        "R": [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0],
        "P": [intr.fx, 0.0, intr.ppx, 0.0, 0.0, intr.fy, intr.ppy, 0.0, 0.0, 0.0, 1.0, 0.0],
    }


def _quat_mul(a: tuple[float, ...], b: tuple[float, ...]) -> tuple[float, float, float, float]:
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
        aw * bw - ax * bx - ay * by - az * bz,
    )


def rotation_quaternion(rotation: list[float] | tuple[float, ...]) -> tuple[float, float, float, float]:
    """x, y, z, w of a librealsense rotation (9 floats, column-major), as Eigen's Quaternion(Matrix3)."""
    m = [[rotation[0], rotation[3], rotation[6]], [rotation[1], rotation[4], rotation[7]],
         [rotation[2], rotation[5], rotation[8]]]  # fmt: skip
    trace = m[0][0] + m[1][1] + m[2][2]
    if trace > 0.0:
        t = math.sqrt(trace + 1.0)
        w = 0.5 * t
        t = 0.5 / t
        return ((m[2][1] - m[1][2]) * t, (m[0][2] - m[2][0]) * t, (m[1][0] - m[0][1]) * t, w)
    i = 0
    if m[1][1] > m[0][0]:
        i = 1
    if m[2][2] > m[i][i]:
        i = 2
    j, k = (i + 1) % 3, (i + 2) % 3
    t = math.sqrt(m[i][i] - m[j][j] - m[k][k] + 1.0)
    q = [0.0, 0.0, 0.0]
    q[i] = 0.5 * t
    t = 0.5 / t
    w = (m[k][j] - m[j][k]) * t
    q[j] = (m[j][i] + m[i][j]) * t
    q[k] = (m[k][i] + m[i][k]) * t
    return (q[0], q[1], q[2], w)


@dataclass(frozen=True)
class StaticTransform:
    parent: str
    child: str
    translation: tuple[float, float, float]
    rotation: tuple[float, float, float, float]  # x, y, z, w


def stream_transforms(
    base_frame: str,
    frame: str,
    optical_frame: str,
    rotation_to_base: list[float] | tuple[float, ...],
    translation_to_base: list[float] | tuple[float, ...],
    aligned_frame: str | None = None,
) -> list[StaticTransform]:
    """base -> stream frame -> stream optical frame (and base -> aligned-depth frame -> the optical
    frame when depth is aligned to this stream), from the stream's extrinsics to the base stream."""
    q = rotation_quaternion(rotation_to_base)
    inverse = (-OPTICAL[0], -OPTICAL[1], -OPTICAL[2], OPTICAL[3])
    body = _quat_mul(_quat_mul(OPTICAL, q), inverse)
    x, y, z = (float(v) for v in translation_to_base)
    moved = (z, -x, -y)
    out = [
        StaticTransform(base_frame, frame, moved, body),
        StaticTransform(frame, optical_frame, (0.0, 0.0, 0.0), OPTICAL),
    ]
    if aligned_frame:
        out += [
            StaticTransform(base_frame, aligned_frame, moved, body),
            StaticTransform(aligned_frame, optical_frame, (0.0, 0.0, 0.0), OPTICAL),
        ]
    return out


@dataclass
class Cloud:
    """A sensor_msgs/PointCloud2's layout and bytes."""

    width: int
    height: int
    point_step: int
    fields: list[tuple[str, int]]  # name, offset (all FLOAT32, count 1)
    data: bytes
    is_dense: bool


def point_cloud(
    vertices: np.ndarray,
    texcoords: np.ndarray | None,
    texture: np.ndarray | None,
    *,
    ordered: bool = False,
    allow_no_texture_points: bool = False,
    shape: tuple[int, int] | None = None,
) -> Cloud:
    """The cloud realsense2_camera publishes for ``vertices`` (N x 3 float32, metres, in the depth
    optical frame), textured from ``texture`` (H x W x 3 RGB or H x W intensity) at ``texcoords``
    (N x 2, u and v in [0, 1]); ``shape`` is the depth image's (height, width) for ordered clouds."""
    vertices = np.asarray(vertices, dtype=np.float32).reshape(-1, 3)
    n = len(vertices)
    has_depth = vertices[:, 2] > 0
    if texture is None or texcoords is None:
        keep = np.ones(n, bool) if ordered else has_depth
        step, fields = 16, [("x", 0), ("y", 4), ("z", 8)]
        out = np.zeros((int(keep.sum()), step), np.uint8)
        out[:, :12] = vertices[keep].view(np.uint8).reshape(-1, 12)
    else:
        uv = np.asarray(texcoords, dtype=np.float32).reshape(-1, 2)
        u, v = uv[:, 0], uv[:, 1]
        colored = (u >= 0) & (u <= 1) & (v >= 0) & (v <= 1)
        keep = np.ones(n, bool) if ordered else has_depth & (colored | allow_no_texture_points)
        tex = np.asarray(texture, dtype=np.uint8)
        th, tw = tex.shape[0], tex.shape[1]
        name = "rgb" if tex.ndim == 3 else "intensity"
        step, fields = 20, [("x", 0), ("y", 4), ("z", 8), (name, 16)]
        out = np.zeros((int(keep.sum()), step), np.uint8)
        out[:, :12] = vertices[keep].view(np.uint8).reshape(-1, 12)
        sel = keep & colored
        px = np.minimum((u[sel] * tw).astype(np.int64), tw - 1)
        py = np.minimum((v[sel] * th).astype(np.int64), th - 1)
        rows = np.flatnonzero(sel[keep])
        if tex.ndim == 3:
            out[rows, 16:19] = tex[py, px][:, 2::-1]  # PointCloud2's rgb is B, G, R in memory
        else:
            out[rows, 16] = tex[py, px]
    if ordered and shape is not None:
        height, width = shape
        dense = False
    else:
        height, width, dense = 1, len(out), True
    return Cloud(width, height, step, fields, out.tobytes(), dense)


def clip_depth(depth: np.ndarray, clip_distance: float, depth_scale: float) -> np.ndarray:
    """Depth beyond ``clip_distance`` metres set to 0 (no reading), as ``~clip_distance`` asks."""
    if clip_distance <= 0:
        return depth
    limit = int(clip_distance / depth_scale)
    out = np.array(depth, copy=True)
    out[out > limit] = 0
    return out
