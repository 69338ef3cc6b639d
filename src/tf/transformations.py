"""ROS 1's ``tf.transformations`` (quaternions as x, y, z, w); the code is :mod:`ninjemys.tf2.transformations`."""

from ninjemys.tf2.transformations import *  # noqa: F403
from ninjemys.tf2.transformations import _AXES2TUPLE, _EPS, _NEXT_AXIS, _TUPLE2AXES  # noqa: F401
