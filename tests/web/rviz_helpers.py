"""Shared pieces of the rviz tests: messages with known geometry, and the page's pixels."""

from __future__ import annotations

import io
import math
from typing import Any

from ninjemys.idl.loader import get_message_class
from ninjemys.rostime import Time

M = get_message_class


def transform(parent: str, child: str, x: float, y: float, yaw: float = 0.0) -> Any:
    ts = M("geometry_msgs/TransformStamped")()
    ts.header.frame_id = parent
    ts.header.stamp = Time(1, 0)
    ts.child_frame_id = child
    ts.transform.translation.x = x
    ts.transform.translation.y = y
    ts.transform.rotation.z = math.sin(yaw / 2)
    ts.transform.rotation.w = math.cos(yaw / 2)
    return ts


def tf_message(*transforms: Any) -> Any:
    return M("tf2_msgs/TFMessage")(transforms=list(transforms))


def scan(frame: str, ranges: list[float], angle_min: float, increment: float) -> Any:
    msg = M("sensor_msgs/LaserScan")()
    msg.header.frame_id = frame
    msg.angle_min = angle_min
    msg.angle_increment = increment
    msg.angle_max = angle_min + increment * (len(ranges) - 1)
    msg.range_min = 0.05
    msg.range_max = 20.0
    msg.ranges = ranges
    return msg


def grid(
    frame: str, width: int, height: int, resolution: float, ox: float, oy: float, data: list[int]
) -> Any:
    msg = M("nav_msgs/OccupancyGrid")()
    msg.header.frame_id = frame
    msg.info.resolution = resolution
    msg.info.width = width
    msg.info.height = height
    msg.info.origin.position.x = ox
    msg.info.origin.position.y = oy
    msg.info.origin.orientation.w = 1.0
    msg.data = data
    return msg


def screenshot_rgb(page: Any) -> Any:
    """The page as an RGB numpy array (height, width, 3)."""
    import numpy as np
    from pngdecode import decode_png  # tests/web helper

    return np.asarray(decode_png(io.BytesIO(page.screenshot()).getvalue()))[..., :3]


def top_view_url(base: str, cx: float, cy: float, scale: float, fixed: str = "map") -> str:
    return f"{base}?view=top&cx={cx}&cy={cy}&scale={scale}&fixed={fixed}"
