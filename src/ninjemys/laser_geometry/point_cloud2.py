"""Reading and writing ``sensor_msgs/PointCloud2`` points (ROS 1's ``sensor_msgs.point_cloud2``).

The layout of a point comes from the cloud's ``fields`` (name, byte offset, datatype, count), sorted by
offset, with the gaps between them skipped; ``point_step`` and ``row_step`` place each point in
``data``. Values come back as Python ints and floats in a tuple per point, in the order of the
fields' offsets (also when ``field_names`` lists them in another order, as ROS 1 does).

Whole clouds are read with one numpy view over ``data`` (a strided structured array), so large clouds
cost one pass in C instead of a ``struct`` call per point; the values are the same.
"""

from __future__ import annotations

import struct
import sys
from collections import namedtuple
from collections.abc import Iterable, Iterator, Sequence
from typing import Any

import numpy as np

from ninjemys.idl.loader import get_message_class

#: PointField datatype -> (struct code, size in bytes)
DATATYPES: dict[int, tuple[str, int]] = {
    1: ("b", 1),  # INT8
    2: ("B", 1),  # UINT8
    3: ("h", 2),  # INT16
    4: ("H", 2),  # UINT16
    5: ("i", 4),  # INT32
    6: ("I", 4),  # UINT32
    7: ("f", 4),  # FLOAT32
    8: ("d", 8),  # FLOAT64
}

_CLOUD_TYPE = "sensor_msgs/PointCloud2"


def struct_format(is_bigendian: bool, fields: Sequence[Any], field_names: Iterable[str] | None = None) -> str:
    """The ``struct`` format of one point: the chosen fields in offset order, pad bytes between them.

    A field of an unknown datatype is skipped with one line on stderr (its bytes are not padded over,
    as in ROS 1).
    """
    wanted = None if field_names is None else set(field_names)
    fmt = ">" if is_bigendian else "<"
    offset = 0
    for field in sorted(fields, key=lambda f: f.offset):
        if wanted is not None and field.name not in wanted:
            continue
        if offset < field.offset:
            fmt += "x" * (field.offset - offset)
            offset = field.offset
        kind = DATATYPES.get(field.datatype)
        if kind is None:
            print(f"Skipping unknown PointField datatype [{field.datatype}]", file=sys.stderr)
            continue
        fmt += field.count * kind[0]
        offset += field.count * kind[1]
    return fmt


def _check(cloud: Any) -> None:
    if getattr(cloud, "_type", None) != _CLOUD_TYPE:
        raise AssertionError("cloud is not a sensor_msgs.msg.PointCloud2")


def _has_nan(point: tuple) -> bool:
    return any(v != v for v in point)  # NaN is the only value unequal to itself


def _as_array(cloud: Any, fmt: str) -> np.ndarray | None:
    """All points as a flat structured array, or None when numpy cannot view the layout (a point
    wider than ``point_step``, data shorter than the rows claim)."""
    order = fmt[0]
    names: list[str] = []
    formats: list[str] = []
    offsets: list[int] = []
    position = 0
    for code in fmt[1:]:
        if code == "x":
            position += 1
            continue
        names.append(f"f{len(names)}")
        formats.append(order + code)
        offsets.append(position)
        position += struct.calcsize(order + code)
    height, width, point_step, row_step = cloud.height, cloud.width, cloud.point_step, cloud.row_step
    if not names or position > point_step:
        return None
    dtype = np.dtype({"names": names, "formats": formats, "offsets": offsets, "itemsize": point_step})
    if not height or not width:
        return np.zeros(0, dtype=dtype)
    data = cloud.data
    if len(data) < row_step * (height - 1) + point_step * width:
        return None
    points = np.ndarray(shape=(height, width), dtype=dtype, buffer=data, strides=(row_step, point_step))
    return points.reshape(-1)


def read_points(
    cloud: Any, field_names: Iterable[str] | None = None, skip_nans: bool = False, uvs: Iterable[Any] = ()
) -> Iterator[tuple]:
    """The points of ``cloud`` as tuples (the chosen fields, in offset order); ``uvs`` picks points by
    (column, row); ``skip_nans`` leaves out points with a NaN in a chosen field."""
    _check(cloud)
    fmt = struct_format(cloud.is_bigendian, cloud.fields, field_names)
    uvs = list(uvs)
    if uvs:
        unpack_from = struct.Struct(fmt).unpack_from
        for u, v in uvs:
            point = unpack_from(cloud.data, cloud.row_step * v + cloud.point_step * u)
            if not (skip_nans and _has_nan(point)):
                yield point
        return
    points = _as_array(cloud, fmt)
    if points is None:  # a layout numpy cannot view (or short data): one struct call per point
        unpack_from = struct.Struct(fmt).unpack_from
        for v in range(cloud.height):
            offset = cloud.row_step * v
            for _u in range(cloud.width):
                point = unpack_from(cloud.data, offset)
                offset += cloud.point_step
                if not (skip_nans and _has_nan(point)):
                    yield point
        return
    if skip_nans:
        floats = [name for name in points.dtype.names or () if points.dtype[name].kind == "f"]
        if floats:
            keep = ~np.logical_or.reduce([np.isnan(points[name]) for name in floats])
            points = points[keep]
    yield from points.tolist()


def read_points_list(
    cloud: Any, field_names: Sequence[str] | None = None, skip_nans: bool = False, uvs: Iterable[Any] = ()
) -> list[Any]:
    """:func:`read_points` as a list of namedtuples ``Point`` named by ``field_names`` (all fields
    when None)."""
    _check(cloud)
    if field_names is None:
        field_names = [f.name for f in cloud.fields]
    point = namedtuple("Point", field_names)  # type: ignore[misc]
    return [point._make(p) for p in read_points(cloud, field_names, skip_nans, uvs)]


def create_cloud(header: Any, fields: Sequence[Any], points: Sequence[Sequence[Any]]) -> Any:
    """A one-row, little-endian ``PointCloud2`` of ``points`` (each a sequence of the fields' values)."""
    layout = struct.Struct(struct_format(False, fields))
    buffer = bytearray(layout.size * len(points))
    pack_into = layout.pack_into
    offset = 0
    for p in points:
        pack_into(buffer, offset, *p)
        offset += layout.size
    return get_message_class(_CLOUD_TYPE)(
        header=header,
        height=1,
        width=len(points),
        is_dense=False,
        is_bigendian=False,
        fields=fields,
        point_step=layout.size,
        row_step=layout.size * len(points),
        data=bytes(buffer),
    )


def create_cloud_xyz32(header: Any, points: Sequence[Sequence[float]]) -> Any:
    """A ``PointCloud2`` of float32 ``x, y, z`` points."""
    field = get_message_class("sensor_msgs/PointField")
    fields = [field("x", 0, 7, 1), field("y", 4, 7, 1), field("z", 8, 7, 1)]
    return create_cloud(header, fields, points)


__all__ = [
    "DATATYPES",
    "create_cloud",
    "create_cloud_xyz32",
    "read_points",
    "read_points_list",
    "struct_format",
]
