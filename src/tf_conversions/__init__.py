"""ROS 1's ``tf_conversions``: posemath, the conversions between PyKDL frames, tf tuples, Pose
messages, 4x4 matrices and OpenCV camera extrinsics (``from tf_conversions import posemath``)."""

from .posemath import *  # noqa: F403 - ROS 1's package re-exports posemath whole
