"""sensor_msgs.point_cloud2 on fixed clouds, printed as JSON (run under either interpreter, no master):
create_cloud / create_cloud_xyz32 (as serialized bytes), read_points with field subsets in any order,
skip_nans, uvs, padded rows, big-endian data, read_points_list's namedtuples,
and a projected laser scan read back."""

import io
import json
import math

import rospy
from laser_geometry import LaserProjection
from sensor_msgs import point_cloud2 as pc2
from sensor_msgs.msg import LaserScan, PointCloud2, PointField
from std_msgs.msg import Header


def wire(msg):
    buf = io.BytesIO()
    msg.serialize(buf)
    return buf.getvalue().hex()


def plain(x):
    if isinstance(x, float) and math.isnan(x):
        return "nan"
    if isinstance(x, (list, tuple)):
        return [plain(v) for v in x]
    return x


def outcome(fn, *args, **kwargs):
    try:
        return ["ok", plain(fn(*args, **kwargs))]
    except Exception as exc:
        return ["raise", type(exc).__name__, str(exc)]


header = Header(stamp=rospy.Time(3, 4), frame_id="cloud")
fields = [
    PointField("x", 0, PointField.FLOAT32, 1),
    PointField("y", 4, PointField.FLOAT32, 1),
    PointField("z", 8, PointField.FLOAT32, 1),
    PointField("ring", 12, PointField.UINT16, 1),
    PointField("rgb", 16, PointField.UINT8, 3),
    PointField("t", 20, PointField.FLOAT64, 1),
    PointField("id", 28, PointField.INT32, 1),
]
points = [
    (1.5, -2.25, 3.0, 7, 1, 2, 3, 0.125, -9),
    (float("nan"), 0.5, 1.0, 65535, 255, 0, 128, 1e-9, 2147483647),
    (0.1, 0.2, 0.3, 0, 9, 8, 7, -4.5, -2147483648),
]
cloud = pc2.create_cloud(header, fields, points)
out = {"pc2": {}}
out["pc2"]["create_wire"] = wire(cloud)
out["pc2"]["xyz32_wire"] = wire(pc2.create_cloud_xyz32(header, [(1, 2, 3), (0.1, 0.2, 0.3)]))
out["pc2"]["all"] = outcome(lambda: list(pc2.read_points(cloud)))
out["pc2"]["subset_reordered"] = outcome(lambda: list(pc2.read_points(cloud, field_names=("id", "x", "rgb"))))
out["pc2"]["skip_nans"] = outcome(lambda: list(pc2.read_points(cloud, skip_nans=True)))
out["pc2"]["skip_nans_ints_only"] = outcome(
    lambda: list(pc2.read_points(cloud, ("ring", "id"), skip_nans=True))
)
out["pc2"]["uvs"] = outcome(lambda: list(pc2.read_points(cloud, ("x", "y"), uvs=[(2, 0), (0, 0), (1, 0)])))
out["pc2"]["uvs_nan"] = outcome(lambda: list(pc2.read_points(cloud, ("x", "y"), True, [(1, 0), (2, 0)])))
as_list = pc2.read_points_list(cloud, ("x", "y", "z"))
out["pc2"]["list"] = outcome(lambda: [[type(p).__name__, list(p._fields), list(p)] for p in as_list])
out["pc2"]["list_default"] = outcome(lambda: [list(p._fields) for p in pc2.read_points_list(cloud)][:1])
out["pc2"]["fmt"] = [
    pc2._get_struct_fmt(False, fields),
    pc2._get_struct_fmt(True, fields, ["z", "id"]),
    pc2._get_struct_fmt(False, [PointField("b", 8, 7, 2), PointField("a", 3, 1, 1)]),
]
padded = PointCloud2(
    header=header,
    height=2,
    width=2,
    fields=fields[:3],
    is_bigendian=False,
    point_step=16,
    row_step=40,
    data=bytes(range(80)),
    is_dense=True,
)
out["pc2"]["padded_rows"] = outcome(lambda: list(pc2.read_points(padded, ("x", "z"))))
big = PointCloud2(
    header=header,
    height=1,
    width=2,
    fields=[PointField("v", 0, PointField.INT16, 1), PointField("w", 2, PointField.FLOAT64, 1)],
    is_bigendian=True,
    point_step=10,
    row_step=20,
    data=bytes(range(20)),
    is_dense=True,
)
out["pc2"]["big_endian"] = outcome(lambda: list(pc2.read_points(big)))
out["pc2"]["not_a_cloud"] = outcome(lambda: list(pc2.read_points(header)))
out["pc2"]["empty"] = outcome(lambda: list(pc2.read_points(pc2.create_cloud_xyz32(header, []))))

scan = LaserScan(
    header=header,
    angle_min=-1.0,
    angle_max=1.0,
    angle_increment=0.5,
    time_increment=0.01,
    scan_time=0.1,
    range_min=0.2,
    range_max=10.0,
    ranges=[1.0, float("nan"), 0.1, 5.0, 20.0],
    intensities=[1, 2, 3, 4, 5],
)
projected = LaserProjection().projectLaser(scan)
out["pc2"]["projected"] = outcome(lambda: [list(p) for p in pc2.read_points(projected, skip_nans=True)])
out["pc2"]["projected_fields"] = [[f.name, f.offset, f.datatype, f.count] for f in projected.fields]
print(json.dumps(out))
