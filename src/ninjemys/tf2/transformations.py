"""tf's classic ``transformations`` module: 4x4 homogeneous matrices, Euler angles and quaternions.

The API and conventions are those of ``tf.transformations`` in ROS 1 (C. Gohlke's transformations.py
of 2009 as tf ships it): quaternions are ``(x, y, z, w)``; matrices are 4x4 numpy arrays that
multiply column vectors (``M @ v``); Euler angles take one of the 24 axis sequences named like
``'sxyz'`` (s = static/extrinsic axes, r = rotating/intrinsic; then the three axes in order) or a
``(firstaxis, parity, repetition, frame)`` tuple. Written here from the underlying math (Shoemake's
Euler-angle scheme in Graphics Gems IV, Horn's and Kabsch's superimposition) and checked against
an independent library (transforms3d) in the tests.
"""

from __future__ import annotations

import math
from typing import Any

import numpy

_EPS = numpy.finfo(float).eps * 4.0

# the axis that follows axis i in the cyclic order x -> y -> z -> x (index 3 wraps for parity)
_NEXT_AXIS = [1, 2, 0, 1]

# axis sequence -> (inner axis, parity, repetition, frame)
_AXES2TUPLE = {
    "sxyz": (0, 0, 0, 0),
    "sxyx": (0, 0, 1, 0),
    "sxzy": (0, 1, 0, 0),
    "sxzx": (0, 1, 1, 0),
    "syzx": (1, 0, 0, 0),
    "syzy": (1, 0, 1, 0),
    "syxz": (1, 1, 0, 0),
    "syxy": (1, 1, 1, 0),
    "szxy": (2, 0, 0, 0),
    "szxz": (2, 0, 1, 0),
    "szyx": (2, 1, 0, 0),
    "szyz": (2, 1, 1, 0),
    "rzyx": (0, 0, 0, 1),
    "rxyx": (0, 0, 1, 1),
    "ryzx": (0, 1, 0, 1),
    "rxzx": (0, 1, 1, 1),
    "rxzy": (1, 0, 0, 1),
    "ryzy": (1, 0, 1, 1),
    "rzxy": (1, 1, 0, 1),
    "ryxy": (1, 1, 1, 1),
    "ryxz": (2, 0, 0, 1),
    "rzxz": (2, 0, 1, 1),
    "rxyz": (2, 1, 0, 1),
    "rzyz": (2, 1, 1, 1),
}

_TUPLE2AXES = {v: k for k, v in _AXES2TUPLE.items()}


def _axes(axes: Any) -> tuple[int, int, int, int, int, int]:
    """(i, j, k, parity, repetition, frame) for an axes string or tuple."""
    try:
        first, parity, repetition, frame = _AXES2TUPLE[axes.lower()]
    except (AttributeError, KeyError):
        if tuple(axes) not in _TUPLE2AXES:
            raise ValueError(f"unknown Euler axes specification {axes!r}") from None
        first, parity, repetition, frame = axes
    i = first
    j = _NEXT_AXIS[i + parity]
    k = _NEXT_AXIS[i - parity + 1]
    return i, j, k, parity, repetition, frame


# -- vectors ----------------------------------------------------------------------------------------


def vector_norm(data: Any, axis: int | None = None, out: Any = None) -> Any:
    """Euclidean length of ``data`` (along ``axis``)."""
    data = numpy.array(data, dtype=numpy.float64, copy=True)
    if out is None:
        if data.ndim == 1:
            return math.sqrt(numpy.dot(data, data))
        data *= data
        out = numpy.atleast_1d(numpy.sum(data, axis=axis))
        numpy.sqrt(out, out)
        return out
    data *= data
    numpy.sum(data, axis=axis, out=out)
    numpy.sqrt(out, out)
    return None


def unit_vector(data: Any, axis: int | None = None, out: Any = None) -> Any:
    """``data`` divided by its length (along ``axis``); written into ``out`` when given."""
    if out is None:
        data = numpy.array(data, dtype=numpy.float64, copy=True)
        if data.ndim == 1:
            data /= math.sqrt(numpy.dot(data, data))
            return data
    else:
        if out is not data:
            out[:] = numpy.asarray(data)
        data = out
    length = numpy.atleast_1d(numpy.sum(data * data, axis))
    numpy.sqrt(length, length)
    if axis is not None:
        length = numpy.expand_dims(length, axis)
    data /= length
    return data if out is None else None


def random_vector(size: Any) -> Any:
    """Uniform random numbers in [0, 1) of the given shape."""
    return numpy.random.random(size)


# -- matrices ---------------------------------------------------------------------------------------


def identity_matrix() -> Any:
    """The 4x4 identity."""
    return numpy.identity(4, dtype=numpy.float64)


def translation_matrix(direction: Any) -> Any:
    """The matrix that translates by ``direction``."""
    m = numpy.identity(4)
    m[:3, 3] = numpy.asarray(direction, dtype=numpy.float64)[:3]
    return m


def translation_from_matrix(matrix: Any) -> Any:
    """The translation of a homogeneous matrix."""
    return numpy.array(matrix, dtype=numpy.float64)[:3, 3].copy()


def inverse_matrix(matrix: Any) -> Any:
    """The inverse of a square matrix."""
    return numpy.linalg.inv(matrix)


def concatenate_matrices(*matrices: Any) -> Any:
    """The product of the matrices, left to right (the last one applies first)."""
    m = numpy.identity(4)
    for other in matrices:
        m = numpy.dot(m, other)
    return m


def is_same_transform(matrix0: Any, matrix1: Any) -> bool:
    """Whether two homogeneous matrices describe the same transform (after normalizing M[3, 3])."""
    a = numpy.array(matrix0, dtype=numpy.float64, copy=True)
    a /= a[3, 3]
    b = numpy.array(matrix1, dtype=numpy.float64, copy=True)
    b /= b[3, 3]
    return bool(numpy.allclose(a, b))


def _eigvec(m: Any, value: float, what: str, tol: float = 1e-8, last: bool = True) -> Any:
    """A real eigenvector of ``m`` for eigenvalue ``value`` (ValueError naming ``what`` if none)."""
    w, v = numpy.linalg.eig(m)
    idx = numpy.where(abs(numpy.real(w) - value) < tol)[0]
    if not len(idx):
        raise ValueError(f"no {what} corresponding to eigenvalue {value:g}")
    return numpy.real(v[:, idx[-1] if last else idx[0]]).squeeze()


def _fixed_point(m: Any) -> Any:
    """A point the homogeneous matrix ``m`` leaves in place (homogeneous, w = 1).

    For an affine ``m`` this solves ``(R - I) x = -t`` in the least-squares sense (the fixed point
    nearest the origin), which stays well defined where the eigenvectors of a defective matrix (a
    shear's) degenerate to points at infinity; other matrices use the eigenvector for eigenvalue 1.
    """
    if numpy.allclose(m[3], (0.0, 0.0, 0.0, 1.0)):
        x = numpy.linalg.lstsq(m[:3, :3] - numpy.identity(3), -m[:3, 3], rcond=None)[0]
        if numpy.allclose(m[:3, :3] @ x + m[:3, 3], x, atol=1e-8):
            return numpy.append(x, 1.0)
    p = _eigvec(m, 1.0, "eigenvector")
    return p / p[3]


def reflection_matrix(point: Any, normal: Any) -> Any:
    """Mirror at the plane through ``point`` with ``normal``."""
    n = unit_vector(normal[:3])
    m = numpy.identity(4)
    m[:3, :3] -= 2.0 * numpy.outer(n, n)
    m[:3, 3] = (2.0 * numpy.dot(numpy.asarray(point, dtype=float)[:3], n)) * n
    return m


def reflection_from_matrix(matrix: Any) -> tuple[Any, Any]:
    """(point, normal) of the mirror plane of a reflection matrix."""
    m = numpy.array(matrix, dtype=numpy.float64)
    normal = _eigvec(m[:3, :3], -1.0, "unit eigenvector", last=False)
    return _fixed_point(m), normal


def rotation_matrix(angle: float, direction: Any, point: Any = None) -> Any:
    """Rotation by ``angle`` about the axis ``direction`` through ``point`` (the origin by default)."""
    s, c = math.sin(angle), math.cos(angle)
    d = unit_vector(direction[:3])
    r = numpy.diag([c, c, c]) + numpy.outer(d, d) * (1.0 - c)
    dx, dy, dz = d * s
    r += numpy.array(((0.0, -dz, dy), (dz, 0.0, -dx), (-dy, dx, 0.0)))
    m = numpy.identity(4)
    m[:3, :3] = r
    if point is not None:
        p = numpy.array(point[:3], dtype=numpy.float64)
        m[:3, 3] = p - numpy.dot(r, p)
    return m


def rotation_from_matrix(matrix: Any) -> tuple[float, Any, Any]:
    """(angle, direction, point) of a rotation matrix."""
    r = numpy.array(matrix, dtype=numpy.float64)
    r33 = r[:3, :3]
    d = _eigvec(r33.T, 1.0, "unit eigenvector")
    point = _fixed_point(r)
    c = (numpy.trace(r33) - 1.0) / 2.0
    if abs(d[2]) > 1e-8:
        s = (r[1, 0] + (c - 1.0) * d[0] * d[1]) / d[2]
    elif abs(d[1]) > 1e-8:
        s = (r[0, 2] + (c - 1.0) * d[0] * d[2]) / d[1]
    else:
        s = (r[2, 1] + (c - 1.0) * d[1] * d[2]) / d[0]
    return math.atan2(s, c), d, point


def scale_matrix(factor: float, origin: Any = None, direction: Any = None) -> Any:
    """Scale by ``factor`` about ``origin``, uniformly or along ``direction`` only."""
    if direction is None:
        m = numpy.diag([factor, factor, factor, 1.0])
        if origin is not None:
            m[:3, 3] = numpy.asarray(origin, dtype=float)[:3] * (1.0 - factor)
        return m
    d = unit_vector(direction[:3])
    f = 1.0 - factor
    m = numpy.identity(4)
    m[:3, :3] -= f * numpy.outer(d, d)
    if origin is not None:
        m[:3, 3] = (f * numpy.dot(numpy.asarray(origin, dtype=float)[:3], d)) * d
    return m


def scale_from_matrix(matrix: Any) -> tuple[float, Any, Any]:
    """(factor, origin, direction) of a scaling matrix (direction None for uniform scaling)."""
    m = numpy.array(matrix, dtype=numpy.float64)
    m33 = m[:3, :3]
    factor = numpy.trace(m33) - 2.0
    try:
        d = _eigvec(m33, factor, "eigenvector", last=False)
        direction = d / vector_norm(d)
    except ValueError:  # no single eigenvalue `factor`: uniform scaling
        factor = (factor + 2.0) / 3.0
        direction = None
    return factor, _fixed_point(m), direction


def projection_matrix(
    point: Any, normal: Any, direction: Any = None, perspective: Any = None, pseudo: bool = False
) -> Any:
    """Projection onto the plane (point, normal): orthogonal, parallel along ``direction``, or
    perspective from ``perspective`` (``pseudo`` keeps relative depth)."""
    m = numpy.identity(4)
    p = numpy.array(point[:3], dtype=numpy.float64)
    n = unit_vector(normal[:3])
    if perspective is not None:
        e = numpy.array(perspective[:3], dtype=numpy.float64)
        m[0, 0] = m[1, 1] = m[2, 2] = numpy.dot(e - p, n)
        m[:3, :3] -= numpy.outer(e, n)
        if pseudo:
            m[:3, :3] -= numpy.outer(n, n)
            m[:3, 3] = numpy.dot(p, n) * (e + n)
        else:
            m[:3, 3] = numpy.dot(p, n) * e
        m[3, :3] = -n
        m[3, 3] = numpy.dot(e, n)
    elif direction is not None:
        d = numpy.array(direction[:3], dtype=numpy.float64)
        scale = numpy.dot(d, n)
        m[:3, :3] -= numpy.outer(d, n) / scale
        m[:3, 3] = d * (numpy.dot(p, n) / scale)
    else:
        m[:3, :3] -= numpy.outer(n, n)
        m[:3, 3] = numpy.dot(p, n) * n
    return m


def projection_from_matrix(matrix: Any, pseudo: bool = False) -> tuple[Any, Any, Any, Any, bool]:
    """(point, normal, direction, perspective, pseudo) of a projection matrix."""
    m = numpy.array(matrix, dtype=numpy.float64)
    m33 = m[:3, :3]
    w, v = numpy.linalg.eig(m)
    ones = numpy.where(abs(numpy.real(w) - 1.0) < 1e-8)[0]
    if not pseudo and len(ones):
        point = numpy.real(v[:, ones[-1]]).squeeze()
        point /= point[3]
        d = _eigvec(m33, 0.0, "eigenvector", last=False)
        direction = d / vector_norm(d)
        wt, vt = numpy.linalg.eig(m33.T)
        zeros = numpy.where(abs(numpy.real(wt)) < 1e-8)[0]
        if len(zeros):  # parallel projection
            normal = numpy.real(vt[:, zeros[0]]).squeeze()
            return point, normal / vector_norm(normal), direction, None, False
        return point, direction, None, None, False  # orthogonal: the normal is the direction
    nonzero = numpy.where(abs(numpy.real(w)) > 1e-8)[0]
    if not len(nonzero):
        raise ValueError("no eigenvector not corresponding to eigenvalue 0")
    point = numpy.real(v[:, nonzero[-1]]).squeeze()
    point /= point[3]
    normal = -m[3, :3]
    perspective = m[:3, 3] / numpy.dot(point[:3], normal)
    if pseudo:
        perspective -= normal
    return point, normal, None, perspective, pseudo


def clip_matrix(
    left: float, right: float, bottom: float, top: float, near: float, far: float, perspective: bool = False
) -> Any:
    """Map the frustum (or box) to normalized device coordinates [-1, 1]^3."""
    if left >= right or bottom >= top or near >= far:
        raise ValueError("invalid frustrum")
    if perspective:
        if near <= _EPS:
            raise ValueError("invalid frustrum: near <= 0")
        t = 2.0 * near
        rows = (
            (-t / (right - left), 0.0, (right + left) / (right - left), 0.0),
            (0.0, -t / (top - bottom), (top + bottom) / (top - bottom), 0.0),
            (0.0, 0.0, -(far + near) / (far - near), t * far / (far - near)),
            (0.0, 0.0, -1.0, 0.0),
        )
    else:
        rows = (
            (2.0 / (right - left), 0.0, 0.0, (right + left) / (left - right)),
            (0.0, 2.0 / (top - bottom), 0.0, (top + bottom) / (bottom - top)),
            (0.0, 0.0, 2.0 / (far - near), (far + near) / (near - far)),
            (0.0, 0.0, 0.0, 1.0),
        )
    return numpy.array(rows, dtype=numpy.float64)


def shear_matrix(angle: float, direction: Any, point: Any, normal: Any) -> Any:
    """Shear by ``angle`` along ``direction`` on the plane (point, normal); direction ⟂ normal."""
    n = unit_vector(normal[:3])
    d = unit_vector(direction[:3])
    if abs(numpy.dot(n, d)) > 1e-6:
        raise ValueError("direction and normal vectors are not orthogonal")
    t = math.tan(angle)
    m = numpy.identity(4)
    m[:3, :3] += t * numpy.outer(d, n)
    m[:3, 3] = -t * numpy.dot(numpy.asarray(point, dtype=float)[:3], n) * d
    return m


def shear_from_matrix(matrix: Any) -> tuple[float, Any, Any, Any]:
    """(angle, direction, point, normal) of a shear matrix."""
    m = numpy.array(matrix, dtype=numpy.float64)
    m33 = m[:3, :3]
    w, v = numpy.linalg.eig(m33)
    idx = numpy.where(abs(numpy.real(w) - 1.0) < 1e-4)[0]
    if len(idx) < 2:
        raise ValueError(f"no two linear independent eigenvectors found {w}")
    vecs = numpy.real(v[:, idx]).squeeze().T
    best = -1.0
    normal: Any = None
    for a, b in ((0, 1), (0, 2), (1, 2)):
        if b >= len(vecs):
            continue
        n = numpy.cross(vecs[a], vecs[b])
        length = vector_norm(n)
        if length > best:
            best, normal = length, n
    normal = normal / best
    direction = numpy.dot(m33 - numpy.identity(3), normal)
    angle = vector_norm(direction)
    direction = direction / angle
    return math.atan(angle), direction, _fixed_point(m), normal


def decompose_matrix(matrix: Any) -> tuple[Any, Any, Any, Any, Any]:
    """(scale, shear, angles, translate, perspective) of a homogeneous matrix; angles are 'sxyz'.

    ValueError for a singular matrix or M[3, 3] == 0.
    """
    m = numpy.array(matrix, dtype=numpy.float64, copy=True).T
    if abs(m[3, 3]) < _EPS:
        raise ValueError("M[3, 3] is zero")
    m /= m[3, 3]
    p = m.copy()
    p[:, 3] = 0.0, 0.0, 0.0, 1.0
    if not numpy.linalg.det(p):
        raise ValueError("matrix is singular")
    scale = numpy.zeros(3)
    shear = numpy.zeros(3)
    angles = numpy.zeros(3)
    if any(abs(m[:3, 3]) > _EPS):
        perspective = numpy.dot(m[:, 3], numpy.linalg.inv(p.T))
        m[:, 3] = 0.0, 0.0, 0.0, 1.0
    else:
        perspective = numpy.array((0.0, 0.0, 0.0, 1.0))
    translate = m[3, :3].copy()
    m[3, :3] = 0.0
    row = m[:3, :3].copy()
    scale[0] = vector_norm(row[0])
    row[0] /= scale[0]
    shear[0] = numpy.dot(row[0], row[1])
    row[1] -= row[0] * shear[0]
    scale[1] = vector_norm(row[1])
    row[1] /= scale[1]
    shear[0] /= scale[1]
    shear[1] = numpy.dot(row[0], row[2])
    row[2] -= row[0] * shear[1]
    shear[2] = numpy.dot(row[1], row[2])
    row[2] -= row[1] * shear[2]
    scale[2] = vector_norm(row[2])
    row[2] /= scale[2]
    shear[1:] /= scale[2]
    if numpy.dot(row[0], numpy.cross(row[1], row[2])) < 0:
        scale *= -1
        row *= -1
    angles[1] = math.asin(-row[0, 2])
    if math.cos(angles[1]):
        angles[0] = math.atan2(row[1, 2], row[2, 2])
        angles[2] = math.atan2(row[0, 1], row[0, 0])
    else:
        angles[0] = math.atan2(-row[2, 1], row[1, 1])
        angles[2] = 0.0
    return scale, shear, angles, translate, perspective


def compose_matrix(
    scale: Any = None, shear: Any = None, angles: Any = None, translate: Any = None, perspective: Any = None
) -> Any:
    """The matrix ``perspective * translate * rotate('sxyz' angles) * shear * scale``."""
    m = numpy.identity(4)
    if perspective is not None:
        pm = numpy.identity(4)
        pm[3, :] = perspective[:4]
        m = numpy.dot(m, pm)
    if translate is not None:
        m = numpy.dot(m, translation_matrix(translate))
    if angles is not None:
        m = numpy.dot(m, euler_matrix(angles[0], angles[1], angles[2], "sxyz"))
    if shear is not None:
        z = numpy.identity(4)
        z[1, 2] = shear[2]
        z[0, 2] = shear[1]
        z[0, 1] = shear[0]
        m = numpy.dot(m, z)
    if scale is not None:
        m = numpy.dot(m, numpy.diag([scale[0], scale[1], scale[2], 1.0]))
    m /= m[3, 3]
    return m


def orthogonalization_matrix(lengths: Any, angles: Any) -> Any:
    """The de-orthogonalization matrix of a crystal cell (lengths a, b, c; angles in degrees)."""
    a, b, c = lengths
    rad = numpy.radians(angles)
    sina, sinb, _ = numpy.sin(rad)
    cosa, cosb, cosg = numpy.cos(rad)
    co = (cosa * cosb - cosg) / (sina * sinb)
    return numpy.array(
        (
            (a * sinb * math.sqrt(1.0 - co * co), 0.0, 0.0, 0.0),
            (-a * sinb * co, b * sina, 0.0, 0.0),
            (a * cosb, b * cosa, c, 0.0),
            (0.0, 0.0, 0.0, 1.0),
        ),
        dtype=numpy.float64,
    )


def superimposition_matrix(v0: Any, v1: Any, scaling: bool = False, usesvd: bool = True) -> Any:
    """The rigid (optionally scaled) transform mapping point set ``v0`` onto ``v1`` (3xN or 4xN) in the
    least-squares sense: Kabsch's SVD method, or Horn's quaternion method with ``usesvd=False``."""
    a = numpy.array(v0, dtype=numpy.float64)[:3]
    b = numpy.array(v1, dtype=numpy.float64)[:3]
    if a.shape != b.shape or a.shape[1] < 3:
        raise ValueError("vector sets are of wrong shape or type")
    t0 = numpy.mean(a, axis=1)
    t1 = numpy.mean(b, axis=1)
    a = a - t0.reshape(3, 1)
    b = b - t1.reshape(3, 1)
    if usesvd:
        u, _, vh = numpy.linalg.svd(numpy.dot(b, a.T))
        r = numpy.dot(u, vh)
        if numpy.linalg.det(r) < 0.0:  # a reflection: flip the least significant axis
            r -= numpy.outer(u[:, 2], vh[2, :] * 2.0)
        m = numpy.identity(4)
        m[:3, :3] = r
    else:
        xx, yy, zz = numpy.sum(a * b, axis=1)
        xy, yz, zx = numpy.sum(a * numpy.roll(b, -1, axis=0), axis=1)
        xz, yx, zy = numpy.sum(a * numpy.roll(b, -2, axis=0), axis=1)
        n = (
            (xx + yy + zz, yz - zy, zx - xz, xy - yx),
            (yz - zy, xx - yy - zz, xy + yx, zx + xz),
            (zx - xz, xy + yx, -xx + yy - zz, yz + zy),
            (xy - yx, zx + xz, yz + zy, -xx - yy + zz),
        )
        w, v = numpy.linalg.eigh(numpy.array(n))
        q = v[:, numpy.argmax(w)]  # (w, x, y, z)
        m = quaternion_matrix((q[1], q[2], q[3], q[0]))
    if scaling:
        m[:3, :3] *= math.sqrt(numpy.sum(b * b) / numpy.sum(a * a))
    m[:3, 3] = t1
    return numpy.dot(m, translation_matrix(-t0))


# -- Euler angles -----------------------------------------------------------------------------------


def euler_matrix(ai: float, aj: float, ak: float, axes: Any = "sxyz") -> Any:
    """The rotation matrix of Euler angles (radians) in the given axis sequence."""
    i, j, k, parity, repetition, frame = _axes(axes)
    if frame:
        ai, ak = ak, ai
    if parity:
        ai, aj, ak = -ai, -aj, -ak
    si, sj, sk = math.sin(ai), math.sin(aj), math.sin(ak)
    ci, cj, ck = math.cos(ai), math.cos(aj), math.cos(ak)
    cc, cs = ci * ck, ci * sk
    sc, ss = si * ck, si * sk
    m = numpy.identity(4)
    if repetition:
        m[i, i], m[i, j], m[i, k] = cj, sj * si, sj * ci
        m[j, i], m[j, j], m[j, k] = sj * sk, -cj * ss + cc, -cj * cs - sc
        m[k, i], m[k, j], m[k, k] = -sj * ck, cj * sc + cs, cj * cc - ss
    else:
        m[i, i], m[i, j], m[i, k] = cj * ck, sj * sc - cs, sj * cc + ss
        m[j, i], m[j, j], m[j, k] = cj * sk, sj * ss + cc, sj * cs - sc
        m[k, i], m[k, j], m[k, k] = -sj, cj * si, cj * ci
    return m


def euler_from_matrix(matrix: Any, axes: Any = "sxyz") -> tuple[float, float, float]:
    """Euler angles (radians) of the rotation part of ``matrix`` in the given axis sequence."""
    i, j, k, parity, repetition, frame = _axes(axes)
    m = numpy.array(matrix, dtype=numpy.float64)[:3, :3]
    if repetition:
        sy = math.sqrt(m[i, j] * m[i, j] + m[i, k] * m[i, k])
        if sy > _EPS:
            ax = math.atan2(m[i, j], m[i, k])
            ay = math.atan2(sy, m[i, i])
            az = math.atan2(m[j, i], -m[k, i])
        else:
            ax = math.atan2(-m[j, k], m[j, j])
            ay = math.atan2(sy, m[i, i])
            az = 0.0
    else:
        cy = math.sqrt(m[i, i] * m[i, i] + m[j, i] * m[j, i])
        if cy > _EPS:
            ax = math.atan2(m[k, j], m[k, k])
            ay = math.atan2(-m[k, i], cy)
            az = math.atan2(m[j, i], m[i, i])
        else:
            ax = math.atan2(-m[j, k], m[j, j])
            ay = math.atan2(-m[k, i], cy)
            az = 0.0
    if parity:
        ax, ay, az = -ax, -ay, -az
    if frame:
        ax, az = az, ax
    return ax, ay, az


def euler_from_quaternion(quaternion: Any, axes: Any = "sxyz") -> tuple[float, float, float]:
    """Euler angles of an (x, y, z, w) quaternion."""
    return euler_from_matrix(quaternion_matrix(quaternion), axes)


def quaternion_from_euler(ai: float, aj: float, ak: float, axes: Any = "sxyz") -> Any:
    """The (x, y, z, w) quaternion of Euler angles (radians) in the given axis sequence."""
    i, j, k, parity, repetition, frame = _axes(axes)
    if frame:
        ai, ak = ak, ai
    if parity:
        aj = -aj
    ai, aj, ak = ai / 2.0, aj / 2.0, ak / 2.0
    ci, si = math.cos(ai), math.sin(ai)
    cj, sj = math.cos(aj), math.sin(aj)
    ck, sk = math.cos(ak), math.sin(ak)
    cc, cs = ci * ck, ci * sk
    sc, ss = si * ck, si * sk
    q = numpy.empty(4)
    if repetition:
        q[i] = cj * (cs + sc)
        q[j] = sj * (cc + ss)
        q[k] = sj * (cs - sc)
        q[3] = cj * (cc - ss)
    else:
        q[i] = cj * sc - sj * cs
        q[j] = cj * ss + sj * cc
        q[k] = cj * cs - sj * sc
        q[3] = cj * cc + sj * ss
    if parity:
        q[j] *= -1
    return q


# -- quaternions (x, y, z, w) -----------------------------------------------------------------------


def quaternion_about_axis(angle: float, axis: Any) -> Any:
    """The quaternion of a rotation by ``angle`` about ``axis``."""
    q = numpy.zeros(4)
    q[:3] = numpy.asarray(axis, dtype=float)[:3]
    length = vector_norm(q)
    if length > _EPS:
        q *= math.sin(angle / 2.0) / length
    q[3] = math.cos(angle / 2.0)
    return q


def quaternion_matrix(quaternion: Any) -> Any:
    """The 4x4 rotation matrix of a quaternion (normalized first; identity for a zero quaternion)."""
    q = numpy.array(quaternion[:4], dtype=numpy.float64, copy=True)
    nq = numpy.dot(q, q)
    if nq < _EPS:
        return numpy.identity(4)
    q *= math.sqrt(2.0 / nq)
    x, y, z, w = q
    return numpy.array(
        (
            (1.0 - y * y - z * z, x * y - z * w, x * z + y * w, 0.0),
            (x * y + z * w, 1.0 - x * x - z * z, y * z - x * w, 0.0),
            (x * z - y * w, y * z + x * w, 1.0 - x * x - y * y, 0.0),
            (0.0, 0.0, 0.0, 1.0),
        ),
        dtype=numpy.float64,
    )


def quaternion_from_matrix(matrix: Any) -> Any:
    """The quaternion of the rotation part of a homogeneous matrix (Shepperd's method)."""
    m = numpy.array(matrix, dtype=numpy.float64)[:4, :4]
    q = numpy.empty(4)
    t = numpy.trace(m)
    if t > m[3, 3]:
        q[3] = t
        q[2] = m[1, 0] - m[0, 1]
        q[1] = m[0, 2] - m[2, 0]
        q[0] = m[2, 1] - m[1, 2]
    else:
        i, j, k = 0, 1, 2
        if m[1, 1] > m[0, 0]:
            i, j, k = 1, 2, 0
        if m[2, 2] > m[i, i]:
            i, j, k = 2, 0, 1
        t = m[i, i] - (m[j, j] + m[k, k]) + m[3, 3]
        q[i] = t
        q[j] = m[i, j] + m[j, i]
        q[k] = m[k, i] + m[i, k]
        q[3] = m[k, j] - m[j, k]
    q *= 0.5 / math.sqrt(t * m[3, 3])
    return q


def quaternion_multiply(quaternion1: Any, quaternion0: Any) -> Any:
    """``quaternion1 * quaternion0`` (apply quaternion0 first)."""
    x0, y0, z0, w0 = quaternion0[:4]
    x1, y1, z1, w1 = quaternion1[:4]
    return numpy.array(
        (
            w1 * x0 + x1 * w0 + y1 * z0 - z1 * y0,
            w1 * y0 - x1 * z0 + y1 * w0 + z1 * x0,
            w1 * z0 + x1 * y0 - y1 * x0 + z1 * w0,
            w1 * w0 - x1 * x0 - y1 * y0 - z1 * z0,
        ),
        dtype=numpy.float64,
    )


def quaternion_conjugate(quaternion: Any) -> Any:
    """(-x, -y, -z, w)."""
    x, y, z, w = quaternion[:4]
    return numpy.array((-x, -y, -z, w), dtype=numpy.float64)


def quaternion_inverse(quaternion: Any) -> Any:
    """The inverse: the conjugate over the squared norm."""
    q = numpy.asarray(quaternion, dtype=numpy.float64)[:4]
    return quaternion_conjugate(q) / numpy.dot(q, q)


def quaternion_slerp(
    quat0: Any, quat1: Any, fraction: float, spin: int = 0, shortestpath: bool = True
) -> Any:
    """Spherical interpolation from ``quat0`` (fraction 0) to ``quat1`` (1), with extra ``spin`` turns."""
    q0 = unit_vector(quat0[:4])
    q1 = unit_vector(quat1[:4])
    if fraction == 0.0:
        return q0
    if fraction == 1.0:
        return q1
    d = numpy.dot(q0, q1)
    if abs(abs(d) - 1.0) < _EPS:
        return q0
    if shortestpath and d < 0.0:
        d = -d
        q1 *= -1.0
    angle = math.acos(d) + spin * math.pi
    if abs(angle) < _EPS:
        return q0
    isin = 1.0 / math.sin(angle)
    return q0 * (math.sin((1.0 - fraction) * angle) * isin) + q1 * (math.sin(fraction * angle) * isin)


def random_quaternion(rand: Any = None) -> Any:
    """A uniformly distributed unit quaternion; ``rand`` is three numbers in [0, 1) (random by default)."""
    if rand is None:
        rand = numpy.random.rand(3)
    elif len(rand) != 3:
        raise ValueError("rand must hold three numbers")
    r1 = math.sqrt(1.0 - rand[0])
    r2 = math.sqrt(rand[0])
    t1 = 2.0 * math.pi * rand[1]
    t2 = 2.0 * math.pi * rand[2]
    return numpy.array(
        (math.sin(t1) * r1, math.cos(t1) * r1, math.sin(t2) * r2, math.cos(t2) * r2), dtype=numpy.float64
    )


def random_rotation_matrix(rand: Any = None) -> Any:
    """A uniformly distributed rotation matrix (see :func:`random_quaternion`)."""
    return quaternion_matrix(random_quaternion(rand))


# -- the virtual trackball --------------------------------------------------------------------------


def arcball_map_to_sphere(point: Any, center: Any, radius: float) -> Any:
    """A window point mapped onto the unit sphere of the arcball."""
    v = numpy.array(
        ((point[0] - center[0]) / radius, (center[1] - point[1]) / radius, 0.0), dtype=numpy.float64
    )
    n = v[0] * v[0] + v[1] * v[1]
    if n > 1.0:
        v /= math.sqrt(n)  # outside the ball: the nearest point on its rim
    else:
        v[2] = math.sqrt(1.0 - n)
    return v


def arcball_constrain_to_axis(point: Any, axis: Any) -> Any:
    """The sphere point nearest ``point`` that is perpendicular to ``axis``."""
    v = numpy.array(point, dtype=numpy.float64, copy=True)
    a = numpy.array(axis, dtype=numpy.float64, copy=True)
    v -= a * numpy.dot(a, v)
    n = vector_norm(v)
    if n > _EPS:
        if v[2] < 0.0:
            v *= -1.0
        return v / n
    if a[2] == 1.0:
        return numpy.array([1.0, 0.0, 0.0])
    return unit_vector([-a[1], a[0], 0.0])


def arcball_nearest_axis(point: Any, axes: Any) -> Any:
    """The axis whose constraint arc passes nearest ``point``."""
    p = numpy.array(point, dtype=numpy.float64)
    nearest = None
    best = -1.0
    for axis in axes:
        t = numpy.dot(arcball_constrain_to_axis(p, axis), p)
        if t > best:
            nearest, best = axis, t
    return nearest


class Arcball:
    """Shoemake's virtual trackball: ``place``, then ``down``/``drag`` with window points; ``matrix()``."""

    def __init__(self, initial: Any = None) -> None:
        self._axis = None
        self._axes: list[Any] | None = None
        self._radius = 1.0
        self._center = [0.0, 0.0]
        self._vdown = numpy.array([0.0, 0.0, 1.0])
        self._constrain = False
        if initial is None:
            self._qdown = numpy.array([0.0, 0.0, 0.0, 1.0])
        else:
            initial = numpy.array(initial, dtype=numpy.float64)
            if initial.shape == (4, 4):
                self._qdown = quaternion_from_matrix(initial)
            elif initial.shape == (4,):
                self._qdown = initial / vector_norm(initial)
            else:
                raise ValueError("initial not a quaternion or matrix")
        self._qnow = self._qpre = self._qdown

    def place(self, center: Any, radius: float) -> None:
        """Set the ball's window center and radius."""
        self._radius = float(radius)
        self._center[0] = center[0]
        self._center[1] = center[1]

    def setaxes(self, *axes: Any) -> None:
        """Axes to constrain rotations to (none: free rotation)."""
        self._axes = None if not axes else [unit_vector(axis) for axis in axes]

    def setconstrain(self, constrain: bool) -> None:
        self._constrain = bool(constrain)

    def getconstrain(self) -> bool:
        return self._constrain

    def down(self, point: Any) -> None:
        """The mouse button went down at ``point``."""
        self._vdown = arcball_map_to_sphere(point, self._center, self._radius)
        self._qdown = self._qpre = self._qnow
        if self._constrain and self._axes is not None:
            self._axis = arcball_nearest_axis(self._vdown, self._axes)
            self._vdown = arcball_constrain_to_axis(self._vdown, self._axis)
        else:
            self._axis = None

    def drag(self, point: Any) -> None:
        """The mouse moved to ``point`` with the button down."""
        vnow = arcball_map_to_sphere(point, self._center, self._radius)
        if self._axis is not None:
            vnow = arcball_constrain_to_axis(vnow, self._axis)
        self._qpre = self._qnow
        t = numpy.cross(self._vdown, vnow)
        if numpy.dot(t, t) < _EPS:
            self._qnow = self._qdown
        else:
            q = [t[0], t[1], t[2], numpy.dot(self._vdown, vnow)]
            self._qnow = quaternion_multiply(q, self._qdown)

    def next(self, acceleration: float = 0.0) -> None:
        """Keep spinning in the last drag's direction."""
        q = quaternion_slerp(self._qpre, self._qnow, 2.0 + acceleration, False)
        self._qpre, self._qnow = self._qnow, q

    def matrix(self) -> Any:
        """The current rotation."""
        return quaternion_matrix(self._qnow)
