"""cv_bridge's ``cvtColorForDisplay``: any image as an 8-bit color or mono image a viewer can show.

Its rules are cv_bridge's (C++ ``cvtColorForDisplay``): an empty output encoding is guessed (bgr8 for
one channel of 8, 16 or 32 bits and for 8 or 16 bit color); a ``32SC1`` label image shown as bgr8
gets one color per label (label -1 and other negative ones black); with ``do_dynamic_scaling`` or a
``min``/``max`` range, one channel is scaled linearly to 0..255 (a constant image becomes gray 128);
otherwise the image is converted as its encoding says, ``16UC1`` depth taken as mono16.
"""

from __future__ import annotations

import numpy as np

from ninjemys.cv_bridge.encodings import NAMED, CvBridgeError, convert, parse

_PREFIX = "cv_bridge.cvtColorForDisplay()"

#: the label colors (RGB, 146 of them, cycled): the X11 named colors in alphabetical order
_LABEL_RGB = bytes.fromhex(
    "eff8fff9ebd600ffff7effd3effffff5f5dcffe3c4000000ffebcd0000ff892be1a42a2adeb8865f9e9f7eff00d2691e"
    "ff7e506394ecfff8dcdc133b00ffff00008a008a8ab8850aa9a9a9006300a9a9a9bcb76b8a008a546b2eff8b009931cc"
    "8a0000e995798fbb8f473c8a2e4f4f2e4f4f00ced19300d2ff139200beff6969696969691e90ffb12121fff9ef218a21"
    "ff00ffdcdcdcf8f8ffffd600daa41f808080008000acff2e808080efffefff69b4cd5c5c4a0082ffffefefe68be6e6f9"
    "ffeff57bfb00fff9cdacd7e6ef8080dffffff9f9d2d2d2d290ed90d2d2d2ffb6c1ff9f791fb1aa86cef9778799778799"
    "afc4deffffdf00ff0031cd31f9efe6ff00ff80000066cdaa0000cdb954d2926fdb3bb3707a68ed00f99a47d1ccc61585"
    "18186ff5fff9ffe3e0ffe3b5ffdeac000080fcf5e68080006b8e22ffa400ff4500da6fd5ede8aa97fa97aeededffeed4"
    "ffdab8cd853effc0cadd9fddafdfe6800080ff0000bb8f8f4169e08a4512f98071f9a35f2d8a56fff5ed9f522cc0c0c0"
    "86ceeb6a5acd6f80906f8090fff9f900ff7e4682b4d2b48b008080d7bed7ff624640dfd0ed82edf5deb3fffffff5f5f5"
    "ffff009acd31"
)
LABEL_COLORS = np.frombuffer(_LABEL_RGB, dtype=np.uint8).reshape(-1, 3)

#: what the output may be: the 8-bit color and mono encodings
_DISPLAYABLE = {
    name
    for name, (depth, _ch, _kind) in NAMED.items()
    if depth == "8U" and name.startswith(("mono", "rgb", "bgr"))
}


def _guess(encoding_in: str) -> str:
    try:
        depth, channels, _kind = parse(encoding_in)
    except CvBridgeError:
        raise RuntimeError(f"{_PREFIX} output encoding is empty and cannot be guessed.") from None
    bits = int(depth[:-1])
    if (channels == 1 and bits in (8, 16, 32)) or (channels > 1 and bits in (8, 16)):
        return "bgr8"
    raise RuntimeError(f"{_PREFIX} output encoding is empty and cannot be guessed.")


def _labels(source: np.ndarray) -> np.ndarray:
    labels = np.asarray(source, dtype=np.int32)
    if labels.ndim == 3:
        labels = labels[..., 0]
    index = np.fmod(labels, len(LABEL_COLORS))  # C's %: negative labels stay negative (black)
    rgb = np.where((index >= 0)[..., None], LABEL_COLORS[np.clip(index, 0, None)], 0).astype(np.uint8)
    return np.ascontiguousarray(rgb[..., ::-1])


def _scaled(source: np.ndarray, low: float, high: float) -> np.ndarray:
    """(source - low) * 255 / (high - low) as mono8: the subtraction saturates in the source's type, as
    OpenCV's ``Mat - scalar`` does, the product rounds to nearest and saturates."""
    if source.dtype.kind in "ui":
        info = np.iinfo(source.dtype)
        shifted = np.clip(np.rint(source.astype(np.float64) - low), info.min, info.max)
    else:
        shifted = (source - source.dtype.type(low)).astype(np.float64)
    return np.clip(np.rint(shifted * (255.0 / (high - low))), 0, 255).astype(np.uint8)


def cvt_color_for_display(
    source: np.ndarray,
    encoding_in: str,
    encoding_out: str,
    do_dynamic_scaling: bool = False,
    min_image_value: float = 0.0,
    max_image_value: float = 0.0,
) -> np.ndarray:
    """``source`` (in ``encoding_in``) as ``encoding_out`` for display; RuntimeError (ROS 1's texts) if it cannot be."""
    encoding = encoding_out or _guess(encoding_in)
    if encoding not in _DISPLAYABLE:
        raise RuntimeError(
            f"{_PREFIX} does not have an output encoding that is color or mono, and has is bit in depth"
        )
    if encoding == "bgr8" and encoding_in == "32SC1":
        return _labels(source)
    channels = 1 if source.ndim < 3 else source.shape[2]
    low, high = float(min_image_value), float(max_image_value)
    if do_dynamic_scaling:
        if channels != 1:
            raise RuntimeError(f"{_PREFIX} scaling for images with more than one channel is unsupported")
        low, high = float(np.min(source)), float(np.max(source))
        if low == high:
            return np.full((source.shape[0], source.shape[1], 3), 128, dtype=np.uint8)
    if low != high:
        if channels != 1:
            raise RuntimeError(f"{_PREFIX} scaling for images with more than one channel is unsupported")
        mono = _scaled(source.reshape(source.shape[0], source.shape[1]), low, high)
        return convert(mono, "mono8", encoding)
    typed = "mono16" if encoding_in == "16UC1" else encoding_in
    try:
        return convert(np.asarray(source), typed, encoding)
    except CvBridgeError as exc:
        raise RuntimeError(
            f"{_PREFIX} while trying to convert image from '{encoding_in}' to '{encoding}' an exception "
            f"was thrown ({exc})"
        ) from None


__all__ = ["LABEL_COLORS", "cvt_color_for_display"]
