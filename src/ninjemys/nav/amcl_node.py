"""``rosrun amcl amcl``: ROS 1 amcl's node over :mod:`ninjemys.nav.amcl`.

Subscribes ``scan`` (sensor_msgs/LaserScan), ``initialpose`` (PoseWithCovarianceStamped) and, with
``~use_map_topic``, ``map``; otherwise asks the ``static_map`` service once. Publishes ``amcl_pose``
(latched PoseWithCovarianceStamped), ``particlecloud`` (latched PoseArray) and the TF ``map -> odom``
(``~global_frame_id -> ~odom_frame_id``, stamped scan time + ``~transform_tolerance``). Services:
``global_localization`` (spread the particles over the free space), ``request_nomotion_update``
(force an update without motion), ``set_map`` (nav_msgs/SetMap).

The filter updates when odometry moved more than ``~update_min_d`` along x or y or turned more than
``~update_min_a`` since the last update (amcl compares each component), and resamples every
``~resample_interval`` updates (``~selective_resampling``: only when the effective sample size is below
half the set). After a resampling that injected uniform particles (recovery), the next scan updates the
filter even without motion, so the injected particles are weighed at once. ``~global_candidates`` (ours,
0 = ROS 1's behaviour): the first scan after ``global_localization`` keeps the ``~max_particles`` best of
that many uniform candidates. Only the likelihood-field laser model and the diff-drive odometry model
exist: other ``~laser_model_type``/``~odom_model_type`` values are reported once and replaced.
"""

from __future__ import annotations

import math
import threading
from typing import Any

import numpy as np

from ninjemys.nav.amcl import AMCLParams, ParticleFilter
from ninjemys.nav.rosglue import (
    Pose2D,
    Tf2D,
    fill_pose,
    grid_from_msg,
    param,
    pose_msg_to_2d,
    run_core_node,
    scan_arrays,
    tf_item,
)
from ninjemys.node.log import WARN
from ninjemys.tf2.math import se2_compose, se2_inverse


class AmclNode:
    """The node's state; every callback takes :attr:`lock`."""

    def __init__(self, node: Any) -> None:
        from geometry_msgs.msg import PoseArray, PoseWithCovarianceStamped
        from nav_msgs.msg import OccupancyGrid
        from nav_msgs.srv import SetMap
        from sensor_msgs.msg import LaserScan
        from std_srvs.srv import Empty

        self.node = node
        self.lock = threading.RLock()
        self.params = AMCLParams()
        values = {}
        for name in AMCLParams.__dataclass_fields__:
            values[name] = param(node, name, getattr(self.params, name))
        self.params.update(values)
        laser_model = param(node, "laser_model_type", "likelihood_field")
        if laser_model not in ("likelihood_field", "likelihood_field_prob"):
            self.node.log.warn(
                "amcl: ~laser_model_type %r is not available; using likelihood_field", laser_model
            )
        odom_model = param(node, "odom_model_type", "diff")
        if odom_model not in ("diff", "diff-corrected"):
            self.node.log.warn("amcl: ~odom_model_type %r is not available; using diff", odom_model)
        self.global_frame = param(node, "global_frame_id", "map")
        self.odom_frame = param(node, "odom_frame_id", "odom")
        self.base_frame = param(node, "base_frame_id", "base_link")
        self.tf_broadcast = param(node, "tf_broadcast", True)
        self.tolerance = param(node, "transform_tolerance", 0.1)
        self.seed = param(node, "seed", -1)
        self.init_pose = (
            param(node, "initial_pose_x", 0.0),
            param(node, "initial_pose_y", 0.0),
            param(node, "initial_pose_a", 0.0),
        )
        self.init_cov = (
            param(node, "initial_cov_xx", 0.5 * 0.5),
            param(node, "initial_cov_yy", 0.5 * 0.5),
            param(node, "initial_cov_aa", (math.pi / 12) ** 2),
        )
        self.pf: ParticleFilter | None = None
        self.last_odom: Pose2D | None = None
        self.force_update = True
        self.updates = 0
        self.map_to_odom: Pose2D | None = None
        self.laser_pose: dict[str, Pose2D] = {}
        self.bad_scan_reported = False
        self.tf = Tf2D(node)
        self.pose_pub = node.publisher("amcl_pose", PoseWithCovarianceStamped, queue_size=2, latch=True)
        self.cloud_pub = node.publisher("particlecloud", PoseArray, queue_size=2, latch=True)
        self._pose_cls, self._cloud_cls = PoseWithCovarianceStamped, PoseArray
        node.service("global_localization", Empty, self.on_global_localization)
        node.service("request_nomotion_update", Empty, self.on_nomotion)
        node.service("set_map", SetMap, self.on_set_map)
        node.subscriber("initialpose", PoseWithCovarianceStamped, self.on_initial_pose)
        node.subscriber("scan", LaserScan, self.on_scan, queue_size=1)
        if param(node, "use_map_topic", False):
            node.subscriber("map", OccupancyGrid, self.on_map, queue_size=1)
        else:
            threading.Thread(target=self._request_map, name="amcl-static-map", daemon=True).start()

    # -- map ----------------------------------------------------------------------------------------

    def _request_map(self) -> None:
        from nav_msgs.srv import GetMap

        self.node.log.info("Requesting the map...")
        while not self.node.is_shutdown:
            try:
                self.node.wait_for_service("static_map", timeout=2.0)
                proxy = self.node.service_proxy("static_map", GetMap)
                self.on_map(proxy().map)
                return
            except Exception as exc:  # the service is not up yet: ROS 1 amcl waits and retries too
                self.node.log.log_throttle(10.0, WARN, "Request for map failed; trying again... (%s)", exc)

    def on_map(self, msg: Any) -> None:
        with self.lock:
            if self.pf is not None and param(self.node, "first_map_only", False):
                return
            grid = grid_from_msg(msg)
            self.node.log.info(
                "Received a %d X %d map @ %.3f m/pix", grid.width, grid.height, grid.resolution
            )
            seed = None if self.seed < 0 else self.seed
            self.pf = ParticleFilter(grid, self.params, seed=seed)
            x, y, a = self.init_pose
            self.pf.init_gaussian((x, y, a), *self.init_cov)
            self.node.log.info("Initializing with the initial pose: %.3f %.3f %.3f", x, y, a)
            self.force_update = True
            self.last_odom = None

    def on_set_map(self, req: Any) -> Any:
        from nav_msgs.srv import SetMapResponse

        self.on_map(req.map)
        self.on_initial_pose(req.initial_pose)
        return SetMapResponse(success=True)

    # -- services and initial pose ------------------------------------------------------------------

    def on_global_localization(self, _req: Any) -> Any:
        from std_srvs.srv import EmptyResponse

        with self.lock:
            if self.pf is None:
                self.node.log.warn("amcl: global_localization before a map arrived; ignored")
            else:
                self.node.log.info("Initializing with uniform distribution")
                self.pf.init_global()
                self.force_update = True
                self.node.log.info("Global initialisation done!")
        return EmptyResponse()

    def on_nomotion(self, _req: Any) -> Any:
        from std_srvs.srv import EmptyResponse

        with self.lock:
            self.force_update = True
        self.node.log.info("Requesting no-motion update")
        return EmptyResponse()

    def on_initial_pose(self, msg: Any) -> None:
        frame = msg.header.frame_id.lstrip("/")
        if frame and frame != self.global_frame:
            self.node.log.warn(
                'Ignoring initial pose in frame "%s"; initial poses must be in the global frame, "%s"',
                frame,
                self.global_frame,
            )
            return
        x, y, a = pose_msg_to_2d(msg.pose.pose)
        cov = msg.pose.covariance
        if not all(math.isfinite(v) for v in (x, y, a, cov[0], cov[7], cov[35])):
            self.node.log.error("amcl: initialpose has NaN or inf values; ignored")
            return
        with self.lock:
            self.node.log.info("Setting pose (%.6f): %.3f %.3f %.3f", self.node.get_time(), x, y, a)
            self.init_pose = (x, y, a)
            self.init_cov = (float(cov[0]), float(cov[7]), float(cov[35]))
            if self.pf is not None:
                self.pf.init_gaussian((x, y, a), *self.init_cov)
                self.force_update = True

    # -- the filter ---------------------------------------------------------------------------------

    def on_scan(self, scan: Any) -> None:
        if self.pf is None:
            return
        t = scan.header.stamp.to_sec()
        # the odometry of the scan's own instant (waiting for it, as amcl's message filter does)
        odom = self.tf.lookup_at(self.odom_frame, self.base_frame, t)
        if odom is None:
            self.node.log.log_throttle(
                5.0,
                WARN,
                "amcl: no transform %s -> %s at the scan's stamp %.3f; scan dropped",
                self.odom_frame,
                self.base_frame,
                t,
            )
            return
        with self.lock:
            if self.pf is None:
                return
            laser_frame = scan.header.frame_id or self.base_frame
            laser = self.laser_pose.get(laser_frame)
            if laser is None:
                laser = self.tf.lookup(self.base_frame, laser_frame, 0.0)
                if laser is None:
                    self.node.log.log_throttle(
                        5.0, WARN, "amcl: no transform %s -> %s yet", self.base_frame, laser_frame
                    )
                    return
                self.laser_pose[laser_frame] = laser
            ranges, angles = scan_arrays(scan)
            bad = ~np.isfinite(ranges)
            if bad.any() and not self.bad_scan_reported:
                self.bad_scan_reported = True
                self.node.log.warn(
                    "amcl: scan from %s has %d NaN/inf ranges of %d; those beams are skipped",
                    laser_frame,
                    int(bad.sum()),
                    len(ranges),
                )
            update = self.force_update
            if self.last_odom is not None:
                d = se2_compose(se2_inverse(self.last_odom), odom)
                moved = (
                    abs(odom[0] - self.last_odom[0]) > self.params.update_min_d
                    or abs(odom[1] - self.last_odom[1]) > self.params.update_min_d
                    or abs(d[2]) > self.params.update_min_a
                )
                update = update or moved
            if update:
                if self.last_odom is not None:
                    self.pf.motion_update(self.last_odom, odom)
                self.last_odom = odom
                self.pf.sensor_update(ranges, angles, float(scan.range_max), laser, float(scan.range_min))
                self.updates += 1
                # the estimate of the weighed set, before resampling: particles injected for recovery
                # are not weighed yet, and thousands of them would connect the real cluster into one
                # spanning the map (a huge covariance, which makes the safety monitor stop the robot)
                mean, cov = self.pf.estimate()
                injected = 0
                if self.updates % max(1, self.params.resample_interval) == 0:
                    injected = self.pf.resample()
                # injected particles are weighed by the next scan even if the robot does not move
                # (ROS 1's amcl waits for motion; a robot stopped for its covariance would wait forever)
                self.force_update = injected > 0
                est = (float(mean[0]), float(mean[1]), float(mean[2]))
                self._publish_pose(scan, est, cov)
                self.map_to_odom = se2_compose(est, se2_inverse(odom))
            if self.map_to_odom is not None and self.tf_broadcast:
                self.tf.send(
                    [tf_item(self.global_frame, self.odom_frame, t + self.tolerance, self.map_to_odom)]
                )

    def _publish_pose(self, scan: Any, est: Pose2D, cov: np.ndarray) -> None:
        msg = self._pose_cls()
        msg.header.frame_id = self.global_frame
        msg.header.stamp = scan.header.stamp
        fill_pose(msg.pose.pose, est)
        c = [0.0] * 36
        c[0], c[1], c[6], c[7], c[35] = (
            float(cov[0, 0]),
            float(cov[0, 1]),
            float(cov[1, 0]),
            float(cov[1, 1]),
            float(cov[2, 2]),
        )
        msg.pose.covariance = c
        self.pose_pub.publish(msg)
        cloud = self._cloud_cls()
        cloud.header.frame_id = self.global_frame
        cloud.header.stamp = scan.header.stamp
        from geometry_msgs.msg import Pose

        assert self.pf is not None
        cloud.poses = [
            fill_pose(Pose(), (p[0], p[1], p[2])) for p in self.pf.poses[:: max(1, len(self.pf.poses) // 500)]
        ]
        self.cloud_pub.publish(cloud)


def main(argv: list[str] | None = None) -> int:
    return run_core_node("amcl", argv, AmclNode)
