"""A costmap_2d ROS wrapper for move_base: parameters from ROS 1's costmap YAMLs, laser input, output.

Parameters are read under the costmap's namespace (``~global_costmap``, ``~local_costmap``) the way
ROS 1 users write them: either flat (``inflation_radius``, ``obstacle_range``, ``observation_sources``
next to ``robot_radius``, the pre-Hydro layout most tutorials use) or per layer
(``inflation_layer/inflation_radius``, ``obstacle_layer/scan/...``); a layer namespace wins. The
costmap is published on ``<ns>/costmap`` (nav_msgs/OccupancyGrid, full grid whenever its size or
origin changes) and ``<ns>/costmap_updates`` (map_msgs/OccupancyGridUpdate of the changed bounds).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ninjemys.nav.costmap import Costmap, CostmapParams, parse_footprint, to_occupancy
from ninjemys.nav.rosglue import fill_info


class CostmapROS:
    """One costmap with its parameters, frames and publishers."""

    def __init__(self, node: Any, ns: str) -> None:
        self.node = node
        self.ns = ns  # e.g. "~global_costmap"
        self.name = ns.lstrip("~")
        g = self.get
        self.global_frame = str(g("global_frame", "map")).lstrip("/")
        self.robot_base_frame = str(g("robot_base_frame", "base_link")).lstrip("/")
        self.update_frequency = g("update_frequency", 5.0)
        self.publish_frequency = g("publish_frequency", 0.0)
        #: seconds a robot pose may lag ROS time before it is refused (costmap_2d's default)
        self.transform_tolerance = g("transform_tolerance", 0.3)
        p = CostmapParams(
            resolution=g("resolution", 0.05),
            width=g("width", 10.0 if self.name == "global_costmap" else 3.0),
            height=g("height", 10.0 if self.name == "global_costmap" else 3.0),
            rolling_window=g("rolling_window", False),
            robot_radius=g("robot_radius", 0.12),
            footprint_padding=g("footprint_padding", 0.0),
            inflation_radius=g("inflation_radius", 0.55, "inflation_layer"),
            cost_scaling_factor=g("cost_scaling_factor", 10.0, "inflation_layer"),
            obstacle_range=g("obstacle_range", 2.5, "obstacle_layer"),
            raytrace_range=g("raytrace_range", 3.0, "obstacle_layer"),
            track_unknown_space=g("track_unknown_space", False, "obstacle_layer"),
            lethal_cost_threshold=g("lethal_cost_threshold", 100, "static_layer"),
            use_static=g("static_map", True),
        )
        footprint = self.node.get_param(self.ns + "/footprint", None)
        if footprint not in (None, "", "[]", []):
            try:
                p.footprint = parse_footprint(footprint)
            except ValueError as exc:
                self.node.log.error("%s/footprint: %s; using robot_radius %.3f", self.ns, exc, p.robot_radius)
        plugins = self.node.get_param(self.ns + "/plugins", None)
        if isinstance(plugins, list):
            kinds = {str(pl.get("type", "")) for pl in plugins if isinstance(pl, dict)}
            p.use_static = p.use_static and any("StaticLayer" in k for k in kinds)
            p.use_obstacles = any("ObstacleLayer" in k or "VoxelLayer" in k for k in kinds)
            if not any("InflationLayer" in k for k in kinds):
                p.inflation_radius = 0.0
        self.costmap = Costmap(p)
        self.sources = self._observation_sources()
        from map_msgs.msg import OccupancyGridUpdate
        from nav_msgs.msg import OccupancyGrid

        self._grid_cls, self._update_cls = OccupancyGrid, OccupancyGridUpdate
        self.pub = node.publisher(ns + "/costmap", OccupancyGrid, queue_size=1, latch=True)
        self.update_pub = node.publisher(ns + "/costmap_updates", OccupancyGridUpdate, queue_size=1)
        #: the newest scan of each observation source (topic) since the last update (move_base fills it)
        self.observations: dict[str, Any] = {}
        self.dirty = False  # marks added since the costs were last computed
        self._published: tuple | None = None  # (shape, origin) of the last full grid
        self._last_costs: np.ndarray | None = None

    def get(self, key: str, default: Any, layer: str | None = None) -> Any:
        """``<ns>/<layer>/<key>`` or ``<ns>/<key>``; a value of the wrong kind is reported once and ignored."""
        value = default
        for name in ([f"{self.ns}/{layer}/{key}"] if layer else []) + [f"{self.ns}/{key}"]:
            if self.node.has_param(name):
                value = self.node.get_param(name)
                where = name
                break
        else:
            return default
        try:
            if isinstance(default, bool):
                if not isinstance(value, bool | int):
                    raise ValueError
                return bool(value)
            if isinstance(default, int):
                return int(value)
            if isinstance(default, float):
                out = float(value)
                if not math.isfinite(out):
                    raise ValueError
                return out
        except (TypeError, ValueError):
            self.node.log.error(
                "move_base: parameter %s: expected a %s, got %r; using %r",
                self.node.resolve_name(where),
                type(default).__name__,
                value,
                default,
            )
            return default
        return value

    def _observation_sources(self) -> list[dict[str, Any]]:
        names = self.get("observation_sources", "", "obstacle_layer")
        if not self.costmap.params.use_obstacles:
            return []
        out = []
        for name in str(names).split():
            base = None
            for cand in (f"{self.ns}/obstacle_layer/{name}", f"{self.ns}/{name}"):
                if self.node.has_param(cand):
                    base = self.node.get_param(cand)
                    break
            if not isinstance(base, dict):
                self.node.log.error("%s: observation source '%s' has no parameters; ignored", self.ns, name)
                continue
            kind = str(base.get("data_type", "LaserScan"))
            if kind != "LaserScan":
                self.node.log.error(
                    "%s: observation source '%s' has data_type %s; only LaserScan is supported",
                    self.ns,
                    name,
                    kind,
                )
                continue
            out.append(
                {
                    "topic": str(base.get("topic", name)),
                    "marking": bool(base.get("marking", True)),
                    "clearing": bool(base.get("clearing", True)),
                    "sensor_frame": str(base.get("sensor_frame", "")).lstrip("/"),
                }
            )
        return out

    # -- output -------------------------------------------------------------------------------------

    def publish(self) -> None:
        cm = self.costmap
        if cm.size_x == 0:
            return
        occ = to_occupancy(cm.costs)
        key = (cm.costs.shape, round(cm.origin_x, 6), round(cm.origin_y, 6))
        if self._published != key or self._last_costs is None:
            msg = self._grid_cls()
            msg.header.frame_id = self.global_frame
            msg.header.stamp = self.node.now()
            fill_info(
                msg.info,
                cm.size_x,
                cm.size_y,
                cm.resolution,
                (cm.origin_x, cm.origin_y, 0.0),
                self.node.get_time(),
            )
            msg.data = occ.ravel()
            self.pub.publish(msg)
            self._published = key
        else:
            changed = np.argwhere(occ != self._last_costs)
            if len(changed) == 0:
                return
            y0, x0 = changed.min(axis=0)
            y1, x1 = changed.max(axis=0) + 1
            up = self._update_cls()
            up.header.frame_id = self.global_frame
            up.header.stamp = self.node.now()
            up.x, up.y, up.width, up.height = int(x0), int(y0), int(x1 - x0), int(y1 - y0)
            up.data = np.ascontiguousarray(occ[y0:y1, x0:x1]).ravel()
            self.update_pub.publish(up)
        self._last_costs = occ
