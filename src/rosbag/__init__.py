"""ROS 1's ``rosbag`` Python API, served by ninjemys (``import rosbag; rosbag.Bag(...)``)."""

from rosbag.bag import (
    Bag,
    BagMessage,
    Compression,
    ROSBagException,
    ROSBagFormatException,
    ROSBagUnindexedException,
)

__all__ = [
    "Bag",
    "BagMessage",
    "Compression",
    "ROSBagException",
    "ROSBagFormatException",
    "ROSBagUnindexedException",
]
