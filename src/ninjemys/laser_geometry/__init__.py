"""Laser scans to point clouds (ROS 1's ``laser_geometry.LaserProjection``), vectorized with numpy.

:func:`project_ranges` is the algorithm alone (arrays in, a structured array out, no ROS); the class
wraps it into ``sensor_msgs/PointCloud2`` with ROS 1's Python field layout: ``x, y, z`` then, as
``channel_options`` asks, ``intensity``, ``index`` (int32), ``distances``, ``stamps`` and
``vp_x, vp_y, vp_z`` (all float32, packed without padding). A point is kept when
``range_min <= r < cutoff`` (so NaN and inf never pass), where the cutoff is ``range_max``, or
``range_cutoff`` when that is given and smaller. Coordinates are computed in float64 and stored as
float32, as ROS 1 does, so both give the same bytes.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ninjemys.idl.loader import get_message_class


class ChannelOption:
    """Which channels ``projectLaser`` adds (OR them together)."""

    NONE = 0x00
    INTENSITY = 0x01
    INDEX = 0x02
    DISTANCE = 0x04
    TIMESTAMP = 0x08
    VIEWPOINT = 0x10
    DEFAULT = INTENSITY | INDEX


_FLOAT32, _INT32 = 7, 5  # sensor_msgs/PointField datatypes


def cloud_dtype(channel_options: int, has_intensities: bool) -> np.dtype:
    """The packed point layout for these options (field name -> little-endian type, in order)."""
    names: list[tuple[str, str]] = [("x", "<f4"), ("y", "<f4"), ("z", "<f4")]
    if channel_options & ChannelOption.INTENSITY and has_intensities:
        names.append(("intensity", "<f4"))
    if channel_options & ChannelOption.INDEX:
        names.append(("index", "<i4"))
    if channel_options & ChannelOption.DISTANCE:
        names.append(("distances", "<f4"))
    if channel_options & ChannelOption.TIMESTAMP:
        names.append(("stamps", "<f4"))
    if channel_options & ChannelOption.VIEWPOINT:
        names += [("vp_x", "<f4"), ("vp_y", "<f4"), ("vp_z", "<f4")]
    return np.dtype(names)


def project_ranges(
    ranges: np.ndarray,
    cos_sin: np.ndarray,
    range_min: float,
    cutoff: float,
    dtype: np.dtype,
    intensities: np.ndarray | None = None,
    time_increment: float = 0.0,
) -> np.ndarray:
    """The points of one scan as a structured array of ``dtype`` (only the valid beams)."""
    r64 = ranges.astype(np.float64)  # compare in double, as ROS 1 does with Python floats
    with np.errstate(invalid="ignore"):
        keep = np.flatnonzero((r64 < float(cutoff)) & (r64 >= float(range_min)))
    out = np.zeros(keep.size, dtype=dtype)
    out["x"] = r64[keep] * cos_sin[0, keep]
    out["y"] = r64[keep] * cos_sin[1, keep]
    names = dtype.names or ()
    if "intensity" in names and intensities is not None:
        out["intensity"] = intensities[keep]
    if "index" in names:
        out["index"] = keep
    if "distances" in names:
        out["distances"] = ranges[keep]
    if "stamps" in names:
        out["stamps"] = keep * float(time_increment)
    return out


class LaserProjection:
    """Projects ``sensor_msgs/LaserScan`` into ``sensor_msgs/PointCloud2`` in the scan's frame.

    The beam directions are cached between scans with the same geometry.
    """

    LASER_SCAN_INVALID = -1.0
    LASER_SCAN_MIN_RANGE = -2.0
    LASER_SCAN_MAX_RANGE = -3.0
    ChannelOption = ChannelOption

    def __init__(self) -> None:
        self._geometry: tuple[int, float, float] | None = None
        self._cos_sin = np.zeros((2, 0))

    def _directions(self, n: int, angle_min: float, angle_increment: float) -> np.ndarray:
        key = (n, float(angle_min), float(angle_increment))
        if key != self._geometry:
            angles = angle_min + np.arange(n) * angle_increment
            self._cos_sin = np.array([np.cos(angles), np.sin(angles)])
            self._geometry = key
        return self._cos_sin

    def projectLaser(  # noqa: N802 - ROS 1 API
        self, scan_in: Any, range_cutoff: float = -1.0, channel_options: int = ChannelOption.DEFAULT
    ) -> Any:
        """The point cloud of ``scan_in``; ``range_cutoff`` (if >= 0) tightens ``range_max``."""
        ranges = np.asarray(scan_in.ranges, dtype=np.float32)
        intensities = np.asarray(scan_in.intensities, dtype=np.float32)
        if intensities.size and intensities.size != ranges.size:
            raise ValueError(
                f"sensor_msgs/LaserScan: {intensities.size} intensities for {ranges.size} ranges"
            )
        dtype = cloud_dtype(channel_options, intensities.size > 0)
        cutoff = scan_in.range_max if range_cutoff < 0 else min(range_cutoff, scan_in.range_max)
        points = project_ranges(
            ranges,
            self._directions(ranges.size, scan_in.angle_min, scan_in.angle_increment),
            scan_in.range_min,
            cutoff,
            dtype,
            intensities if intensities.size else None,
            scan_in.time_increment,
        )
        PointCloud2 = get_message_class("sensor_msgs/PointCloud2")
        PointField = get_message_class("sensor_msgs/PointField")
        fields = [
            PointField(name, offset, _INT32 if name == "index" else _FLOAT32, 1)
            for name, (_, offset, *_) in (dtype.fields or {}).items()
        ]
        return PointCloud2(
            header=scan_in.header,
            height=1,
            width=points.size,
            fields=fields,
            is_bigendian=False,
            point_step=dtype.itemsize,
            row_step=dtype.itemsize * points.size,
            data=points.tobytes(),
            is_dense=False,
        )
