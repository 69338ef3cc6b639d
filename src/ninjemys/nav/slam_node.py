"""``rosrun gmapping slam_gmapping``: slam_gmapping's interface over :mod:`ninjemys.nav.slam`.

Subscribes ``scan``; reads odometry from TF (``~odom_frame`` -> ``~base_frame``) at each scan's own
stamp (gmapping's tf message filter: a scan waits for the odometry of its instant, however late /tf
runs under load); publishes ``map`` and ``map_metadata`` (latched, every ``~map_update_interval``
seconds), the TF ``~map_frame`` -> ``~odom_frame`` every ``~transform_publish_period`` seconds, and
answers ``dynamic_map`` (nav_msgs/GetMap); ``~entropy`` (std_msgs/Float64) carries the particle
weights' entropy with each map update. gmapping's parameters keep their names and meaning: the map
(``~delta``, ``~xmin``.., ``~occ_thresh``), the laser (``~maxUrange``, ``~maxRange``, ``~lskip``), the
update rule (``~linearUpdate``, ``~angularUpdate``), the filter (``~particles``,
``~resampleThreshold``, the motion model ``~srr`` ``~srt`` ``~str`` ``~stt``) and the matcher
(``~sigma``, ``~lstep``, ``~astep``, ``~ogain``). ``~kernelSize``, ``~iterations``, ``~lsigma`` and the
``~l?sample*`` ranges belong to gmapping's hill-climbing matcher, which the grid search here replaces;
they are ignored.
"""

from __future__ import annotations

import threading
from typing import Any

import numpy as np

from ninjemys.maps.mapfile import GridMap
from ninjemys.nav.rosglue import Tf2D, grid_to_msg, node_sleep, param, run_core_node, scan_arrays, tf_item
from ninjemys.nav.slam import ParticleMapper, SlamParams
from ninjemys.node.log import WARN


class SlamNode:
    def __init__(self, node: Any) -> None:
        from nav_msgs.msg import MapMetaData, OccupancyGrid
        from nav_msgs.srv import GetMap
        from sensor_msgs.msg import LaserScan
        from std_msgs.msg import Float64

        self.node = node
        self.lock = threading.Lock()
        params = SlamParams()
        rejected = params.update(
            {name: param(node, name, getattr(params, name)) for name in SlamParams.__dataclass_fields__}
        )
        for name, reason in rejected:
            self.node.log.error("slam_gmapping: parameter %s: %s", node.resolve_name("~" + name), reason)
        self.mapper = ParticleMapper(params)
        self.map_frame = param(node, "map_frame", "map")
        self.odom_frame = param(node, "odom_frame", "odom")
        self.base_frame = param(node, "base_frame", "base_link")
        self.update_interval = param(node, "map_update_interval", 5.0)
        self.tf_period = param(node, "transform_publish_period", 0.05)
        self.tf = Tf2D(node)
        self.correction = (0.0, 0.0, 0.0)
        self.laser: dict[str, tuple[float, float, float]] = {}
        self.last_map_time = -1e9
        self.bad_scan_reported = False
        self.got_first_scan = False
        self.map_msg: Any = None
        self._grid_cls = OccupancyGrid
        self._float_cls = Float64
        self.map_pub = node.publisher("map", OccupancyGrid, queue_size=1, latch=True)
        self.meta_pub = node.publisher("map_metadata", MapMetaData, queue_size=1, latch=True)
        self.entropy_pub = node.publisher("~entropy", Float64, queue_size=1, latch=True)
        node.service("dynamic_map", GetMap, self.on_dynamic_map)
        node.subscriber("scan", LaserScan, self.on_scan, queue_size=5)
        if self.tf_period > 0:
            threading.Thread(target=self.tf_loop, name="slam-tf", daemon=True).start()

    def tf_loop(self) -> None:
        while node_sleep(self.node, self.tf_period):
            corr = self.correction  # one tuple, swapped whole: no lock, so a long filter step never
            # holds back the transform (amcl and move_base would see map -> odom go stale)
            self.tf.send(
                [tf_item(self.map_frame, self.odom_frame, self.node.get_time() + self.tf_period, corr)]
            )

    def on_scan(self, scan: Any) -> None:
        t = scan.header.stamp.to_sec()
        odom = self.tf.lookup_at(self.odom_frame, self.base_frame, t)  # gmapping's message filter
        if odom is None:
            self.node.log.log_throttle(
                5.0,
                WARN,
                "slam_gmapping: no transform %s -> %s at the scan's stamp; scan dropped",
                self.odom_frame,
                self.base_frame,
            )
            return
        frame = scan.header.frame_id or self.base_frame
        laser = self.laser.get(frame)
        if laser is None:
            laser = self.tf.lookup(self.base_frame, frame, 0.0)
            if laser is None:
                return
            self.laser[frame] = laser
        ranges, angles = scan_arrays(scan)
        if not self.bad_scan_reported and not np.isfinite(ranges).all():
            self.bad_scan_reported = True
            self.node.log.warn(
                "slam_gmapping: scan from %s has NaN/inf ranges (%d of %d): NaN and -inf are skipped, +inf is free space up to maxUrange",
                frame,
                int((~np.isfinite(ranges)).sum()),
                len(ranges),
            )
        with self.lock:
            if not self.mapper.should_process(odom):
                return
            self.mapper.process(odom, ranges, angles, laser, float(scan.range_max))
            self.correction = self.mapper.map_to_odom(odom)
            publish = t - self.last_map_time >= self.update_interval or not self.got_first_scan
            self.got_first_scan = True
            if publish:
                self.last_map_time = t
                entropy = self.mapper.entropy()
                p = self.mapper.params
                grid = GridMap(self.mapper.occupancy(), p.delta, (p.xmin, p.ymin, 0.0))
                self.map_msg = grid_to_msg(grid, self.map_frame, self.node.get_time(), cls=self._grid_cls)
        if publish:
            if entropy > 0.0:  # as slam_gmapping: published with each map update, when above zero
                self.entropy_pub.publish(self._float_cls(data=entropy))
            self.meta_pub.publish(self.map_msg.info)
            self.map_pub.publish(self.map_msg)

    def on_dynamic_map(self, _req: Any) -> Any:
        from nav_msgs.srv import GetMapResponse

        with self.lock:
            p = self.mapper.params
            grid = GridMap(self.mapper.occupancy(), p.delta, (p.xmin, p.ymin, 0.0))
        return GetMapResponse(map=grid_to_msg(grid, self.map_frame, self.node.get_time(), cls=self._grid_cls))


def main(argv: list[str] | None = None) -> int:
    return run_core_node("slam_gmapping", argv, SlamNode)
