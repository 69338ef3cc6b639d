"""ROS 1's ``tf`` Python package over ninjemys's tf2: ``tf.transformations``, ``tf.TransformListener``,
``tf.TransformBroadcaster``, ``tf.Transformer``, tf's exception names, and ``tf.msg.tfMessage``."""

from tf2_ros import ConnectivityException, ExtrapolationException, LookupException
from tf2_ros import TransformException as Exception  # noqa: A004 (tf's own name)

from . import transformations  # noqa: F401 - ``import tf`` alone gives tf.transformations, as in ROS 1
from .broadcaster import TransformBroadcaster
from .listener import Transformer, TransformerROS, TransformListener

__all__ = [
    "ConnectivityException",
    "Exception",
    "ExtrapolationException",
    "LookupException",
    "TransformBroadcaster",
    "TransformListener",
    "Transformer",
    "TransformerROS",
]
