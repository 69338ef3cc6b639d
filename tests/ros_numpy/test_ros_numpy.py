"""ros_numpy: numpify/msgify for the types course code converts (grids, images, clouds, poses)."""

from __future__ import annotations

import math

import numpy as np
import pytest

import ros_numpy
from geometry_msgs.msg import Point, Pose, Quaternion, Transform, Vector3
from nav_msgs.msg import OccupancyGrid
from ros_numpy import point_cloud2
from sensor_msgs.msg import Image, PointCloud2
from std_msgs.msg import String


def test_occupancy_grid_masks_unknown_cells_and_round_trips() -> None:
    grid = OccupancyGrid()
    grid.info.width, grid.info.height = 3, 2
    grid.data = [0, 100, -1, 50, -1, 0]
    arr = ros_numpy.numpify(grid)
    assert arr.shape == (2, 3) and arr.dtype == np.int8
    assert arr.mask.tolist() == [[False, False, True], [False, True, False]]
    assert arr[0, 1] == 100 and arr.count() == 4
    back = ros_numpy.msgify(OccupancyGrid, arr)
    assert list(back.data) == [0, 100, -1, 50, -1, 0] and (back.info.width, back.info.height) == (3, 2)
    with pytest.raises(TypeError, match="int8"):
        ros_numpy.msgify(OccupancyGrid, np.zeros((2, 2)))


def test_images_by_encoding_with_row_padding() -> None:
    rgb = np.arange(2 * 3 * 3, dtype=np.uint8).reshape(2, 3, 3)
    msg = ros_numpy.msgify(Image, rgb, encoding="rgb8")
    assert (msg.height, msg.width, msg.step, msg.encoding) == (2, 3, 9, "rgb8")
    assert np.array_equal(ros_numpy.numpify(msg), rgb)
    depth = Image(encoding="32FC1", height=2, width=2, step=12, is_bigendian=0)
    values = np.array([[1.5, 2.5, 0], [3.5, 4.5, 0]], dtype="<f4")  # 4 padding bytes per row
    depth.data = values.tobytes()
    assert ros_numpy.numpify(depth).tolist() == [[1.5, 2.5], [3.5, 4.5]]
    with pytest.raises(TypeError, match="requires 3"):
        ros_numpy.msgify(Image, np.zeros((2, 2), np.uint8), encoding="bgr8")


def test_point_cloud_structured_arrays_round_trip() -> None:
    pts = np.zeros(
        4, dtype=[("x", np.float32), ("y", np.float32), ("z", np.float32), ("intensity", np.float32)]
    )
    pts["x"], pts["y"], pts["z"], pts["intensity"] = (
        [1, 2, np.nan, 4],
        [5, 6, 7, 8],
        [9, 10, 11, 12],
        [0, 1, 2, 3],
    )
    msg = ros_numpy.msgify(PointCloud2, pts, frame_id="laser")
    assert (msg.height, msg.width, msg.point_step, msg.is_dense) == (1, 4, 16, False)
    assert [f.name for f in msg.fields] == ["x", "y", "z", "intensity"]
    back = ros_numpy.numpify(msg)
    assert back.shape == (4,) and back["intensity"].tolist() == [0, 1, 2, 3]
    xyz = point_cloud2.pointcloud2_to_xyz_array(msg)
    assert xyz.tolist() == [[1, 5, 9], [2, 6, 10], [4, 8, 12]]
    colour = np.zeros(1, dtype=[("x", np.float32), ("r", np.uint8), ("g", np.uint8), ("b", np.uint8)])
    colour["r"], colour["g"], colour["b"] = 10, 20, 30
    merged = point_cloud2.merge_rgb_fields(colour)
    split = point_cloud2.split_rgb_field(merged)
    assert (int(split["r"][0]), int(split["g"][0]), int(split["b"][0])) == (10, 20, 30)


def test_geometry_vectors_and_matrices() -> None:
    assert ros_numpy.numpify(Vector3(1, 2, 3), hom=True).tolist() == [1, 2, 3, 0]
    assert ros_numpy.numpify(Point(1, 2, 3), hom=True).tolist() == [1, 2, 3, 1]
    p = ros_numpy.msgify(Point, np.array([2.0, 4.0, 6.0, 2.0]))
    assert (p.x, p.y, p.z) == (1, 2, 3)
    half = math.sqrt(0.5)
    pose = Pose(position=Point(1, 2, 3), orientation=Quaternion(0, 0, half, half))  # 90 deg about z
    m = ros_numpy.numpify(pose)
    assert np.allclose(m @ [1, 0, 0, 1], [1, 3, 3, 1])
    back = ros_numpy.msgify(Pose, m)
    assert np.allclose(
        [back.orientation.x, back.orientation.y, back.orientation.z, back.orientation.w], [0, 0, half, half]
    )
    t = ros_numpy.msgify(Transform, m)
    assert (t.translation.x, t.translation.y, t.translation.z) == (1, 2, 3)
    many = ros_numpy.msgify(Vector3, np.arange(6.0).reshape(2, 3))
    assert many.shape == (2,) and many[1].z == 5
    for q in ([0.1, 0.2, 0.3, 0.9], [0.9, 0.1, -0.2, 0.1], [0.0, 0.0, 1.0, 0.0]):
        q = np.array(q) / np.linalg.norm(q)
        mat = ros_numpy.numpify(Transform(rotation=Quaternion(*q)))
        got = ros_numpy.numpify(ros_numpy.msgify(Transform, mat).rotation)
        assert np.allclose(got, q) or np.allclose(got, -q)


def test_unknown_type_is_one_clear_error() -> None:
    with pytest.raises(TypeError, match="Cannot convert type String to numpy"):
        ros_numpy.numpify(String(data="x"))
    assert ros_numpy.numpify(None) is None
