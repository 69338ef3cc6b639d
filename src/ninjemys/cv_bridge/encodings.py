"""sensor_msgs image encodings: their numpy types, channel counts, color kinds, and conversions.

The conversion rules are cv_bridge's (C++ ``getConversionCode``): between color encodings (mono,
rgb, bgr, rgba, bgra, yuv422, bayer) any listed pair converts; a generic encoding (``8UC3``, ``32FC1``)
only converts to one with the same number of channels, changing depth; 8 <-> 16 bit depth changes
scale the values (x 65535/255 or 255/65535). Pixel arithmetic follows OpenCV's (fixed-point gray
weights, rounding to nearest), so results match ROS 1's cv_bridge. With OpenCV installed (a runtime
dependency) color changes go through ``cv2.cvtColor`` as ROS 1's do; the numpy path stays for
byte-swapped arrays and a Python without cv2. Bayer demosaicing needs OpenCV.
"""

from __future__ import annotations

import re
from typing import Any

import numpy as np

from ninjemys.errors import NinjemysError


class CvBridgeError(NinjemysError, TypeError):
    """A conversion cv_bridge cannot do (ROS 1's is a TypeError; so is this)."""


CvBridgeError.__module__ = "cv_bridge"

# OpenCV depth codes, for the cvtype integers (CV_MAKETYPE) ROS 1's API exposes
DEPTHS = {"8U": 0, "8S": 1, "16U": 2, "16S": 3, "32S": 4, "32F": 5, "64F": 6}
DEPTH_DTYPES = {
    "8U": "uint8",
    "8S": "int8",
    "16U": "uint16",
    "16S": "int16",
    "32S": "int32",
    "32F": "float32",
    "64F": "float64",
}
DTYPE_DEPTHS = {v: k for k, v in DEPTH_DTYPES.items()}

GRAY, RGB, BGR, RGBA, BGRA, YUV422, BAYER = "GRAY", "RGB", "BGR", "RGBA", "BGRA", "YUV422", "BAYER"

# named encodings: encoding -> (depth, channels, kind)
NAMED: dict[str, tuple[str, int, str]] = {
    "mono8": ("8U", 1, GRAY),
    "mono16": ("16U", 1, GRAY),
    "rgb8": ("8U", 3, RGB),
    "bgr8": ("8U", 3, BGR),
    "rgba8": ("8U", 4, RGBA),
    "bgra8": ("8U", 4, BGRA),
    "rgb16": ("16U", 3, RGB),
    "bgr16": ("16U", 3, BGR),
    "rgba16": ("16U", 4, RGBA),
    "bgra16": ("16U", 4, BGRA),
    "yuv422": ("8U", 2, YUV422),
}
for _pattern in ("rggb", "bggr", "gbrg", "grbg"):
    NAMED[f"bayer_{_pattern}8"] = ("8U", 1, BAYER)
    NAMED[f"bayer_{_pattern}16"] = ("16U", 1, BAYER)

_GENERIC = re.compile(r"(8U|8S|16U|16S|32S|32F|64F)(?:C([0-9]+))?")

# which (source kind, destination kind) pairs convert (cv_bridge's table; same kind = depth change only)
_COLOR = (GRAY, RGB, BGR, RGBA, BGRA)
CONVERTIBLE = {(a, b) for a in _COLOR for b in _COLOR}
CONVERTIBLE |= {(YUV422, b) for b in _COLOR}
CONVERTIBLE |= {(BAYER, b) for b in (GRAY, RGB, BGR)}


def parse(encoding: str) -> tuple[str, int, str | None]:
    """``(depth, channels, color kind or None)`` of an encoding; CvBridgeError if unknown."""
    named = NAMED.get(encoding)
    if named is not None:
        return named
    m = _GENERIC.fullmatch(encoding)
    if m is None:
        raise CvBridgeError(f"Unrecognized image encoding [{encoding}]")
    return m.group(1), int(m.group(2) or 1), None


def dtype_and_channels(encoding: str) -> tuple[str, int]:
    depth, channels, _kind = parse(encoding)
    return DEPTH_DTYPES[depth], channels


def cvtype(encoding: str) -> int:
    """OpenCV's type integer (CV_MAKETYPE(depth, channels)) for an encoding."""
    depth, channels, _kind = parse(encoding)
    return DEPTHS[depth] + ((channels - 1) << 3)


def bit_depth(encoding: str) -> int:
    depth = parse(encoding)[0]
    return int(depth[:-1])


def _max_value(dtype: np.dtype) -> float:
    return float(np.iinfo(dtype).max) if dtype.kind in "ui" else 1.0


def _convert_depth(img: np.ndarray, src_bits: int, dst_bits: int, dst_dtype: np.dtype) -> np.ndarray:
    """OpenCV ``convertTo``: scale between 8 and 16 bit, round to nearest (ties to even), saturate."""
    scale = (
        65535.0 / 255.0
        if (src_bits, dst_bits) == (8, 16)
        else 255.0 / 65535.0
        if (src_bits, dst_bits) == (16, 8)
        else 1.0
    )
    if img.dtype == dst_dtype and scale == 1.0:
        return img.copy()
    if dst_dtype.kind == "f":
        return (img.astype(np.float64) * scale).astype(dst_dtype)
    values = img.astype(np.float64) * scale if scale != 1.0 or img.dtype.kind == "f" else img
    if values.dtype.kind == "f":
        values = np.rint(values)
    info = np.iinfo(dst_dtype)
    return np.clip(values, info.min, info.max).astype(dst_dtype)


def _gray(rgb: np.ndarray) -> np.ndarray:
    """OpenCV's RGB -> gray (input channels in R, G, B order)."""
    r, g, b = (rgb[..., i] for i in range(3))
    if rgb.dtype.kind in "ui":  # 8 and 16 bit: 15-bit fixed-point weights, rounded
        y = (
            r.astype(np.int64) * 9798 + g.astype(np.int64) * 19235 + b.astype(np.int64) * 3735 + (1 << 14)
        ) >> 15
        return y.astype(rgb.dtype)
    out = r.astype(np.float32) * np.float32(0.299) + g * np.float32(0.587) + b * np.float32(0.114)
    return out.astype(rgb.dtype)


def _to_rgba(img: np.ndarray, kind: str) -> np.ndarray:
    """Any of GRAY/RGB/BGR/RGBA/BGRA as an RGBA array (alpha = the type's maximum when absent)."""
    if kind == GRAY:
        img = img.reshape(img.shape[0], img.shape[1])
        channels = [img, img, img]
    elif kind in (RGB, RGBA):
        channels = [img[..., 0], img[..., 1], img[..., 2]]
    else:
        channels = [img[..., 2], img[..., 1], img[..., 0]]
    if kind in (RGBA, BGRA):
        alpha = img[..., 3]
    else:
        alpha = np.full(channels[0].shape, _max_value(img.dtype), dtype=img.dtype)
    return np.stack([*channels, alpha], axis=-1)


def _from_rgba(rgba: np.ndarray, kind: str, src_kind: str) -> np.ndarray:
    if kind == GRAY:
        if src_kind == GRAY:
            return np.ascontiguousarray(rgba[..., 0])
        return _gray(rgba[..., :3])
    order = {RGB: (0, 1, 2), BGR: (2, 1, 0), RGBA: (0, 1, 2, 3), BGRA: (2, 1, 0, 3)}[kind]
    return np.ascontiguousarray(rgba[..., list(order)])


def _yuv422_to_rgb(img: np.ndarray) -> np.ndarray:
    """UYVY (ROS ``yuv422``) to RGB, OpenCV's fixed-point BT.601 (studio swing)."""
    u = img[:, 0::2, 0].astype(np.int64) - 128
    v = img[:, 1::2, 0].astype(np.int64) - 128
    y = img[..., 1].astype(np.int64)
    u = np.repeat(u, 2, axis=1)[:, : y.shape[1]]
    v = np.repeat(v, 2, axis=1)[:, : y.shape[1]]
    yy = np.maximum(0, y - 16) * 1220542
    half = 1 << 19
    r = (yy + 1673527 * v + half) >> 20
    g = (yy - 852492 * v - 409993 * u + half) >> 20
    b = (yy + 2116026 * u + half) >> 20
    return np.clip(np.stack([r, g, b], axis=-1), 0, 255).astype(np.uint8)


_BAYER_CODES = {"rggb": "BayerBG", "bggr": "BayerRG", "gbrg": "BayerGR", "grbg": "BayerGB"}


def _bayer(img: np.ndarray, encoding: str, kind: str) -> np.ndarray:
    try:
        import cv2
    except ImportError:
        raise CvBridgeError(
            f"converting {encoding} to color needs OpenCV (pip install opencv-python-headless); "
            "'passthrough' gives the raw mosaic"
        ) from None
    pattern = encoding.split("_")[1].rstrip("0123456789")
    target = {GRAY: "GRAY", RGB: "RGB", BGR: "BGR"}[kind]
    return cv2.cvtColor(img, getattr(cv2, f"COLOR_{_BAYER_CODES[pattern]}2{target}"))


_CV_NATIVE = (np.dtype(np.uint8), np.dtype(np.uint16), np.dtype(np.float32))


def _cvt_color(img: np.ndarray, src_kind: str, dst_kind: str) -> np.ndarray | None:
    """OpenCV's ``cvtColor`` between GRAY/RGB/BGR/RGBA/BGRA, as ROS 1's cv_bridge converts (and 5-60x
    faster than the numpy path); None when OpenCV is absent or the array is not one it takes."""
    if img.dtype not in _CV_NATIVE or not img.dtype.isnative:
        return None
    try:
        import cv2
    except ImportError:
        return None
    code = getattr(cv2, f"COLOR_{src_kind}2{dst_kind}", None)
    if code is None:
        return None
    if src_kind == GRAY and img.ndim == 3:
        img = img[..., 0]
    return np.asarray(cv2.cvtColor(img, code))


def convert(img: np.ndarray, src: str, dst: str) -> np.ndarray:
    """``img`` (in encoding ``src``) as encoding ``dst``; a new array. CvBridgeError if impossible."""
    if src == dst:
        return img.copy()
    src_depth, src_ch, src_kind = parse(src)
    dst_depth, dst_ch, dst_kind = parse(dst)
    dst_dtype = np.dtype(DEPTH_DTYPES[dst_depth])
    src_bits, dst_bits = int(src_depth[:-1]), int(dst_depth[:-1])
    if src_kind is None:
        if dst_kind is not None:
            raise CvBridgeError(
                f"[{src}] is not a color format. but [{dst}] is. The conversion does not make sense"
            )
        if src_ch != dst_ch:
            raise CvBridgeError(f"[{src}] and [{dst}] do not have the same number of channel")
        return _convert_depth(img, src_bits, dst_bits, dst_dtype)
    if dst_kind is None:
        if src_ch != dst_ch:
            raise CvBridgeError(
                f"[{src}] is a color format but [{dst}] is not so they must have the same OpenCV type, "
                "CV_8UC3, CV16UC1 ...."
            )
        return _convert_depth(img, src_bits, dst_bits, dst_dtype)
    if (src_kind, dst_kind) not in CONVERTIBLE:
        raise CvBridgeError(f"Unsupported conversion from [{src}] to [{dst}]")
    if src_kind == BAYER:
        out = _bayer(img, src, dst_kind)
    elif src_kind == YUV422:
        rgb = _yuv422_to_rgb(img)
        out = (
            np.ascontiguousarray(img[..., 1])
            if dst_kind == GRAY
            else _from_rgba(_to_rgba(rgb, RGB), dst_kind, RGB)
        )
    elif src_kind == dst_kind:
        out = img
    else:
        converted = _cvt_color(img, src_kind, dst_kind)
        out = converted if converted is not None else _from_rgba(_to_rgba(img, src_kind), dst_kind, src_kind)
    if src_bits != dst_bits or out.dtype != dst_dtype:
        out = _convert_depth(out, src_bits, dst_bits, dst_dtype)
    elif out is img:
        out = img.copy()
    return out


def decode_source_encoding(image: Any) -> str:
    """The encoding of an array a decoder produced (OpenCV's order: BGR / BGRA / mono)."""
    channels = 1 if image.ndim == 2 else image.shape[2]
    bits = "16" if image.dtype == np.uint16 else "8"
    return {1: f"mono{bits}", 3: f"bgr{bits}", 4: f"bgra{bits}"}.get(channels, f"{bits}UC{channels}")
