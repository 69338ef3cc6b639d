"""Pinhole and stereo camera models, with ROS 1's names and results.

A ``CameraInfo`` carries K (3x3 intrinsics), D (distortion), R (rectification) and P (3x4 projection)
for the full sensor; binning and a region of interest shrink the image the driver sends, so the
model scales the focal lengths by the binning and moves the principal point by the ROI offset, as
ROS 1's model does. The matrices are ``numpy.matrix`` as in ROS 1, because user code multiplies them
with ``*`` (``model.P * point``). Projections use the rectified camera (P); ``rectifyPoint`` and
``rectifyImage`` undo lens distortion through OpenCV, as ROS 1's do.
"""

from __future__ import annotations

import copy
import math
from collections.abc import Sequence
from typing import Any

import numpy


def _matrix(rows: int, cols: int, values: Sequence[float]) -> Any:
    """A float64 ``numpy.matrix`` of the given shape from a flat list (zero-padded, as ROS 1's)."""
    flat = numpy.zeros(rows * cols, dtype="float64")
    given = numpy.asarray(list(values), dtype="float64")[: rows * cols]
    flat[: given.size] = given
    return numpy.matrix(flat.reshape(rows, cols))


def _field(msg: Any, upper: str) -> Any:
    """A CameraInfo matrix field: ``K`` in Noetic's messages, ``k`` in ROS 2 style ones."""
    return getattr(msg, upper) if hasattr(msg, upper) else getattr(msg, upper.lower())


class PinholeCameraModel:
    """An idealized monocular camera, set from a ``sensor_msgs/CameraInfo`` with :meth:`fromCameraInfo`."""

    def __init__(self) -> None:
        self.K: Any = None
        self.D: Any = None
        self.R: Any = None
        self.P: Any = None
        self.full_K: Any = None
        self.full_P: Any = None
        self.width: int | None = None
        self.height: int | None = None
        self.binning_x: int | None = None
        self.binning_y: int | None = None
        self.raw_roi: Any = None
        self.tf_frame: str | None = None
        self.stamp: Any = None
        self.resolution: tuple[int, int] | None = None

    def fromCameraInfo(self, msg: Any) -> None:  # noqa: N802 - ROS 1's name
        """Take the camera's parameters from a CameraInfo message."""
        k, d, r, p = (_field(msg, name) for name in ("K", "D", "R", "P"))
        self.K = _matrix(3, 3, k)
        self.D = _matrix(len(d), 1, d) if len(d) else None
        self.R = _matrix(3, 3, r)
        self.P = _matrix(3, 4, p)
        self.full_K = _matrix(3, 3, k)
        self.full_P = _matrix(3, 4, p)
        self.width = msg.width
        self.height = msg.height
        self.binning_x = max(1, msg.binning_x)
        self.binning_y = max(1, msg.binning_y)
        self.resolution = (msg.width, msg.height)
        self.raw_roi = copy.copy(msg.roi)
        roi = self.raw_roi
        if roi.x_offset == 0 and roi.y_offset == 0 and roi.width == 0 and roi.height == 0:
            roi.width = self.width  # an all-zero ROI means the whole image
            roi.height = self.height
        self.tf_frame = msg.header.frame_id
        self.stamp = msg.header.stamp
        for matrix in (self.K, self.P):
            matrix[0, 0] /= self.binning_x
            matrix[1, 1] /= self.binning_y
            matrix[0, 2] = (matrix[0, 2] - roi.x_offset) / self.binning_x
            matrix[1, 2] = (matrix[1, 2] - roi.y_offset) / self.binning_y

    def rectifyImage(self, raw: Any, rectified: Any) -> None:  # noqa: N802
        """Write into ``rectified`` the image ``raw`` with the lens distortion removed (K, D, R, P)."""
        import cv2

        size = (int(self.width or 0), int(self.height or 0))
        self.mapx, self.mapy = cv2.initUndistortRectifyMap(self.K, self.D, self.R, self.P, size, cv2.CV_32FC1)
        cv2.remap(raw, self.mapx, self.mapy, cv2.INTER_CUBIC, rectified)

    def rectifyPoint(self, uv_raw: Sequence[float]) -> Any:  # noqa: N802
        """The rectified pixel of the raw pixel ``(u, v)`` (a numpy array of two)."""
        import cv2

        src = numpy.array([[[float(uv_raw[0]), float(uv_raw[1])]]], dtype="float64")
        return cv2.undistortPoints(src, self.K, self.D, R=self.R, P=self.P)[0, 0]

    def project3dToPixel(self, point: Sequence[float]) -> tuple[float, float]:  # noqa: N802
        """The rectified pixel ``(u, v)`` where the camera-frame point ``(x, y, z)`` appears;
        ``(nan, nan)`` for a point in the camera's plane."""
        u, v, w = (self.P * _matrix(4, 1, [point[0], point[1], point[2], 1.0])).A1
        if w == 0:
            return (float("nan"), float("nan"))
        return (u / w, v / w)

    def projectPixelTo3dRay(self, uv: Sequence[float]) -> tuple[float, float, float]:  # noqa: N802
        """The unit vector from the camera centre through the rectified pixel ``(u, v)``."""
        x = (uv[0] - self.cx()) / self.fx()
        y = (uv[1] - self.cy()) / self.fy()
        norm = math.sqrt(x * x + y * y + 1.0)
        return (x / norm, y / norm, 1.0 / norm)

    def getDeltaU(self, deltaX: float, Z: float) -> float:  # noqa: N802, N803
        """Pixels spanned by ``deltaX`` metres at depth ``Z`` (inf at Z = 0)."""
        return float("inf") if Z == 0 else self.fx() * deltaX / Z

    def getDeltaV(self, deltaY: float, Z: float) -> float:  # noqa: N802, N803
        """Pixels spanned by ``deltaY`` metres at depth ``Z`` (inf at Z = 0)."""
        return float("inf") if Z == 0 else self.fy() * deltaY / Z

    def getDeltaX(self, deltaU: float, Z: float) -> float:  # noqa: N802, N803
        """Metres spanned by ``deltaU`` pixels at depth ``Z``."""
        return Z * deltaU / self.fx()

    def getDeltaY(self, deltaV: float, Z: float) -> float:  # noqa: N802, N803
        """Metres spanned by ``deltaV`` pixels at depth ``Z``."""
        return Z * deltaV / self.fy()

    def fullResolution(self) -> tuple[int, int] | None:  # noqa: N802
        """(width, height) of the camera info."""
        return self.resolution

    def intrinsicMatrix(self) -> Any:  # noqa: N802
        """K, adjusted for binning and ROI."""
        return self.K

    def distortionCoeffs(self) -> Any:  # noqa: N802
        """D (None when the message has none)."""
        return self.D

    def rotationMatrix(self) -> Any:  # noqa: N802
        """R."""
        return self.R

    def projectionMatrix(self) -> Any:  # noqa: N802
        """P, adjusted for binning and ROI."""
        return self.P

    def fullIntrinsicMatrix(self) -> Any:  # noqa: N802
        """K as the message gives it (full resolution)."""
        return self.full_K

    def fullProjectionMatrix(self) -> Any:  # noqa: N802
        """P as the message gives it (full resolution)."""
        return self.full_P

    def cx(self) -> float:
        return float(self.P[0, 2])

    def cy(self) -> float:
        return float(self.P[1, 2])

    def fx(self) -> float:
        return float(self.P[0, 0])

    def fy(self) -> float:
        return float(self.P[1, 1])

    def Tx(self) -> float:  # noqa: N802
        return float(self.P[0, 3])

    def Ty(self) -> float:  # noqa: N802
        return float(self.P[1, 3])

    def fovX(self) -> float:  # noqa: N802
        """Horizontal field of view in radians, from the width and fx."""
        return 2 * math.atan(float(self.width or 0) / (2 * self.fx()))

    def fovY(self) -> float:  # noqa: N802
        """Vertical field of view in radians, from the height and fy."""
        return 2 * math.atan(float(self.height or 0) / (2 * self.fy()))

    def tfFrame(self) -> str | None:  # noqa: N802
        """The camera's frame (the CameraInfo's header.frame_id)."""
        return self.tf_frame


class StereoCameraModel:
    """Two rectified pinhole cameras side by side; depth from disparity."""

    def __init__(self) -> None:
        self.left = PinholeCameraModel()
        self.right = PinholeCameraModel()
        self.Q: Any = None

    def fromCameraInfo(self, left_msg: Any, right_msg: Any) -> None:  # noqa: N802
        """Take both cameras' parameters; the right camera's P gives the baseline (its Tx = -fx * b)."""
        self.left.fromCameraInfo(left_msg)
        self.right.fromCameraInfo(right_msg)
        fx, cx, cy = self.right.fx(), self.right.cx(), self.right.cy()
        baseline = -self.right.Tx() / fx
        q = numpy.zeros((4, 4), dtype="float64")
        q[0, 0] = q[1, 1] = 1.0
        q[0, 3], q[1, 3] = -cx, -cy
        q[2, 3] = fx
        q[3, 2] = 1 / baseline
        self.Q = q  # reprojects (u, v, disparity, 1) to homogeneous 3D

    def tfFrame(self) -> str | None:  # noqa: N802
        """The frame of the 3D points: the left camera's."""
        return self.left.tfFrame()

    def project3dToPixel(self, point: Sequence[float]) -> tuple[tuple[float, float], tuple[float, float]]:  # noqa: N802
        """The pixel in each camera: ((u_left, v_left), (u_right, v_right))."""
        return (self.left.project3dToPixel(point), self.right.project3dToPixel(point))

    def projectPixelTo3d(self, left_uv: Sequence[float], disparity: float) -> tuple[float, float, float]:  # noqa: N802
        """The 3D point seen at the left pixel with that disparity ((0, 0, 0) when it cannot be placed)."""
        x, y, z, w = numpy.asarray(self.Q) @ numpy.array([left_uv[0], left_uv[1], disparity, 1.0])
        if w == 0:
            return (0.0, 0.0, 0.0)
        return (float(x / w), float(y / w), float(z / w))

    def getZ(self, disparity: float) -> float:  # noqa: N802
        """Depth at which a point shows this disparity (inf at 0)."""
        return float("inf") if disparity == 0 else -self.right.Tx() / disparity

    def getDisparity(self, Z: float) -> float:  # noqa: N802, N803
        """Disparity a point at depth Z shows (inf at 0)."""
        return float("inf") if Z == 0 else -self.right.Tx() / Z
