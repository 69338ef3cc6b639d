"""nav_msgs/OccupancyGrid <-> an int8 (height, width) masked array, unknown cells (-1) masked."""

from __future__ import annotations

from typing import Any

import numpy as np

from nav_msgs.msg import MapMetaData, OccupancyGrid
from ros_numpy.registry import converts_from_numpy, converts_to_numpy


@converts_to_numpy(OccupancyGrid)
def occupancygrid_to_numpy(msg: Any) -> np.ma.MaskedArray:
    data = np.asarray(msg.data, dtype=np.int8).reshape(msg.info.height, msg.info.width)
    return np.ma.array(data, mask=data == -1, fill_value=-1)


@converts_from_numpy(OccupancyGrid)
def numpy_to_occupancy_grid(arr: Any, info: Any = None) -> Any:
    if arr.ndim != 2:
        raise TypeError("Array must be 2D")
    if arr.dtype != np.int8:
        raise TypeError("Array must be of int8s")
    data = arr.filled(-1) if isinstance(arr, np.ma.MaskedArray) else arr
    grid = OccupancyGrid()
    grid.info = info or MapMetaData()
    grid.info.height, grid.info.width = data.shape
    grid.data = data.ravel().tolist()
    return grid
