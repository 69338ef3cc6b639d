"""``cv_bridge.boost.cv_bridge_boost``: ROS 1's compiled helpers, in numpy.

``getCvType``, ``cvtColor2`` and ``cvtColorForDisplay`` raise RuntimeError with ROS 1's texts, as the
Boost.Python module does (CvBridge's methods turn them into CvBridgeError).
"""

from __future__ import annotations

import numpy as np

from ninjemys.cv_bridge.display import cvt_color_for_display
from ninjemys.cv_bridge.encodings import CvBridgeError, convert, cvtype, parse

__all__ = ["CV_MAT_CNWrap", "CV_MAT_DEPTHWrap", "cvtColor2", "cvtColorForDisplay", "getCvType"]


def getCvType(encoding: str) -> int:  # noqa: N802 - ROS 1's name
    """OpenCV's type integer (CV_MAKETYPE) of an image encoding: ``getCvType("bgr8") == 16``."""
    try:
        return cvtype(encoding)
    except CvBridgeError as exc:
        raise RuntimeError(str(exc)) from None


def CV_MAT_CNWrap(i: int) -> int:  # noqa: N802 - ROS 1's name
    """The channel count of an OpenCV type integer."""
    return ((i >> 3) & 511) + 1


def CV_MAT_DEPTHWrap(i: int) -> int:  # noqa: N802 - ROS 1's name
    """The depth code (CV_8U=0 ... CV_64F=6) of an OpenCV type integer."""
    return i & 7


def cvtColor2(img: np.ndarray, encoding_in: str, encoding_out: str) -> np.ndarray:  # noqa: N802
    """``img`` converted from ``encoding_in`` to ``encoding_out`` (cv_bridge's conversion rules)."""
    for encoding in (encoding_in, encoding_out):
        try:
            parse(encoding)
        except CvBridgeError:
            raise RuntimeError(f"Unknown encoding {encoding}") from None
    try:
        return convert(np.asarray(img), encoding_in, encoding_out)
    except CvBridgeError as exc:
        raise RuntimeError(str(exc)) from None


def cvtColorForDisplay(  # noqa: N802 - ROS 1's name
    source: np.ndarray,
    encoding_in: str,
    encoding_out: str,
    do_dynamic_scaling: bool = False,
    min_image_value: float = 0.0,
    max_image_value: float = 0.0,
) -> np.ndarray:
    """An image a viewer can show: 8-bit color or mono, depth scaled, labels colored (see
    :mod:`ninjemys.cv_bridge.display`)."""
    return cvt_color_for_display(
        source, encoding_in, encoding_out, do_dynamic_scaling, min_image_value, max_image_value
    )
