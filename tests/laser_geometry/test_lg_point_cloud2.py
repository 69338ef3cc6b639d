"""sensor_msgs.point_cloud2 (ninjemys.laser_geometry.point_cloud2): points in and out of PointCloud2."""

from __future__ import annotations

import math
import struct

import pytest

from laser_geometry import LaserProjection
from sensor_msgs import point_cloud2 as pc2
from sensor_msgs.msg import LaserScan, PointCloud2, PointField
from std_msgs.msg import Header


def test_round_trip_with_mixed_types_and_nans() -> None:
    fields = [
        PointField("x", 0, PointField.FLOAT32, 1),
        PointField("n", 4, PointField.INT8, 1),
        PointField("w", 8, PointField.FLOAT64, 2),
    ]
    points = [(1.5, -3, 0.25, 1e300), (float("nan"), 127, -1.0, 2.0)]
    cloud = pc2.create_cloud(Header(frame_id="f"), fields, points)
    assert (cloud.height, cloud.width, cloud.point_step, cloud.row_step) == (1, 2, 24, 48)
    got = list(pc2.read_points(cloud))
    assert got[0] == (1.5, -3, 0.25, 1e300) and math.isnan(got[1][0]) and got[1][1:] == (127, -1.0, 2.0)
    assert list(pc2.read_points(cloud, skip_nans=True)) == [got[0]]
    # fields come back in offset order, whatever order they are asked in
    assert list(pc2.read_points(cloud, ("w", "x"), uvs=[(0, 0)])) == [(1.5, 0.25, 1e300)]
    named = pc2.read_points_list(cloud, ("x", "n"), skip_nans=True)
    assert named[0].x == 1.5 and named[0].n == -3 and type(named[0]).__name__ == "Point"


def test_padded_rows_and_big_endian() -> None:
    fields = [PointField("x", 0, PointField.FLOAT32, 1)]
    data = b"".join(struct.pack(">f", 1.0 + r * 2 + c) + b"\0" * 4 for r in range(2) for c in range(2))
    rows = data[:16] + b"\xff" * 4 + data[16:] + b"\xff" * 4  # row_step 20: 4 bytes of padding per row
    cloud = PointCloud2(
        header=Header(),
        height=2,
        width=2,
        fields=fields,
        is_bigendian=True,
        point_step=8,
        row_step=20,
        data=rows,
    )
    assert list(pc2.read_points(cloud)) == [(1.0,), (2.0,), (3.0,), (4.0,)]


def test_projected_scan_reads_back() -> None:
    scan = LaserScan(
        angle_min=0.0, angle_max=0.5, angle_increment=0.5, range_min=0.1, range_max=10.0, ranges=[1.0, 2.0]
    )
    cloud = LaserProjection().projectLaser(scan)
    xyz = [p[:3] for p in pc2.read_points(cloud, ("x", "y", "z"))]
    assert xyz[0] == pytest.approx((1.0, 0.0, 0.0)) and xyz[1] == pytest.approx(
        (2 * math.cos(0.5), 2 * math.sin(0.5), 0.0), rel=1e-6
    )


def test_not_a_cloud_is_refused() -> None:
    with pytest.raises(AssertionError, match="cloud is not a sensor_msgs.msg.PointCloud2"):
        list(pc2.read_points(Header()))
