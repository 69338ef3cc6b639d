"""LaserProjection: the numpy projection, its PointCloud2 layout, and byte equality with Debian's."""

from __future__ import annotations

import base64
import json
import math
import subprocess
from pathlib import Path

import numpy as np
import pytest

from laser_geometry import LaserProjection
from ninjemys.idl.loader import get_message_class
from ninjemys.testing import ROS1_PYTHON, ros1_env

LaserScan = get_message_class("sensor_msgs/LaserScan")
PointCloud2 = get_message_class("sensor_msgs/PointCloud2")
ORACLE = Path(__file__).with_name("lg_oracle.py")
Opt = LaserProjection.ChannelOption


def make_scan(seed: int, n: int = 360, intensities: bool = True) -> object:
    rng = np.random.default_rng(seed)
    ranges = rng.uniform(0.05, 12.0, n).astype(np.float32)
    ranges[rng.integers(0, n, n // 20)] = np.inf
    ranges[rng.integers(0, n, n // 20)] = np.nan
    ranges[rng.integers(0, n, n // 20)] = 0.01  # below range_min
    scan = LaserScan()
    scan.header.frame_id = "laser"
    scan.header.stamp.secs = 1000 + seed
    scan.angle_min = -math.pi
    scan.angle_increment = 2 * math.pi / n
    scan.angle_max = scan.angle_min + (n - 1) * scan.angle_increment
    scan.time_increment = 1.0 / (10 * n)
    scan.scan_time = 0.1
    scan.range_min = 0.1
    scan.range_max = 10.0
    scan.ranges = ranges.tolist()
    scan.intensities = rng.uniform(0, 100, n).astype(np.float32).tolist() if intensities else []
    # as received from the wire (float32 values, lazy arrays)
    return LaserScan.deserialize_from(scan.serialize_to_bytes())


def points(cloud: object) -> np.ndarray:
    names = [f.name for f in cloud.fields]
    dtype = np.dtype({"names": names, "formats": ["<i4" if n == "index" else "<f4" for n in names],
                      "offsets": [f.offset for f in cloud.fields], "itemsize": cloud.point_step})  # fmt: skip
    return np.frombuffer(bytes(cloud.data), dtype=dtype)


def test_projection_geometry_and_fields() -> None:
    scan = make_scan(1)
    cloud = LaserProjection().projectLaser(scan, channel_options=Opt.DEFAULT | Opt.DISTANCE | Opt.TIMESTAMP)
    assert [f.name for f in cloud.fields] == ["x", "y", "z", "intensity", "index", "distances", "stamps"]
    assert [f.offset for f in cloud.fields] == [0, 4, 8, 12, 16, 20, 24]
    assert [f.datatype for f in cloud.fields] == [7, 7, 7, 7, 5, 7, 7]
    assert cloud.point_step == 28 and cloud.height == 1 and cloud.row_step == 28 * cloud.width
    assert cloud.header.frame_id == "laser" and cloud.is_dense is False
    p = points(cloud)
    ranges = np.asarray(scan.ranges)
    valid = np.flatnonzero((ranges >= 0.1) & (ranges < 10.0))
    assert np.array_equal(p["index"], valid)
    angles = scan.angle_min + valid * scan.angle_increment
    assert np.allclose(p["x"], ranges[valid] * np.cos(angles), atol=1e-5)
    assert np.allclose(p["y"], ranges[valid] * np.sin(angles), atol=1e-5)
    assert np.all(p["z"] == 0) and np.allclose(p["distances"], ranges[valid])
    assert np.allclose(p["stamps"], valid * scan.time_increment)


def test_cutoff_and_no_intensities() -> None:
    scan = make_scan(2, intensities=False)
    cloud = LaserProjection().projectLaser(scan, range_cutoff=3.0)
    assert [f.name for f in cloud.fields] == ["x", "y", "z", "index"]
    d = np.hypot(points(cloud)["x"], points(cloud)["y"])
    assert d.max() < 3.0 and d.min() >= 0.1 - 1e-6
    bad = make_scan(3)
    bad.intensities = [1.0, 2.0]
    with pytest.raises(ValueError, match="2 intensities for 360 ranges"):
        LaserProjection().projectLaser(bad)


@pytest.mark.ros1
def test_same_bytes_as_ros1() -> None:
    cases = []
    scans = []
    for seed, cutoff, options in [
        (10, -1.0, Opt.DEFAULT),
        (11, 4.2, Opt.DEFAULT),
        (12, -1.0, Opt.NONE),
        (13, 20.0, Opt.INTENSITY | Opt.INDEX | Opt.DISTANCE | Opt.TIMESTAMP | Opt.VIEWPOINT),
        (14, 5.1, Opt.INDEX | Opt.TIMESTAMP),
    ]:
        scan = make_scan(seed, n=720 if seed % 2 else 360, intensities=seed != 12)
        scans.append((scan, cutoff, options))
        cases.append(
            {
                "scan": base64.b64encode(scan.serialize_to_bytes()).decode(),
                "cutoff": cutoff,
                "options": options,
            }
        )
    done = subprocess.run(
        [ROS1_PYTHON, str(ORACLE)],
        input=json.dumps(cases),
        capture_output=True,
        text=True,
        env=ros1_env("http://localhost:1/"),
        timeout=120,
    )
    assert done.returncode == 0, done.stderr
    theirs = [base64.b64decode(b) for b in json.loads(done.stdout)]
    projector = LaserProjection()
    for (scan, cutoff, options), expected in zip(scans, theirs, strict=True):
        ours = projector.projectLaser(scan, cutoff, options)
        assert ours.serialize_to_bytes() == expected
