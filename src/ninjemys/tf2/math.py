"""Rigid transforms as plain 7-tuples ``(tx, ty, tz, qx, qy, qz, qw)``.

The buffer composes a handful of transforms per lookup; for 4-vectors numpy's per-call overhead
(about a microsecond an operation) costs more than the arithmetic, so these are straight-line
float code on tuples. Quaternions are (x, y, z, w), ROS's order, and are assumed unit length
(the buffer refuses others on input). ``compose(a, b)`` is ``a * b``: apply ``b`` first, then ``a``.
The planar helpers at the end (yaw <-> quaternion, SE(2) compose and inverse) are the one copy that
the simulator, the navigation stack and the tools share.
"""

from __future__ import annotations

from math import acos, atan2, cos, pi, sin, sqrt

Transform7 = tuple[float, float, float, float, float, float, float]

IDENTITY: Transform7 = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0)


def compose(a: Transform7, b: Transform7) -> Transform7:
    """``a * b``: the transform that maps a point through ``b`` and then through ``a``."""
    ax, ay, az, qx, qy, qz, qw = a
    bx, by, bz, bqx, bqy, bqz, bqw = b
    # rotate b's translation by a's rotation: v + 2*q x (q x v + w v)
    cx = qy * bz - qz * by + qw * bx
    cy = qz * bx - qx * bz + qw * by
    cz = qx * by - qy * bx + qw * bz
    return (
        ax + bx + 2.0 * (qy * cz - qz * cy),
        ay + by + 2.0 * (qz * cx - qx * cz),
        az + bz + 2.0 * (qx * cy - qy * cx),
        qw * bqx + qx * bqw + qy * bqz - qz * bqy,
        qw * bqy - qx * bqz + qy * bqw + qz * bqx,
        qw * bqz + qx * bqy - qy * bqx + qz * bqw,
        qw * bqw - qx * bqx - qy * bqy - qz * bqz,
    )


def matrix_signed(a: Transform7) -> Transform7:
    """``a`` with the quaternion sign tf2 gets when it composes through 3x3 matrices (the full lookup):
    ``w`` positive when the matrix trace is, else the component of the largest diagonal element."""
    x, y, z, qx, qy, qz, qw = a
    r00, r11, r22 = (
        1.0 - 2.0 * (qy * qy + qz * qz),
        1.0 - 2.0 * (qx * qx + qz * qz),
        1.0 - 2.0 * (qx * qx + qy * qy),
    )
    if r00 + r11 + r22 > 0.0:
        lead = qw
    elif r00 < r11:
        lead = qz if r11 < r22 else qy
    else:
        lead = qz if r00 < r22 else qx
    return a if lead >= 0.0 else (x, y, z, -qx, -qy, -qz, -qw)


def inverse(a: Transform7) -> Transform7:
    """The inverse transform."""
    tx, ty, tz, qx, qy, qz, qw = a
    # rotate -t by the conjugate quaternion (-qx, -qy, -qz, qw)
    cx = -qy * -tz + qz * -ty + qw * -tx
    cy = -qz * -tx + qx * -tz + qw * -ty
    cz = -qx * -ty + qy * -tx + qw * -tz
    return (
        -tx + 2.0 * (-qy * cz + qz * cy),
        -ty + 2.0 * (-qz * cx + qx * cz),
        -tz + 2.0 * (-qx * cy + qy * cx),
        -qx,
        -qy,
        -qz,
        qw,
    )


def inverse_compose(a: Transform7, b: Transform7) -> Transform7:
    """``inverse(a) * b`` in one step: from two frames' transforms to a common root, the one between them."""
    ax, ay, az, qx, qy, qz, qw = a
    bx, by, bz, bqx, bqy, bqz, bqw = b
    dx = bx - ax
    dy = by - ay
    dz = bz - az
    # rotate d by conj(qa) = (-qx, -qy, -qz, qw)
    cx = qz * dy - qy * dz + qw * dx
    cy = qx * dz - qz * dx + qw * dy
    cz = qy * dx - qx * dy + qw * dz
    return (
        dx + 2.0 * (qz * cy - qy * cz),
        dy + 2.0 * (qx * cz - qz * cx),
        dz + 2.0 * (qy * cx - qx * cy),
        qw * bqx - qx * bqw - qy * bqz + qz * bqy,
        qw * bqy + qx * bqz - qy * bqw - qz * bqx,
        qw * bqz - qx * bqy + qy * bqx - qz * bqw,
        qw * bqw + qx * bqx + qy * bqy + qz * bqz,
    )


def transform_point(a: Transform7, x: float, y: float, z: float) -> tuple[float, float, float]:
    """The point ``(x, y, z)`` mapped through ``a`` (rotation, then translation)."""
    rx, ry, rz = rotate_vector(a[3], a[4], a[5], a[6], x, y, z)
    return rx + a[0], ry + a[1], rz + a[2]


def rotate_vector(
    qx: float, qy: float, qz: float, qw: float, x: float, y: float, z: float
) -> tuple[float, float, float]:
    """The vector ``(x, y, z)`` rotated by the unit quaternion ``(qx, qy, qz, qw)``."""
    cx = qy * z - qz * y + qw * x
    cy = qz * x - qx * z + qw * y
    cz = qx * y - qy * x + qw * z
    return (
        x + 2.0 * (qy * cz - qz * cy),
        y + 2.0 * (qz * cx - qx * cz),
        z + 2.0 * (qx * cy - qy * cx),
    )


def quaternion_multiply(
    a: tuple[float, float, float, float], b: tuple[float, float, float, float]
) -> tuple[float, float, float, float]:
    """Hamilton product ``a * b`` of (x, y, z, w) quaternions."""
    qx, qy, qz, qw = a
    bqx, bqy, bqz, bqw = b
    return (
        qw * bqx + qx * bqw + qy * bqz - qz * bqy,
        qw * bqy - qx * bqz + qy * bqw + qz * bqx,
        qw * bqz + qx * bqy - qy * bqx + qz * bqw,
        qw * bqw - qx * bqx - qy * bqy - qz * bqz,
    )


def slerp(
    a: tuple[float, float, float, float], b: tuple[float, float, float, float], ratio: float
) -> tuple[float, float, float, float]:
    """Spherical interpolation from ``a`` (ratio 0) to ``b`` (ratio 1) along the shorter arc, as tf2 does."""
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    dot = ax * bx + ay * by + az * bz + aw * bw
    if dot < 0.0:  # q and -q are the same rotation: take the short way round
        bx, by, bz, bw, dot = -bx, -by, -bz, -bw, -dot
    if dot > 0.9999995:  # nearly equal: the sine below vanishes; a normalized lerp is exact to rounding
        s0, s1 = 1.0 - ratio, ratio
    else:
        theta = acos(dot if dot < 1.0 else 1.0)
        inv = 1.0 / sin(theta)
        s0 = sin((1.0 - ratio) * theta) * inv
        s1 = sin(ratio * theta) * inv
    x = s0 * ax + s1 * bx
    y = s0 * ay + s1 * by
    z = s0 * az + s1 * bz
    w = s0 * aw + s1 * bw
    n = sqrt(x * x + y * y + z * z + w * w)
    return x / n, y / n, z / n, w / n


# -- planar helpers: the one home of yaw, quaternion and SE(2) math for sim, nav and the tools ---------

#: a planar pose or transform (x, y, yaw)
Pose2D = tuple[float, float, float]
Quaternion = tuple[float, float, float, float]


def wrap_angle(a: float) -> float:
    """``a`` wrapped into [-pi, pi)."""
    return (a + pi) % (2.0 * pi) - pi


def angle_diff(a: float, b: float) -> float:
    """``a - b`` wrapped into [-pi, pi)."""
    return (a - b + pi) % (2.0 * pi) - pi


def quaternion_from_yaw(yaw: float) -> Quaternion:
    """The (x, y, z, w) quaternion of a turn by ``yaw`` about z."""
    return 0.0, 0.0, sin(yaw / 2.0), cos(yaw / 2.0)


def quaternion_from_rpy(roll: float, pitch: float, yaw: float) -> Quaternion:
    """tf2's ``Quaternion::setRPY``: roll about x, then pitch about y, then yaw about z (fixed axes)."""
    cr, sr = cos(roll / 2.0), sin(roll / 2.0)
    cp, sp = cos(pitch / 2.0), sin(pitch / 2.0)
    cy, sy = cos(yaw / 2.0), sin(yaw / 2.0)
    return (
        sr * cp * cy - cr * sp * sy,
        cr * sp * cy + sr * cp * sy,
        cr * cp * sy - sr * sp * cy,
        cr * cp * cy + sr * sp * sy,
    )


def yaw_from_quaternion(x: float, y: float, z: float, w: float) -> float:
    """The yaw (rotation about z) of an (x, y, z, w) quaternion, as tf2's ``getYaw``."""
    return atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


def se2_compose(a: Pose2D, b: Pose2D) -> Pose2D:
    """Pose ``a`` then pose ``b`` expressed in ``a``'s frame (yaw wrapped)."""
    c, s = cos(a[2]), sin(a[2])
    return a[0] + c * b[0] - s * b[1], a[1] + s * b[0] + c * b[1], wrap_angle(a[2] + b[2])


def se2_inverse(a: Pose2D) -> Pose2D:
    """The planar transform that undoes ``a``."""
    c, s = cos(a[2]), sin(a[2])
    return -c * a[0] - s * a[1], s * a[0] - c * a[1], wrap_angle(-a[2])
