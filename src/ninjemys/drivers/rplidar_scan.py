"""From RPLIDAR samples to ``sensor_msgs/LaserScan`` fields, with rplidar_ros' conventions.

rplidar_ros (1.10, Noetic) does three things to a revolution before publishing it (its angles as the
SDK hands them on, in 90/16384-degree steps: :func:`ninjemys.drivers.rplidar_protocol.q14_degrees`):

1. *ascend*: samples with no distance get an angle interpolated from their neighbours, then all are
   sorted by angle (the device's clockwise degrees);
2. *angle compensation* (``angle_compensate``, default true): the samples go into fixed bins of
   ``1/multiple`` degree, ``multiple = 1e6 / us_per_sample / 10 / 360`` (samples per degree at 10 Hz),
   so every scan has ``360 * multiple`` beams at the same angles; bins no sample fell in read ``inf``;
3. *the angle flip*: the device turns clockwise, ROS angles turn counter-clockwise, and rplidar_ros
   publishes the beam at device angle ``a`` at ``pi - a``: ``angle_min = pi - 359 deg``,
   ``angle_max = pi`` for compensated scans, with the ranges in reverse order (``inverted`` undoes the
   reversal for a lidar mounted upside down). Ranges are metres, 0 becomes ``inf``; intensities are
   the 6-bit quality.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass
class ScanFields:
    angle_min: float
    angle_max: float
    angle_increment: float
    time_increment: float
    scan_time: float
    range_min: float
    range_max: float
    ranges: np.ndarray
    intensities: np.ndarray


class RevolutionAssembler:
    """Samples in, whole revolutions out: a sample with the start flag closes the one before it.

    Samples before the first start flag belong to a revolution seen in part and are dropped, as the
    SDK's grabScanData drops them. Rows are (angle deg, distance mm, quality, start flag); revolutions
    come out as rows of the first three.
    """

    def __init__(self) -> None:
        self._parts: list[np.ndarray] = []
        self._started = False

    def reset(self) -> None:
        self._parts = []
        self._started = False

    def feed(self, rows: np.ndarray) -> list[np.ndarray]:
        out: list[np.ndarray] = []
        if not len(rows):
            return out
        starts = np.nonzero(rows[:, 3] != 0)[0]
        prev = 0
        for s in starts.tolist():
            if self._started:
                self._parts.append(rows[prev:s])
                rev = np.concatenate(self._parts)
                if len(rev):
                    out.append(rev[:, :3])
            self._parts = []
            self._started = True
            prev = s
        if self._started:
            self._parts.append(rows[prev:])
        return out


def ascend(rev: np.ndarray) -> np.ndarray | None:
    """rplidar_ros' ascendScanData: angles for empty samples, then sorted by angle. None: all empty."""
    rev = rev.copy()
    n = len(rev)
    valid = np.nonzero(rev[:, 1] != 0)[0]
    if not len(valid):
        return None
    inc = 360.0 / n
    first, last = valid[0], valid[-1]
    for i in range(first - 1, -1, -1):  # the head: step back from the first valid sample
        rev[i, 0] = max(0.0, rev[i + 1, 0] - inc)
    for i in range(last + 1, n):  # the tail: step on from the last valid sample
        a = rev[i - 1, 0] + inc
        rev[i, 0] = a - 360.0 if a > 360.0 else a
    front = rev[0, 0]
    empty = np.nonzero(rev[:, 1] == 0)[0]
    for i in empty[empty > 0]:
        a = front + i * inc
        rev[i, 0] = a - 360.0 if a > 360.0 else a
    return rev[np.argsort(rev[:, 0], kind="stable")]


def compensate_multiple(us_per_sample: float, scan_frequency: float = 10.0) -> int:
    """Bins per degree of an angle-compensated scan: the samples of one turn at ``scan_frequency``
    (Hz; rplidar_ros 1.x assumed 10, 2.x reads its ``scan_frequency`` parameter) over 360, at least 1."""
    return max(1, int(1000 * 1000 / us_per_sample / scan_frequency / 360.0))


def compensated(rev: np.ndarray, multiple: int) -> np.ndarray:
    """Samples in ``360 * multiple`` bins (rplidar_ros' angle_compensate_nodes), empty bins 0 mm."""
    count = 360 * multiple
    out = np.zeros((count, 3), dtype=np.float64)
    out[:, 0] = np.arange(count) / multiple
    valid = rev[rev[:, 1] != 0]
    if not len(valid):
        return out
    # angles are >= 0, so rplidar_ros' running offset stays 0; each sample fills `multiple` bins from
    # int(angle * multiple) and, where samples share a bin, the later one (in angle order) wins
    values = (valid[:, 0] * multiple).astype(np.int64)
    winner = np.full(count, -1, dtype=np.int64)
    order = np.arange(len(valid), dtype=np.int64)
    for j in range(multiple):
        np.maximum.at(winner, np.minimum(values + j, count - 1), order)
    filled = winner >= 0
    out[filled] = valid[winner[filled]]
    return out


def scan_fields(
    nodes: np.ndarray,
    angle_min_deg: float,
    angle_max_deg: float,
    scan_time: float,
    inverted: bool,
    max_distance: float,
) -> ScanFields:
    """rplidar_ros' publish_scan on ``nodes`` (rows of angle deg, dist mm, quality)."""
    n = len(nodes)
    a_min, a_max = math.radians(angle_min_deg), math.radians(angle_max_deg)
    reversed_ = a_max > a_min
    if reversed_:
        lo, hi = math.pi - a_max, math.pi - a_min
    else:
        lo, hi = math.pi - a_min, math.pi - a_max
    ranges = (nodes[:, 1] / 1000.0).astype(np.float32)
    ranges[ranges == 0.0] = np.inf
    intensities = nodes[:, 2].astype(np.float32)
    if (not inverted and reversed_) or (inverted and not reversed_):
        ranges, intensities = ranges[::-1].copy(), intensities[::-1].copy()
    span = max(n - 1, 1)
    return ScanFields(
        angle_min=lo,
        angle_max=hi,
        angle_increment=(hi - lo) / span,
        time_increment=scan_time / span,
        scan_time=scan_time,
        range_min=0.15,
        range_max=max_distance,
        ranges=ranges,
        intensities=intensities,
    )


def revolution_to_scan(
    rev: np.ndarray,
    angle_compensate: bool,
    multiple: int,
    scan_time: float,
    inverted: bool,
    max_distance: float,
) -> ScanFields:
    """One revolution as rplidar_ros publishes it (see the module docstring)."""
    sorted_rev = ascend(rev)
    if sorted_rev is None:  # all invalid: published as they are, over 0..359 degrees
        return scan_fields(rev, 0.0, 359.0, scan_time, inverted, max_distance)
    if angle_compensate:
        return scan_fields(compensated(sorted_rev, multiple), 0.0, 359.0, scan_time, inverted, max_distance)
    valid = np.nonzero(sorted_rev[:, 1] != 0)[0]
    part = sorted_rev[valid[0] : valid[-1] + 1]
    return scan_fields(part, part[0, 0], part[-1, 0], scan_time, inverted, max_distance)
