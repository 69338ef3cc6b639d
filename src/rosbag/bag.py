"""``rosbag.bag``: re-exports of ninjemys.bag.api under ROS 1's module path."""

from ninjemys.bag.api import (
    Bag,
    BagMessage,
    BagMessageWithConnectionHeader,
    Compression,
    CompressionTuple,
    ROSBagException,
    ROSBagFormatException,
    ROSBagUnindexedException,
    TopicTuple,
    TypesAndTopicsTuple,
)

__all__ = [
    "Bag",
    "BagMessage",
    "BagMessageWithConnectionHeader",
    "Compression",
    "CompressionTuple",
    "ROSBagException",
    "ROSBagFormatException",
    "ROSBagUnindexedException",
    "TopicTuple",
    "TypesAndTopicsTuple",
]
