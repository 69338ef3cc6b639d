"""Encoding and decoding sensor_msgs/CompressedImage the way compressed_image_transport does."""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any

import numpy as np

from ninjemys.cv_bridge import CvBridge, CvBridgeError
from ninjemys.cv_bridge.encodings import parse
from ninjemys.idl.loader import get_message_class

__all__ = ["CompressedPublisher", "CompressionParams", "decode", "encode"]

_bridge = CvBridge()


@dataclass(frozen=True)
class CompressionParams:
    """compressed_image_transport's parameters (its dynamic_reconfigure defaults)."""

    format: str = "jpeg"
    jpeg_quality: int = 80
    png_level: int = 9


def _cv2() -> Any:
    import cv2  # a runtime dependency; imported here so importing this module costs nothing

    return cv2


def encode(img_msg: Any, params: CompressionParams = CompressionParams()) -> Any:
    """A CompressedImage of ``img_msg`` with compressed_image_transport's ``format`` text.

    JPEG takes 8/16-bit images as bgr8 (color) or mono8; PNG keeps 16 bits (bgr16 for color).
    The format reads ``"<encoding>; jpeg compressed bgr8"`` so a subscriber can restore the encoding.
    """
    cv2 = _cv2()
    depth, _channels, kind = parse(img_msg.encoding)
    if depth not in ("8U", "16U"):
        raise CvBridgeError(
            f"compressed transport: {img_msg.encoding} images cannot be compressed (8 or 16 bit only)"
        )
    color = kind not in (None, "GRAY")
    out = get_message_class("sensor_msgs/CompressedImage")()
    out.header = img_msg.header
    if params.format == "png":
        bits = "16" if depth == "16U" else "8"
        target = f"bgr{bits}" if color else ""
        out.format = f"{img_msg.encoding}; png compressed {target}"
        im = _bridge.imgmsg_to_cv2(img_msg, target or "passthrough")
        ok, buf = cv2.imencode(".png", im, [cv2.IMWRITE_PNG_COMPRESSION, int(params.png_level)])
    elif params.format == "jpeg":
        target = "bgr8" if color else "mono8"
        out.format = f"{img_msg.encoding}; jpeg compressed {target}"
        im = _bridge.imgmsg_to_cv2(img_msg, target)
        ok, buf = cv2.imencode(".jpg", im, [cv2.IMWRITE_JPEG_QUALITY, int(params.jpeg_quality)])
    else:
        raise CvBridgeError(f"compressed transport: unknown format '{params.format}' (jpeg or png)")
    if not ok:
        raise CvBridgeError(
            f"compressed transport: OpenCV could not encode {img_msg.encoding} as {params.format}"
        )
    out.data = buf.tobytes()
    return out


def decode(cmsg: Any) -> Any:
    """The sensor_msgs/Image a CompressedImage came from (its encoding restored from ``format``)."""
    cv2 = _cv2()
    data = bytes(cmsg.data)
    try:
        im = cv2.imdecode(np.frombuffer(data, np.uint8), cv2.IMREAD_UNCHANGED) if data else None
    except cv2.error:
        im = None
    if im is None:
        raise CvBridgeError(f"compressed transport: cannot decode the image data (format '{cmsg.format}')")
    fmt = cmsg.format or ""
    original = fmt.split(";", 1)[0].strip() if ";" in fmt else ""
    if original:
        try:
            parse(original)
        except CvBridgeError:
            original = ""
    if not original:  # an old-style format ("jpeg"): bgr8 / mono8 by channel count, as ROS 1 does
        msg = _bridge.cv2_to_imgmsg(im, "bgr8" if im.ndim == 3 and im.shape[2] == 3 else "passthrough")
        if im.ndim == 2 and im.dtype == np.uint8:
            msg.encoding = "mono8"
    else:
        source = "bgr8" if im.ndim == 3 and im.dtype == np.uint8 else "bgr16" if im.ndim == 3 else None
        if source is not None:
            if im.shape[2] == 4:
                source = source.replace("bgr", "bgra")
            tmp = _bridge.cv2_to_imgmsg(im, source)
            im = _bridge.imgmsg_to_cv2(tmp, original)
        msg = _bridge.cv2_to_imgmsg(np.ascontiguousarray(im), original)
    msg.header = cmsg.header
    return msg


class CompressedPublisher:
    """``<base>/compressed`` next to an Image publisher; encodes only while it has subscribers.

    The parameters are read from the parameter server under ``<base>/compressed/`` at most once a
    second (a master round trip per frame would cost more than the encoding).
    """

    def __init__(self, node: Any, base_topic: str, queue_size: int = 2) -> None:
        self._node = node
        self.topic = node.resolve_name(base_topic) + "/compressed"
        self._pub = node.publisher(
            self.topic, get_message_class("sensor_msgs/CompressedImage"), queue_size=queue_size
        )
        self._params = CompressionParams()
        self._read_at = -1.0

    def get_num_connections(self) -> int:
        return int(self._pub.get_num_connections())

    def params(self) -> CompressionParams:
        """The current parameters (refreshed once a second); a bad value keeps the default, with a warning."""
        now = time.monotonic()
        if now - self._read_at >= 1.0:
            self._read_at = now
            d = CompressionParams()
            get = self._node.get_param
            fmt = str(get(self.topic + "/format", d.format))
            if fmt not in ("jpeg", "png"):
                self._node.log.warn(f"{self.topic}/format: '{fmt}' is not jpeg or png; using jpeg")
                fmt = "jpeg"
            try:
                q = min(100, max(1, int(get(self.topic + "/jpeg_quality", d.jpeg_quality))))
                lvl = min(9, max(1, int(get(self.topic + "/png_level", d.png_level))))
            except (TypeError, ValueError):
                self._node.log.warn(
                    f"{self.topic}: jpeg_quality and png_level must be integers; using defaults"
                )
                q, lvl = d.jpeg_quality, d.png_level
            self._params = CompressionParams(fmt, q, lvl)
        return self._params

    def publish(self, img_msg: Any) -> None:
        """Encode and publish ``img_msg`` if anyone listens; otherwise do nothing at all."""
        if self._pub.get_num_connections():
            self._pub.publish(encode(img_msg, self.params()))

    def publish_compressed(self, cmsg: Any) -> None:
        """Publish an already compressed image as it is, if anyone listens."""
        if self._pub.get_num_connections():
            self._pub.publish(cmsg)

    def unregister(self) -> None:
        self._pub.unregister()
