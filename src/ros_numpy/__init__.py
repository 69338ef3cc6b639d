"""ros_numpy: ROS messages to numpy arrays and back (``numpify(msg)``, ``msgify(MsgType, array)``).

Course mapping and perception code uses eric-wieser's ros_numpy (``from ros_numpy import numpify``)
for occupancy grids, images, point clouds and poses. Same functions and conversions: OccupancyGrid
<-> int8 masked array (unknown -1 masked), Image <-> (h, w[, c]) array by encoding, PointCloud2 <->
structured array, Vector3/Point/Quaternion <-> vectors, Transform/Pose <-> 4x4 matrices.
"""

from ros_numpy.registry import msgify, numpify

__all__ = ["geometry", "image", "msgify", "numpify", "occupancy_grid", "point_cloud2"]


def __getattr__(name: str) -> object:
    if name in ("geometry", "image", "occupancy_grid", "point_cloud2"):
        import importlib

        return importlib.import_module(f"ros_numpy.{name}")
    raise AttributeError(f"module 'ros_numpy' has no attribute {name!r}")
