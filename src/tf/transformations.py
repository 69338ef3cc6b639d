"""ROS 1's ``tf.transformations`` (quaternions as x, y, z, w); the code is :mod:`ninjemys.tf2.transformations`."""

from __future__ import annotations

from typing import Any

import numpy

from ninjemys.tf2 import transformations as _core
from ninjemys.tf2.transformations import *  # noqa: F403
from ninjemys.tf2.transformations import _AXES2TUPLE, _EPS, _NEXT_AXIS, _TUPLE2AXES  # noqa: F401


def decompose_matrix(matrix: Any) -> tuple[Any, Any, Any, Any, Any]:
    """(scale, shear, angles, translate, perspective) of a homogeneous matrix; angles are 'sxyz'.

    As ROS 1's, shear and angles are lists (of numpy floats and of floats), the other three arrays,
    so they print the same. ValueError for a singular matrix or M[3, 3] == 0.
    """
    scale, shear, angles, translate, perspective = _core.decompose_matrix(matrix)
    return (
        scale,
        [numpy.float64(v) for v in shear],
        [float(v) for v in angles],
        translate,
        perspective,
    )
