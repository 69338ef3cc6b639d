"""image_transport's ``compressed`` transport in Python: ``<base>/compressed`` publishers and decoding.

A ROS 1 camera driver publishes through image_transport, so ROS 1 users expect every
``sensor_msgs/Image`` topic to come with ``<base>/compressed`` (``sensor_msgs/CompressedImage``).
:class:`CompressedPublisher` offers that subtopic and encodes a frame only while someone subscribes
to it, so an unwatched camera costs nothing. The ``format`` field and the parameters are
compressed_image_transport's (``<base>/compressed/format`` jpeg|png, ``jpeg_quality``, ``png_level``);
decoding (:func:`decode`) restores the original encoding named before the ``;``.
"""

from ninjemys.image_transport.compressed import (
    CompressedPublisher,
    CompressionParams,
    decode,
    encode,
)

__all__ = ["CompressedPublisher", "CompressionParams", "decode", "encode"]
