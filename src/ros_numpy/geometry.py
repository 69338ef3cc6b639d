"""geometry_msgs: Vector3/Point (optionally homogeneous) and Quaternion (x, y, z, w) as vectors;
Transform and Pose as 4x4 homogeneous matrices."""

from __future__ import annotations

from typing import Any

import numpy as np

from geometry_msgs.msg import Point, Pose, Quaternion, Transform, Vector3
from ros_numpy.registry import converts_from_numpy, converts_to_numpy


@converts_to_numpy(Vector3)
def vector3_to_numpy(msg: Any, hom: bool = False) -> np.ndarray:
    return np.array([msg.x, msg.y, msg.z, 0.0] if hom else [msg.x, msg.y, msg.z])


@converts_from_numpy(Vector3)
def numpy_to_vector3(arr: Any) -> Any:
    arr = np.asarray(arr, dtype=float)
    if arr.shape[-1] == 4:
        if not np.all(arr[..., -1] == 0):
            raise ValueError("a homogeneous Vector3 has w == 0")
        arr = arr[..., :-1]
    return _each(arr, lambda v: Vector3(*v))


@converts_to_numpy(Point)
def point_to_numpy(msg: Any, hom: bool = False) -> np.ndarray:
    return np.array([msg.x, msg.y, msg.z, 1.0] if hom else [msg.x, msg.y, msg.z])


@converts_from_numpy(Point)
def numpy_to_point(arr: Any) -> Any:
    arr = np.asarray(arr, dtype=float)
    if arr.shape[-1] == 4:
        arr = arr[..., :-1] / arr[..., -1:]
    return _each(arr, lambda v: Point(*v))


@converts_to_numpy(Quaternion)
def quat_to_numpy(msg: Any) -> np.ndarray:
    return np.array([msg.x, msg.y, msg.z, msg.w])


@converts_from_numpy(Quaternion)
def numpy_to_quat(arr: Any) -> Any:
    arr = np.asarray(arr, dtype=float)
    if arr.shape[-1] != 4:
        raise ValueError("a Quaternion array ends in 4 (x, y, z, w)")
    return _each(arr, lambda v: Quaternion(*v))


def _each(arr: np.ndarray, make: Any) -> Any:
    if arr.ndim == 1:
        return make(arr.tolist())
    out = np.empty(arr.shape[:-1], dtype=object)
    for idx in np.ndindex(out.shape):
        out[idx] = make(arr[idx].tolist())
    return out


def _matrix(t: Any, q: Any) -> np.ndarray:
    x, y, z, w = q.x, q.y, q.z, q.w
    n = x * x + y * y + z * z + w * w
    s = 0.0 if n < np.finfo(float).eps else 2.0 / n
    m = np.identity(4)
    m[:3, :3] = [
        [1 - s * (y * y + z * z), s * (x * y - z * w), s * (x * z + y * w)],
        [s * (x * y + z * w), 1 - s * (x * x + z * z), s * (y * z - x * w)],
        [s * (x * z - y * w), s * (y * z + x * w), 1 - s * (x * x + y * y)],
    ]
    m[:3, 3] = [t.x, t.y, t.z]
    return m


def _quaternion(m: np.ndarray) -> list[float]:
    """(x, y, z, w) of the rotation part of a 4x4 matrix (Shepperd's method, w >= 0)."""
    r = m[:3, :3]
    tr = np.trace(r)
    if tr > 0:
        s = 2.0 * np.sqrt(tr + 1.0)
        q = [(r[2, 1] - r[1, 2]) / s, (r[0, 2] - r[2, 0]) / s, (r[1, 0] - r[0, 1]) / s, 0.25 * s]
    else:
        i = int(np.argmax(np.diag(r)))
        j, k = (i + 1) % 3, (i + 2) % 3
        s = 2.0 * np.sqrt(1.0 + r[i, i] - r[j, j] - r[k, k])
        q = [0.0, 0.0, 0.0, (r[k, j] - r[j, k]) / s]
        q[i] = 0.25 * s
        q[j] = (r[j, i] + r[i, j]) / s
        q[k] = (r[k, i] + r[i, k]) / s
    if q[3] < 0:
        q = [-c for c in q]
    return [float(c) for c in q]


@converts_to_numpy(Transform)
def transform_to_numpy(msg: Any) -> np.ndarray:
    return _matrix(msg.translation, msg.rotation)


@converts_from_numpy(Transform)
def numpy_to_transform(arr: Any) -> Any:
    arr = np.asarray(arr, dtype=float)
    if arr.shape[-2:] != (4, 4):
        raise ValueError("a Transform array ends in 4x4")
    return _each_matrix(
        arr,
        lambda m: Transform(translation=Vector3(*m[:3, 3].tolist()), rotation=Quaternion(*_quaternion(m))),
    )


@converts_to_numpy(Pose)
def pose_to_numpy(msg: Any) -> np.ndarray:
    return _matrix(msg.position, msg.orientation)


@converts_from_numpy(Pose)
def numpy_to_pose(arr: Any) -> Any:
    arr = np.asarray(arr, dtype=float)
    if arr.shape[-2:] != (4, 4):
        raise ValueError("a Pose array ends in 4x4")
    return _each_matrix(
        arr, lambda m: Pose(position=Point(*m[:3, 3].tolist()), orientation=Quaternion(*_quaternion(m)))
    )


def _each_matrix(arr: np.ndarray, make: Any) -> Any:
    if arr.ndim == 2:
        return make(arr)
    out = np.empty(arr.shape[:-2], dtype=object)
    for idx in np.ndindex(out.shape):
        out[idx] = make(arr[idx])
    return out
