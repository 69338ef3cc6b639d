"""sensor_msgs/Image <-> a (height, width) or (height, width, channels) array, dtype from the encoding."""

from __future__ import annotations

import re
from typing import Any

import numpy as np

from ros_numpy.registry import converts_from_numpy, converts_to_numpy
from sensor_msgs.msg import Image

#: encoding -> (numpy dtype, channels)
NAMED = {
    "rgb8": (np.uint8, 3),
    "rgba8": (np.uint8, 4),
    "rgb16": (np.uint16, 3),
    "rgba16": (np.uint16, 4),
    "bgr8": (np.uint8, 3),
    "bgra8": (np.uint8, 4),
    "bgr16": (np.uint16, 3),
    "bgra16": (np.uint16, 4),
    "mono8": (np.uint8, 1),
    "mono16": (np.uint16, 1),
    "bayer_rggb8": (np.uint8, 1),
    "bayer_bggr8": (np.uint8, 1),
    "bayer_gbrg8": (np.uint8, 1),
    "bayer_grbg8": (np.uint8, 1),
    "bayer_rggb16": (np.uint16, 1),
    "bayer_bggr16": (np.uint16, 1),
    "bayer_gbrg16": (np.uint16, 1),
    "bayer_grbg16": (np.uint16, 1),
    "yuv422": (np.uint8, 2),
}
_DEPTHS = {
    "8U": np.uint8,
    "8S": np.int8,
    "16U": np.uint16,
    "16S": np.int16,
    "32S": np.int32,
    "32F": np.float32,
    "64F": np.float64,
}
_CV = re.compile(r"^(8U|8S|16U|16S|32S|32F|64F)C([1-4])$")


def _format(encoding: str) -> tuple[Any, int]:
    if encoding in NAMED:
        return NAMED[encoding]
    m = _CV.match(encoding)
    if m is None:
        raise TypeError(f"Unrecognized encoding {encoding}")
    return _DEPTHS[m.group(1)], int(m.group(2))


@converts_to_numpy(Image)
def image_to_numpy(msg: Any) -> np.ndarray:
    dtype_class, channels = _format(msg.encoding)
    dtype = np.dtype(dtype_class).newbyteorder(">" if msg.is_bigendian else "<")
    row_items = msg.step // dtype.itemsize
    data = np.frombuffer(bytes(msg.data), dtype=dtype)
    rows = data[: msg.height * row_items].reshape(msg.height, row_items)
    pixels = rows[:, : msg.width * channels]
    return (
        pixels.reshape(msg.height, msg.width)
        if channels == 1
        else pixels.reshape(msg.height, msg.width, channels)
    )


@converts_from_numpy(Image)
def numpy_to_image(arr: Any, encoding: str) -> Any:
    dtype_class, channels = _format(encoding)
    arr = np.asarray(arr)
    if arr.ndim == 2:
        shape_channels = 1
    elif arr.ndim == 3:
        shape_channels = arr.shape[-1]
    else:
        raise TypeError(f"Expected a 2D or 3D array for {encoding}, got shape {arr.shape}")
    if shape_channels != channels:
        raise TypeError(f"Array has {shape_channels} channels, {encoding} requires {channels}")
    if arr.dtype.type is not np.dtype(dtype_class).type:
        raise TypeError(f"Array is {arr.dtype}, {encoding} requires {np.dtype(dtype_class)}")
    contig = np.ascontiguousarray(arr)
    im = Image(encoding=encoding)
    im.height, im.width = contig.shape[:2]
    im.is_bigendian = int(contig.dtype.byteorder == ">")
    im.step = contig.strides[0]
    im.data = contig.tobytes()
    return im
