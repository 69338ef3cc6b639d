"""sensor_msgs/PointCloud2 <-> numpy structured arrays (one named field per PointField), zero-copy read."""

from __future__ import annotations

from typing import Any

import numpy as np

from ros_numpy.registry import converts_from_numpy, converts_to_numpy
from sensor_msgs.msg import PointCloud2, PointField

DUMMY_FIELD_PREFIX = "__"
_TYPES = {
    PointField.INT8: np.dtype(np.int8),
    PointField.UINT8: np.dtype(np.uint8),
    PointField.INT16: np.dtype(np.int16),
    PointField.UINT16: np.dtype(np.uint16),
    PointField.INT32: np.dtype(np.int32),
    PointField.UINT32: np.dtype(np.uint32),
    PointField.FLOAT32: np.dtype(np.float32),
    PointField.FLOAT64: np.dtype(np.float64),
}
pftype_to_nptype = dict(_TYPES)
nptype_to_pftype = {v: k for k, v in _TYPES.items()}


@converts_to_numpy(PointField, plural=True)
def fields_to_dtype(fields: Any, point_step: int) -> list[tuple[str, Any]]:
    """The structured dtype of one point, padding bytes as ``__<offset>`` fields."""
    out: list[tuple[str, Any]] = []
    offset = 0
    for f in sorted(fields, key=lambda f: f.offset):
        while offset < f.offset:
            out.append((f"{DUMMY_FIELD_PREFIX}{offset}", np.uint8))
            offset += 1
        base = pftype_to_nptype[f.datatype]
        out.append((f.name, base if f.count == 1 else np.dtype((base, f.count))))
        offset += base.itemsize * f.count
    while offset < point_step:
        out.append((f"{DUMMY_FIELD_PREFIX}{offset}", np.uint8))
        offset += 1
    return out


@converts_from_numpy(PointField, plural=True)
def dtype_to_fields(dtype: np.dtype) -> list[Any]:
    fields = []
    for name in dtype.names or ():
        field_type, offset = dtype.fields[name][:2]
        count = 1
        if field_type.subdtype:
            field_type, shape = field_type.subdtype
            count = int(np.prod(shape))
        fields.append(
            PointField(name=name, offset=offset, datatype=nptype_to_pftype[field_type], count=count)
        )
    return fields


@converts_to_numpy(PointCloud2)
def pointcloud2_to_array(cloud_msg: Any, squeeze: bool = True) -> np.ndarray:
    """A (height, width) structured array over the message bytes ((width,) for height 1 with squeeze)."""
    dtype_list = fields_to_dtype(cloud_msg.fields, cloud_msg.point_step)
    dtype = np.dtype(dtype_list)
    if cloud_msg.is_bigendian:
        dtype = dtype.newbyteorder(">")
    arr = np.frombuffer(bytes(cloud_msg.data), dtype)
    arr = arr[[n for n, _ in dtype_list if not n.startswith(DUMMY_FIELD_PREFIX)]]
    if squeeze and cloud_msg.height == 1:
        return arr.reshape(cloud_msg.width)
    return arr.reshape(cloud_msg.height, cloud_msg.width)


@converts_from_numpy(PointCloud2)
def array_to_pointcloud2(cloud_arr: Any, stamp: Any = None, frame_id: str | None = None) -> Any:
    cloud_arr = np.atleast_2d(cloud_arr)
    msg = PointCloud2()
    if stamp is not None:
        msg.header.stamp = stamp
    if frame_id is not None:
        msg.header.frame_id = frame_id
    msg.height, msg.width = cloud_arr.shape
    msg.fields = dtype_to_fields(cloud_arr.dtype)
    msg.is_bigendian = False
    msg.point_step = cloud_arr.dtype.itemsize
    msg.row_step = msg.point_step * cloud_arr.shape[1]
    msg.is_dense = all(np.isfinite(cloud_arr[n]).all() for n in cloud_arr.dtype.names)
    msg.data = np.ascontiguousarray(cloud_arr).tobytes()
    return msg


def merge_rgb_fields(cloud_arr: np.ndarray) -> np.ndarray:
    """uint8 'r', 'g', 'b' fields packed into one float32 'rgb' field (PCL's layout)."""
    packed = (
        (np.asarray(cloud_arr["r"], np.uint32) << 16)
        | (np.asarray(cloud_arr["g"], np.uint32) << 8)
        | np.asarray(cloud_arr["b"], np.uint32)
    ).view(np.float32)
    fields = [(n, cloud_arr.dtype.fields[n][0]) for n in cloud_arr.dtype.names if n not in ("r", "g", "b")]
    out = np.zeros(cloud_arr.shape, fields + [("rgb", np.float32)])
    for n, _ in fields:
        out[n] = cloud_arr[n]
    out["rgb"] = packed
    return out


def split_rgb_field(cloud_arr: np.ndarray) -> np.ndarray:
    """A packed float32 'rgb' field split into uint8 'r', 'g', 'b' fields."""
    packed = np.ascontiguousarray(cloud_arr["rgb"]).view(np.uint32)
    fields = [(n, cloud_arr.dtype.fields[n][0]) for n in cloud_arr.dtype.names if n != "rgb"]
    out = np.zeros(cloud_arr.shape, fields + [("r", np.uint8), ("g", np.uint8), ("b", np.uint8)])
    for n, _ in fields:
        out[n] = cloud_arr[n]
    out["r"], out["g"], out["b"] = (packed >> 16) & 255, (packed >> 8) & 255, packed & 255
    return out


def get_xyz_points(cloud_array: np.ndarray, remove_nans: bool = True, dtype: Any = float) -> np.ndarray:
    """The x, y, z fields as an (..., 3) array, points with a NaN dropped."""
    if remove_nans:
        mask = np.isfinite(cloud_array["x"]) & np.isfinite(cloud_array["y"]) & np.isfinite(cloud_array["z"])
        cloud_array = cloud_array[mask]
    points = np.zeros(cloud_array.shape + (3,), dtype=dtype)
    points[..., 0], points[..., 1], points[..., 2] = cloud_array["x"], cloud_array["y"], cloud_array["z"]
    return points


def pointcloud2_to_xyz_array(cloud_msg: Any, remove_nans: bool = True) -> np.ndarray:
    return get_xyz_points(pointcloud2_to_array(cloud_msg), remove_nans=remove_nans)
