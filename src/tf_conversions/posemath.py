"""tf_conversions.posemath: a pose as a PyKDL ``Frame``, to and from the other forms ROS 1 code holds.

Written against Noetic's module: the same function names and arguments, and, as there, PyKDL's names
star-imported (scripts write ``posemath.Frame``) next to geometry_msgs' ``Pose``/``Point``/``Quaternion``.
"""

from __future__ import annotations

from typing import Any

import numpy

import rospy  # noqa: F401 - posemath's namespace in ROS 1 carries it
from geometry_msgs.msg import Point, Pose, Quaternion  # noqa: F401 - likewise
from PyKDL import *  # noqa: F403 - ROS 1's posemath re-exports PyKDL
from PyKDL import Frame, Rotation, Vector
from tf import transformations  # noqa: F401 - likewise


def fromTf(tf: Any) -> Frame:
    """A ``(translation, quaternion)`` pair from ``tf.Transformer.lookupTransform`` as a Frame."""
    (x, y, z), (qx, qy, qz, qw) = tf
    return Frame(Rotation.Quaternion(qx, qy, qz, qw), Vector(x, y, z))


def toTf(f: Frame) -> tuple[tuple[float, float, float], tuple[float, float, float, float]]:
    """The ``(translation, quaternion)`` pair ``tf.TransformBroadcaster.sendTransform`` takes."""
    return (f.p[0], f.p[1], f.p[2]), f.M.GetQuaternion()


def fromMsg(p: Any) -> Frame:
    """A geometry_msgs/Pose as a Frame."""
    o, q = p.orientation, p.position
    return Frame(Rotation.Quaternion(o.x, o.y, o.z, o.w), Vector(q.x, q.y, q.z))


def toMsg(f: Frame) -> Pose:
    """A Frame as a new geometry_msgs/Pose."""
    p = Pose()
    o = p.orientation
    o.x, o.y, o.z, o.w = f.M.GetQuaternion()
    p.position.x, p.position.y, p.position.z = f.p[0], f.p[1], f.p[2]
    return p


def fromMatrix(m: Any) -> Frame:
    """The top 3x4 of a homogeneous 4x4 array as a Frame."""
    rotation = Rotation(*(float(m[i, j]) for i in range(3) for j in range(3)))
    return Frame(rotation, Vector(m[0, 3], m[1, 3], m[2, 3]))


def toMatrix(f: Frame) -> Any:
    """A Frame as a 4x4 homogeneous numpy array."""
    rows = [[f.M[i, 0], f.M[i, 1], f.M[i, 2], f.p[i]] for i in range(3)]
    return numpy.array([*rows, [0, 0, 0, 1]])


def fromCameraParams(cv: Any, rvec: Any, tvec: Any) -> Frame:
    """A camera pose from a Rodrigues vector and a translation (3x1), through ``cv.Rodrigues2`` as in
    ROS 1: pass the legacy ``cv`` module (or any object with a ``Rodrigues2(src, dst)``)."""
    m = numpy.array(
        [
            [0, 0, 0, tvec[0, 0]],
            [0, 0, 0, tvec[1, 0]],
            [0, 0, 0, tvec[2, 0]],
            [0, 0, 0, 1.0],
        ],
        dtype=numpy.float32,
    )
    cv.Rodrigues2(rvec, m[:3, :3])
    return fromMatrix(m)
