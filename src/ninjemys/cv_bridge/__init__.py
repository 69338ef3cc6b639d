"""cv_bridge: sensor_msgs/Image and CompressedImage <-> numpy arrays (what OpenCV calls images).

Like ROS 1's, it converts with OpenCV (``opencv-python-headless``, a dependency of ninjemys):
``cv2.cvtColor`` for color changes, ``cv2.imencode``/``imdecode`` for compressed images. Without
cv2 (a Python where it was removed) raw images still convert with numpy and compressed ones with
Pillow; with neither, the error says which to install. Differences from ROS 1, on purpose:
``step`` is honoured (row padding), a too-short ``data`` is an error naming the sizes instead of a
numpy traceback, and decoded compressed images are treated as mono/bgr/bgra by their channel count
(ROS 1 assumes bgr8 and fails on grayscale JPEGs).
"""

from __future__ import annotations

import sys
from typing import Any

import numpy as np

from ninjemys.cv_bridge.encodings import (
    DEPTH_DTYPES,
    DEPTHS,
    DTYPE_DEPTHS,
    CvBridgeError,
    convert,
    cvtype,
    decode_source_encoding,
    dtype_and_channels,
)
from ninjemys.idl.loader import get_message_class

__all__ = ["CvBridge", "CvBridgeError"]

_NEED_CODEC = (
    "compressed images need OpenCV (pip install opencv-python-headless) or Pillow (pip install pillow); "
    "neither is installed"
)
_PIL_FORMATS = {
    "jpg": "JPEG",
    "jpeg": "JPEG",
    "jpe": "JPEG",
    "png": "PNG",
    "bmp": "BMP",
    "dib": "BMP",
    "tif": "TIFF",
    "tiff": "TIFF",
    "pbm": "PPM",
    "pgm": "PPM",
    "ppm": "PPM",
    "webp": "WEBP",
    "jp2": "JPEG2000",
}


def _codec() -> tuple[str, Any]:
    """('cv2', module) or ('pil', PIL.Image), whichever is installed (OpenCV first)."""
    try:
        import cv2

        return "cv2", cv2
    except ImportError:
        pass
    try:
        from PIL import Image

        return "pil", Image
    except ImportError:
        raise CvBridgeError(_NEED_CODEC) from None


def _swap_rb(arr: np.ndarray) -> np.ndarray:
    """RGB(A) <-> BGR(A); other shapes unchanged."""
    if arr.ndim == 3 and arr.shape[2] in (3, 4):
        order = [2, 1, 0, 3][: arr.shape[2]]
        return np.ascontiguousarray(arr[..., order])
    return arr


class CvBridge:
    """Converts between ROS image messages and numpy arrays (ROS 1's ``cv_bridge.CvBridge``)."""

    def __init__(self) -> None:
        self.cvtype_to_name = {DEPTHS[d] + ((c - 1) << 3): f"{d}C{c}" for d in DEPTHS for c in (1, 2, 3, 4)}
        self.cvdepth_to_numpy_depth = {DEPTHS[d]: DEPTH_DTYPES[d] for d in DEPTHS}
        self.numpy_type_to_cvtype = {**DTYPE_DEPTHS, **DEPTH_DTYPES}

    # -- type helpers (ROS 1's names) ------------------------------------------------------------
    def dtype_with_channels_to_cvtype2(self, dtype: np.dtype, n_channels: int) -> str:
        try:
            return f"{DTYPE_DEPTHS[np.dtype(dtype).name]}C{n_channels}"
        except KeyError:
            raise CvBridgeError(f"numpy type {np.dtype(dtype).name} has no OpenCV equivalent") from None

    def cvtype2_to_dtype_with_channels(self, cvtype: int) -> tuple[str, int]:
        return self.cvdepth_to_numpy_depth[cvtype & 7], (cvtype >> 3) + 1

    def encoding_to_cvtype2(self, encoding: str) -> int:
        return cvtype(encoding)

    def encoding_to_dtype_with_channels(self, encoding: str) -> tuple[str, int]:
        return dtype_and_channels(encoding)

    # -- raw images ------------------------------------------------------------------------------
    def imgmsg_to_cv2(self, img_msg: Any, desired_encoding: str = "passthrough") -> np.ndarray:
        """The image as an array (height x width [x channels]); converted unless ``passthrough``.

        A passthrough array is a read-only view of the message's data, as in ROS 1.
        """
        dtype_name, channels = dtype_and_channels(img_msg.encoding)
        dtype = np.dtype(dtype_name).newbyteorder(">" if img_msg.is_bigendian else "<")
        height, width = img_msg.height, img_msg.width
        row = width * channels * dtype.itemsize
        step = img_msg.step or row
        data = img_msg.data
        if isinstance(data, str):
            data = data.encode("latin-1")
        elif isinstance(data, list | tuple):
            data = bytes(data)  # a message built by hand with a list of ints
        size = len(data) if not isinstance(data, memoryview) else data.nbytes
        if step < row or size < step * (height - 1) + row:
            raise CvBridgeError(
                f"sensor_msgs/Image: {img_msg.encoding} {width}x{height} needs step >= {row} and "
                f"{step * height} bytes of data, got step {img_msg.step} and {size} bytes"
            )
        shape = (height, width) if channels == 1 else (height, width, channels)
        if height == 0 or width == 0:
            im = np.zeros(shape, dtype=dtype)
        elif step == row:
            im = np.frombuffer(data, dtype=dtype, count=height * width * channels).reshape(shape)
        else:
            rows = np.frombuffer(data, dtype=np.uint8, count=step * (height - 1) + row)
            strides = (step, channels * dtype.itemsize, dtype.itemsize)[: len(shape)]
            im = np.ndarray(shape, dtype=dtype, buffer=rows, strides=strides)
        if img_msg.is_bigendian == (sys.byteorder == "little"):
            im = im.byteswap().view(im.dtype.newbyteorder())
        if desired_encoding == "passthrough":
            return im
        return convert(im, img_msg.encoding, desired_encoding)

    def cv2_to_imgmsg(self, cvim: np.ndarray, encoding: str = "passthrough", header: Any = None) -> Any:
        """A sensor_msgs/Image holding the array's bytes; ``encoding`` must fit its type and channels."""
        if not isinstance(cvim, np.ndarray | np.generic):
            raise TypeError("Your input type is not a numpy array")
        Image = get_message_class("sensor_msgs/Image")
        msg = Image()
        msg.height = cvim.shape[0]
        msg.width = cvim.shape[1]
        if header is not None:
            msg.header = header
        cv_type = self.dtype_with_channels_to_cvtype2(cvim.dtype, 1 if cvim.ndim < 3 else cvim.shape[2])
        if encoding == "passthrough":
            msg.encoding = cv_type
        else:
            msg.encoding = encoding
            if self.cvtype_to_name.get(cvtype(encoding)) != cv_type:
                raise CvBridgeError(
                    f"encoding specified as {encoding}, but image has incompatible type {cv_type}"
                )
        if cvim.dtype.byteorder == ">":
            msg.is_bigendian = True
        msg.data = np.ascontiguousarray(cvim).tobytes()
        msg.step = len(msg.data) // msg.height if msg.height else 0
        return msg

    # -- compressed images -------------------------------------------------------------------------
    def compressed_imgmsg_to_cv2(
        self, cmprs_img_msg: Any, desired_encoding: str = "passthrough"
    ) -> np.ndarray:
        """Decode a CompressedImage (color comes out in OpenCV's BGR order for ``passthrough``)."""
        kind, codec = _codec()
        data = bytes(cmprs_img_msg.data)
        if kind == "cv2":
            im = codec.imdecode(np.frombuffer(data, dtype=np.uint8), codec.IMREAD_UNCHANGED)
            if im is None:
                raise CvBridgeError(f"cannot decode the {cmprs_img_msg.format or 'compressed'} image data")
        else:
            import io

            try:
                with codec.open(io.BytesIO(data)) as pil:
                    pil.load()
                    if pil.mode not in ("L", "RGB", "RGBA", "I;16"):
                        pil = pil.convert("RGBA" if "A" in pil.mode else "RGB")
                    im = _swap_rb(np.asarray(pil))
            except OSError as exc:
                raise CvBridgeError(
                    f"cannot decode the {cmprs_img_msg.format or 'compressed'} image data: {exc}"
                ) from None
        if desired_encoding == "passthrough":
            return im
        return convert(im, decode_source_encoding(im), desired_encoding)

    def cv2_to_compressed_imgmsg(self, cvim: np.ndarray, dst_format: str = "jpg") -> Any:
        """Encode an array (BGR order for color, as OpenCV) as a CompressedImage in ``dst_format``."""
        if not isinstance(cvim, np.ndarray | np.generic):
            raise TypeError("Your input type is not a numpy array")
        kind, codec = _codec()
        msg = get_message_class("sensor_msgs/CompressedImage")()
        msg.format = dst_format
        if kind == "cv2":
            try:
                ok, buf = codec.imencode("." + dst_format, cvim)
            except codec.error as exc:  # an unknown extension, or a type the format cannot hold
                raise CvBridgeError(
                    f"OpenCV cannot encode a {cvim.dtype} {cvim.shape} image as {dst_format}: "
                    f"{str(exc).strip().splitlines()[-1]}"
                ) from None
            if not ok:
                raise CvBridgeError(
                    f"OpenCV could not encode a {cvim.dtype} {cvim.shape} image as {dst_format}"
                )
            msg.data = buf.tobytes()
            return msg
        import io

        fmt = _PIL_FORMATS.get(dst_format.lower())
        if fmt is None:
            raise CvBridgeError(
                f"Pillow cannot write format '{dst_format}' (known: {', '.join(sorted(_PIL_FORMATS))})"
            )
        try:
            image = codec.fromarray(_swap_rb(np.ascontiguousarray(cvim)))
            out = io.BytesIO()
            image.save(out, format=fmt)
        except (OSError, TypeError, ValueError, KeyError) as exc:
            raise CvBridgeError(
                f"Pillow could not encode a {cvim.dtype} {cvim.shape} image as {dst_format}: {exc}"
            ) from None
        msg.data = out.getvalue()
        return msg
