"""``rosrun move_base move_base``: ROS 1 move_base's interface over the numpy planners.

- Action ``move_base`` (move_base_msgs/MoveBaseAction): a new goal preempts the current one (as
  SimpleActionServer does); feedback ``base_position`` is the robot's pose in the global frame every
  control cycle. ``/move_base_simple/goal`` (PoseStamped) sends a goal without a client.
- Services ``~make_plan`` (nav_msgs/GetPlan) and ``~clear_costmaps`` (std_srvs/Empty).
- Costmaps ``~global_costmap`` and ``~local_costmap`` (see :mod:`ninjemys.nav.costmap_ros`), the global
  plan on ``~GlobalPlanner/plan`` (nav_msgs/Path), the local plan on ``~DWAPlannerROS/local_plan``,
  the goal on ``~current_goal``, ``cmd_vel`` (geometry_msgs/Twist) out; ``odom`` (nav_msgs/Odometry) in
  for the current velocity.
- Parameters: move_base's (``~controller_frequency``, ``~planner_frequency``, ``~controller_patience``,
  ``~planner_patience``, ``~oscillation_timeout``, ``~oscillation_distance``,
  ``~recovery_behavior_enabled``, ``~clearing_rotation_allowed``, ``~conservative_reset_dist``),
  the planner's under ``~GlobalPlanner`` (or ``~NavfnROS``): ``allow_unknown``, ``neutral_cost``,
  ``cost_factor``, ``default_tolerance``, and dwa_local_planner's under ``~DWAPlannerROS``
  (``~TrajectoryPlannerROS`` names are read too). ``~DWAPlannerROS`` and move_base's own tunables
  are dynamic_reconfigure servers, as in ROS 1.

Goals outside the global costmap or on a lethal/inscribed cell are rejected with the reason in the
goal status text (ROS 1 accepts them and aborts after ``planner_patience``); when the local planner
finds no safe arc for ``controller_patience`` seconds, or the robot oscillates, the recovery
behaviours run in ROS 1's order (conservative reset, rotate in place, aggressive reset, rotate), then
the goal is aborted.

Those rules are :class:`~ninjemys.nav.move_base.MoveBaseFsm`'s, which has no ROS inside; this module
keeps the I/O and three threads (control, planner, costmaps), plugs DWA, the grid planner and the
costmap-clearing recoveries into its seams, and feeds it from one goal inbox (action goals,
``move_base_simple`` goals and cancels, in arrival order). The node is a core
:class:`~ninjemys.node.Node` made from the command line (no rospy).
"""

from __future__ import annotations

import math
import threading
from dataclasses import fields
from typing import Any

import numpy as np

from ninjemys.actionlib import states
from ninjemys.errors import NinjemysError, ShutdownError
from ninjemys.nav.costmap import INSCRIBED
from ninjemys.nav.costmap_ros import CostmapROS
from ninjemys.nav.dwa import DWAParams, DWAPlanner
from ninjemys.nav.move_base import (
    CANCELABLE,
    ClearCostmaps,
    Command,
    MoveBaseFsm,
    MoveBaseParams,
    Outcome,
    RotateRecovery,
    Step,
)
from ninjemys.nav.planner import PlanError, plan_path
from ninjemys.nav.rosglue import (
    Pose2D,
    Tf2D,
    fill_pose,
    grid_from_msg,
    node_sleep,
    param,
    pose_msg_to_2d,
    run_core_node,
    scan_arrays,
)
from ninjemys.nav.safety import StopZone, scan_points
from ninjemys.nav.safety_node import read_stop_zone
from ninjemys.node.log import WARN
from ninjemys.tf2.math import se2_compose

#: dwa_local_planner's names for the base_local_planner (TrajectoryPlannerROS) parameters we map
TRAJECTORY_ALIASES = {
    "max_vel_theta": "max_rot_vel",
    "min_vel_theta": "min_rot_vel",
    "max_vel_x": "max_vel_x",
    "min_vel_x": "min_vel_x",
    "acc_lim_theta": "acc_lim_th",
    "path_distance_bias": "pdist_scale",
    "goal_distance_bias": "gdist_scale",
}


def move_base_params(node: Any) -> MoveBaseParams:
    """MoveBaseParams from move_base's private parameters."""
    p = MoveBaseParams()
    for f in fields(p):
        setattr(p, f.name, param(node, f.name, getattr(p, f.name)))
    p.controller_frequency = max(1.0, p.controller_frequency)
    return p


class DwaController:
    """The controller seam over :class:`DWAPlanner` and the local costmap, which is brought up to date
    (new marks, the window moved) just before each command."""

    def __init__(self, dwa: DWAPlanner, local_cm: CostmapROS, refresh: Any) -> None:
        self.dwa = dwa
        self.local_cm = local_cm
        self._refresh = refresh

    def new_goal(self) -> None:
        self.dwa.new_goal()

    def set_plan(self, plan: np.ndarray) -> None:
        latched = self.dwa.xy_latched
        self.dwa.set_plan(plan)
        self.dwa.xy_latched = latched  # a replan for the same goal keeps the goal latch

    def compute(
        self,
        pose: Pose2D,
        velocity: tuple[float, float],
        period: float | None,
        stamps: tuple[float, float] | None = None,
    ) -> Command:
        self._refresh(self.local_cm, pose)
        return self.dwa.compute(pose, velocity, self.local_cm.costmap, period, stamps)

    def remaining(self) -> int:
        return len(self.dwa.plan)


class GridPlanner:
    """The planner seam over :func:`plan_path` on the global costmap (a copy of its costs, taken under
    move_base's lock, so the search itself runs unlocked)."""

    def __init__(self, owner: MoveBase) -> None:
        self.owner = owner

    def make_plan(self, start: Pose2D, goal: Pose2D) -> np.ndarray:
        return self.owner._make_plan(start, goal)


def dwa_params(node: Any) -> DWAParams:
    """DWAParams from ``~DWAPlannerROS/*`` (falling back to ``~TrajectoryPlannerROS/*``)."""
    p = DWAParams()
    for f in fields(p):
        default = getattr(p, f.name)
        for key in (
            f"DWAPlannerROS/{f.name}",
            f"TrajectoryPlannerROS/{TRAJECTORY_ALIASES.get(f.name, f.name)}",
        ):
            if node.has_param("~" + key):
                setattr(p, f.name, param(node, key, default))
                break
    p.controller_frequency = param(node, "controller_frequency", 20.0)
    return p


def stop_zone(node: Any) -> StopZone | None:
    """The safety monitor's stop zone for the local planner, from the monitor's own parameters
    (``~DWAPlannerROS/stop_zone_from``: its namespace, e.g. ``/safety_monitor``; empty: no check, as in
    ROS 1). One set of numbers for both: a planner laxer than the monitor has its arcs refused."""
    ns = str(param(node, "DWAPlannerROS/stop_zone_from", "")).strip()
    if not ns:
        return None
    try:
        prefix = node.resolve_name(ns).rstrip("/") + "/"
    except NinjemysError as exc:
        node.log.error("move_base: ~DWAPlannerROS/stop_zone_from: %s; no stop-zone check", exc)
        return None
    if not any(node.has_param(prefix + key) for key in ("robot_radius", "footprint", "safety_margin")):
        node.log.warn(
            "move_base: ~DWAPlannerROS/stop_zone_from is %s, but it has no robot_radius, footprint or "
            "safety_margin: the planner keeps the default stop zone of the monitor",
            prefix.rstrip("/"),
        )
    return read_stop_zone(node, prefix)


class MoveBase:
    """The node: costmaps, planners, the control loop and the action server."""

    def __init__(self, node: Any) -> None:
        from geometry_msgs.msg import PoseStamped, Twist
        from nav_msgs.msg import OccupancyGrid, Odometry, Path
        from nav_msgs.srv import GetPlan
        from std_srvs.srv import Empty

        self.node = node
        self.log = node.log
        self.lock = threading.RLock()
        self.params = move_base_params(node)
        planner_ns = "GlobalPlanner" if node.has_param("~GlobalPlanner") else "NavfnROS"
        self.allow_unknown = param(node, f"{planner_ns}/allow_unknown", True)
        self.neutral_cost = param(node, f"{planner_ns}/neutral_cost", 50.0)
        self.cost_factor = param(node, f"{planner_ns}/cost_factor", 3.0)
        self.goal_tolerance = param(node, f"{planner_ns}/default_tolerance", 0.0)
        self.global_cm = CostmapROS(node, "~global_costmap")
        self.local_cm = CostmapROS(node, "~local_costmap")
        self.dwa = DWAPlanner(dwa_params(node), stop_zone(node))
        self._stop_points: dict[str, np.ndarray] = {}  # per scan topic, robot frame (the planner's stop zone)
        self.tf = Tf2D(node)
        self.odom = (0.0, 0.0, 0.0)  # the newest odometry: v, w and its stamp (0: none yet)
        self.fsm = MoveBaseFsm(
            self.params,
            GridPlanner(self),
            DwaController(self.dwa, self.local_cm, self._refresh),
            [
                ClearCostmaps(
                    "conservative_reset", self._clear_outside, lambda: self.params.conservative_reset_dist
                ),
                RotateRecovery(
                    lambda: self.dwa.params.max_vel_theta, lambda: self.params.clearing_rotation_allowed
                ),
                ClearCostmaps("aggressive_reset", self._clear_outside, lambda: 0.0),
                RotateRecovery(
                    lambda: self.dwa.params.max_vel_theta, lambda: self.params.clearing_rotation_allowed
                ),
            ],
        )
        # the one goal inbox: action goals, move_base_simple goals and cancels, taken by the control loop
        self.inbox: list[tuple[str, Any, Any]] = []
        self.inbox_lock = threading.Lock()
        self.plan_event = threading.Event()
        self._path_cls, self._pose_stamped = Path, PoseStamped
        self.cmd_pub = node.publisher("cmd_vel", Twist, queue_size=1)
        self._twist = Twist
        self.plan_pub = node.publisher(
            f"~{planner_ns if planner_ns == 'NavfnROS' else 'GlobalPlanner'}/plan", Path, queue_size=1
        )
        self.local_plan_pub = node.publisher("~DWAPlannerROS/local_plan", Path, queue_size=1)
        self.goal_pub = node.publisher("~current_goal", PoseStamped, queue_size=1, latch=True)
        self.scan_subs = []
        topics: dict[str, list[CostmapROS]] = {}
        for cm in (self.global_cm, self.local_cm):
            for src in cm.sources:
                topics.setdefault(src["topic"], []).append(cm)
        from sensor_msgs.msg import LaserScan

        self.bad_scan_reported = False
        for topic, cms in topics.items():
            self.scan_subs.append(
                node.subscriber(topic, LaserScan, self.on_scan, callback_args=(topic, cms), queue_size=1)
            )
        if self.global_cm.costmap.params.use_static:
            node.subscriber("map", OccupancyGrid, self.on_map, queue_size=1)
        if self.local_cm.costmap.params.use_static:
            if not self.global_cm.costmap.params.use_static:
                node.subscriber("map", OccupancyGrid, self.on_map, queue_size=1)
        node.subscriber("odom", Odometry, self.on_odom, queue_size=1)
        node.subscriber("move_base_simple/goal", PoseStamped, self.on_simple_goal, queue_size=1)
        node.service("~make_plan", GetPlan, self.on_make_plan)
        node.service("~clear_costmaps", Empty, self.on_clear_costmaps)
        self._start_action_server()
        self._start_reconfigure()
        self.thread = threading.Thread(target=self.control_loop, name="move_base-control", daemon=True)
        self.thread.start()
        self.planner_thread = threading.Thread(
            target=self.planner_loop, name="move_base-planner", daemon=True
        )
        self.planner_thread.start()
        self.cm_thread = threading.Thread(target=self.costmap_loop, name="move_base-costmaps", daemon=True)
        self.cm_thread.start()

    # -- set-up -------------------------------------------------------------------------------------

    def _start_action_server(self) -> None:
        from move_base_msgs.msg import MoveBaseAction
        from ninjemys.actionlib.server import ActionServer

        self.server = ActionServer(self.node, "move_base", MoveBaseAction, self.on_goal, self.on_cancel)
        self.server.start()

    def _start_reconfigure(self) -> None:
        from ninjemys.dynamic_reconfigure.server import ReconfigureServer
        from ninjemys.nav.reconfigure import dwa_config_type, move_base_config_type

        self.dwa_reconf = ReconfigureServer(
            self.node, dwa_config_type(), self.on_dwa_reconfigure, "~DWAPlannerROS"
        )
        self.mb_reconf = ReconfigureServer(self.node, move_base_config_type(), self.on_mb_reconfigure, "~")

    def on_dwa_reconfigure(self, config: Any, _level: int) -> Any:
        with self.lock:
            self.dwa.params.update(
                {k: config[k] for k in config if hasattr(self.dwa.params, k) and k != "controller_frequency"}
            )
        return config

    def on_mb_reconfigure(self, config: Any, _level: int) -> Any:
        with self.lock:
            for f in fields(self.params):
                if f.name in config:
                    kind = type(getattr(self.params, f.name))
                    setattr(self.params, f.name, kind(config[f.name]))
            self.params.controller_frequency = max(1.0, self.params.controller_frequency)
            self.dwa.params.controller_frequency = self.params.controller_frequency
        return config

    # -- inputs -------------------------------------------------------------------------------------

    def on_map(self, msg: Any) -> None:
        grid = grid_from_msg(msg)
        with self.lock:
            for cm in (self.global_cm, self.local_cm):
                if cm.costmap.params.use_static:
                    cm.costmap.set_static_map(grid.data, grid.resolution, grid.origin[0], grid.origin[1])
            if self.global_cm.costmap.params.use_static:
                self.global_cm.costmap.update()
        self.log.info(
            "move_base: received a %d X %d map at %.3f m/pix", grid.width, grid.height, grid.resolution
        )

    def on_odom(self, msg: Any) -> None:
        # one assignment: the control cycle reads a velocity and its stamp of the same message
        self.odom = (
            float(msg.twist.twist.linear.x),
            float(msg.twist.twist.angular.z),
            msg.header.stamp.to_sec(),
        )

    def on_scan(self, scan: Any, source: tuple[str, list[CostmapROS]]) -> None:
        """A rolling window (the local costmap the controller reads) marks the scan at once; a map-sized
        costmap keeps the newest scan of each source for its next update (ROS 1's observation buffer
        with ``observation_persistence`` 0), so it costs per its update_frequency, not per scan."""
        topic, cms = source
        if self.dwa.stop_zone is not None and self.local_cm in cms:
            self._stop_scan(topic, scan)
        for cm in cms:
            if cm.costmap.params.rolling_window:
                self._apply_scan(cm, scan)
            else:
                cm.observations[topic] = scan

    def _stop_scan(self, topic: str, scan: Any) -> None:
        """The scan's returns in the robot's frame, for the planner's stop-zone check: the points the
        safety monitor judges the command on, read as it reads them (newest scan, latest transform)."""
        ranges, angles = scan_arrays(scan)
        base = self.local_cm.robot_base_frame
        sensor = self.tf.lookup(base, scan.header.frame_id or base, 0.0) or (0.0, 0.0, 0.0)
        self._stop_points[topic] = scan_points(ranges, angles, scan.range_min, scan.range_max, sensor)
        points = list(self._stop_points.values())
        self.dwa.stop_points = points[0] if len(points) == 1 else np.concatenate(points)

    def _apply_scan(self, cm: CostmapROS, scan: Any) -> None:
        """Raytrace and mark one scan (move_base's lock not held while the sensor's pose arrives)."""
        ranges, angles = scan_arrays(scan)
        if not self.bad_scan_reported and not np.isfinite(ranges).all():
            self.bad_scan_reported = True
            self.log.warn(
                "move_base: scan on %s has NaN/inf ranges (%d of %d): NaN is dropped, inf clears without marking",
                scan.header.frame_id,
                int((~np.isfinite(ranges)).sum()),
                len(ranges),
            )
        ranges = np.where(np.isneginf(ranges), scan.range_min, ranges)  # REP 117: closer than range_min
        # the costmap's message filter: the sensor's pose at the scan's own stamp
        sensor = self.tf.lookup_at(cm.global_frame, scan.header.frame_id, scan.header.stamp.to_sec())
        if sensor is None:
            return
        with self.lock:
            if cm.costmap.params.rolling_window:
                cm.costmap.update_origin(sensor[0], sensor[1])
            cm.costmap.add_scan(sensor[0], sensor[1], sensor[2] + angles, ranges, float(scan.range_max))
            cm.dirty = True

    def _refresh(self, cm: CostmapROS, robot: Pose2D) -> None:
        """Centre a rolling window on ``robot`` and recompute its costs if it moved or got new marks
        (move_base's lock held)."""
        c = cm.costmap
        before = (c.origin_x, c.origin_y, c.size_x)
        c.update_origin(robot[0], robot[1])
        if cm.dirty or before != (c.origin_x, c.origin_y, c.size_x):
            c.update()
            cm.dirty = False

    def update_costmap(self, cm: CostmapROS) -> None:
        """One update of ``cm`` (ROS 1's updateMap): a map-sized costmap takes its newest scans, a
        rolling window follows the robot; then the costs are recomputed where needed."""
        if cm.costmap.params.rolling_window:
            robot = self._robot_pose(cm)
            if robot is not None:
                with self.lock:
                    self._refresh(cm, robot)
            return
        pending, cm.observations = cm.observations, {}
        for scan in pending.values():
            self._apply_scan(cm, scan)
        with self.lock:
            cm.costmap.update()

    # -- goals --------------------------------------------------------------------------------------

    def _goal_in_global(self, pose_stamped: Any) -> tuple[Pose2D | None, str]:
        p = pose_msg_to_2d(pose_stamped.pose)
        q = pose_stamped.pose.orientation
        norm = math.sqrt(q.x**2 + q.y**2 + q.z**2 + q.w**2)
        if not all(math.isfinite(v) for v in p) or not math.isfinite(norm) or norm < 1e-6:
            return None, "Aborting on goal because it was sent with an invalid quaternion"
        frame = pose_stamped.header.frame_id.lstrip("/") or self.global_cm.global_frame
        if frame != self.global_cm.global_frame:
            tr = self.tf.lookup(self.global_cm.global_frame, frame, 0.0)
            if tr is None:
                return None, f"cannot transform the goal from frame {frame} to {self.global_cm.global_frame}"
            p = se2_compose(tr, p)
        # read without move_base's lock: the action server calls this with its own lock held, and the
        # control loop takes the two in the other order (the grid and its costs are replaced, not edited)
        cm = self.global_cm.costmap
        # judged on the map (static layer, inflated), not on what the sensors see now: a person
        # standing on the goal does not make it a bad goal
        costs = cm.static_costs if cm.static_costs is not None else cm.costs
        size_x, size_y = cm.size_x, cm.size_y
        ox, oy, res = cm.origin_x, cm.origin_y, cm.resolution
        if size_x == 0 or costs.shape != (size_y, size_x):
            return None, "the global costmap has no map yet"
        cx, cy = int(math.floor((p[0] - ox) / res)), int(math.floor((p[1] - oy) / res))
        if not (0 <= cx < size_x and 0 <= cy < size_y):
            x1, y1 = ox + size_x * res, oy + size_y * res
            return None, (
                f"The goal ({p[0]:.2f}, {p[1]:.2f}) is off the global costmap "
                f"([{ox:.2f}, {x1:.2f}] x [{oy:.2f}, {y1:.2f}])"
            )
        cost = int(costs[cy, cx])
        if INSCRIBED <= cost < 255:
            what = "an obstacle" if cost > INSCRIBED else "the inflated zone of an obstacle"
            return None, f"The goal ({p[0]:.2f}, {p[1]:.2f}) is in {what} (cost {cost})"
        return p, ""

    def on_goal(self, handle: Any) -> None:
        """Runs with the action server's lock held: decide here, hand the goal to the control loop."""
        goal, reason = self._goal_in_global(handle.get_goal().target_pose)
        if goal is None:
            self.log.error("move_base: %s", reason)
            handle.set_rejected(None, reason)
            return
        handle.set_accepted("This goal has been accepted by the simple action server")
        self._post("goal", goal, handle)

    def on_cancel(self, handle: Any) -> None:
        """Runs with the action server's lock held: the control loop cancels."""
        self._post("cancel", None, handle)

    def on_simple_goal(self, msg: Any) -> None:
        """A ``move_base_simple/goal``: through the same inbox as action goals, with no handle."""
        goal, reason = self._goal_in_global(msg)
        if goal is None:
            self.log.error("move_base: %s", reason)
            return
        self._post("goal", goal, None)

    def _post(self, kind: str, goal: Pose2D | None, handle: Any) -> None:
        with self.inbox_lock:
            self.inbox.append((kind, goal, handle))

    def _take_inbox(self) -> list[Step]:
        """Apply goals and cancels in arrival order (control loop, move_base's lock held)."""
        with self.inbox_lock:
            items, self.inbox = self.inbox, []
        steps = []
        for kind, goal, handle in items:
            if kind == "goal":
                steps.append(self.fsm.accept(goal, handle, self.node.get_time()))
                self._publish_goal(goal)
            elif self.fsm.is_current(handle):
                steps.append(self.fsm.cancel(handle))
            elif handle.get_goal_status().status in CANCELABLE:
                handle.set_canceled(None, "")
        return steps

    def _publish_goal(self, goal: Pose2D) -> None:
        msg = self._pose_stamped()
        msg.header.frame_id = self.global_cm.global_frame
        msg.header.stamp = self.node.now()
        fill_pose(msg.pose, goal)
        self.goal_pub.publish(msg)

    # -- services -----------------------------------------------------------------------------------

    def on_make_plan(self, req: Any) -> Any:
        from nav_msgs.srv import GetPlanResponse

        resp = GetPlanResponse()
        resp.plan.header.frame_id = self.global_cm.global_frame
        goal, reason = self._goal_in_global(req.goal)
        if goal is None:
            self.log.error("move_base: make_plan: %s", reason)
            return resp
        start: Pose2D | None = pose_msg_to_2d(req.start.pose) if req.start.header.frame_id else None
        if start is None:
            start = self._robot_pose(self.global_cm)
        if start is None:
            self.log.error("move_base: make_plan: no robot pose in %s", self.global_cm.global_frame)
            return resp
        try:
            plan = self._make_plan(start, goal)
        except PlanError as exc:
            self.log.error("move_base: make_plan: %s", exc)
            return resp
        resp.plan = self._path_msg(plan, self.global_cm.global_frame)
        return resp

    def on_clear_costmaps(self, _req: Any) -> Any:
        from std_srvs.srv import EmptyResponse

        with self.lock:
            for cm in (self.global_cm, self.local_cm):
                cm.costmap.clear_obstacles()
                cm.costmap.update()
        return EmptyResponse()

    # -- planning and control -----------------------------------------------------------------------

    def _make_plan(self, start: Pose2D, goal: Pose2D) -> np.ndarray:
        with self.lock:
            cm = self.global_cm.costmap
            costs = cm.update().copy()
            origin = (cm.origin_x, cm.origin_y)
            res = cm.resolution
        # the robot's own cell may be inflated: the planner starts from it regardless
        return plan_path(
            costs,
            res,
            origin,
            start[:2],
            goal,
            self.neutral_cost,
            self.cost_factor,
            INSCRIBED,
            self.allow_unknown,
        )

    def _path_msg(self, plan: np.ndarray, frame: str) -> Any:
        from geometry_msgs.msg import PoseStamped

        path = self._path_cls()
        path.header.frame_id = frame
        path.header.stamp = self.node.now()
        out = []
        for x, y, yaw in plan:
            ps = PoseStamped()
            ps.header.frame_id = frame
            fill_pose(ps.pose, (float(x), float(y), float(yaw)))
            out.append(ps)
        path.poses = out
        return path

    def _stop(self) -> None:
        self.cmd_pub.publish(self._twist())

    def _send(self, v: float, w: float) -> None:
        msg = self._twist()
        msg.linear.x = float(v)
        msg.angular.z = float(w)
        self.cmd_pub.publish(msg)

    def _apply(self, step: Step) -> None:
        """Carry out what the state machine asked (move_base's lock not held)."""
        for level, text in step.log:
            (self.log.warn if level == "warn" else self.log.info)("move_base: %s", text)
        if step.cmd is not None:
            self._send(*step.cmd)
        for outcome in step.ended:
            self._end(outcome)
        if step.plan is not None:
            self.plan_pub.publish(self._path_msg(step.plan, self.global_cm.global_frame))
        if step.plan_wanted:
            self.plan_event.set()

    def _end(self, outcome: Outcome) -> None:
        handle = outcome.token
        if outcome.goal is not None and outcome.pose is not None:
            (gx, gy, gyaw), (x, y, yaw) = outcome.goal, outcome.pose
            waits = self.dwa.fresh_waits if outcome.status == states.SUCCEEDED else 0
            self.log.info(
                "move_base: goal (%.2f, %.2f, %.2f) %s at (%.2f, %.2f, %.2f)%s",
                gx, gy, gyaw, outcome.name, x, y, yaw,
                f" ({waits} cycles stopped waiting for a pose newer than the stop)" if waits else "",
            )  # fmt: skip
        if outcome.status == states.SUCCEEDED:
            self.log.info("move_base: %s", outcome.text or "goal reached")
            if handle is not None:
                handle.set_succeeded(None, outcome.text)
        elif outcome.status == states.ABORTED:
            self.log.error("move_base: %s", outcome.text)
            if handle is not None:
                handle.set_aborted(None, outcome.text)
        elif handle is not None:  # PREEMPTED: a cancel, or a newer goal
            handle.set_canceled(None, outcome.text)

    def costmap_loop(self) -> None:
        """Update each costmap at its update_frequency and publish it at its publish_frequency (as
        costmap_2d's map update thread; a frequency of 0 never updates or publishes, as in ROS 1)."""
        cms = (self.global_cm, self.local_cm)
        freqs = [f for cm in cms for f in (cm.update_frequency, cm.publish_frequency) if f > 0]
        period = 1.0 / max(freqs) if freqs else 0.5
        updated = {id(cm): -math.inf for cm in cms}
        published = dict(updated)
        while node_sleep(self.node, period):
            t = self.node.get_time()
            for cm in cms:
                if cm.update_frequency > 0 and t - updated[id(cm)] >= 1.0 / cm.update_frequency - 1e-6:
                    updated[id(cm)] = t
                    self.update_costmap(cm)
                if cm.publish_frequency > 0 and t - published[id(cm)] >= 1.0 / cm.publish_frequency - 1e-6:
                    published[id(cm)] = t
                    with self.lock:
                        cm.publish()

    def control_loop(self) -> None:
        rate = self.node.rate(self.params.controller_frequency)
        while not self.node.is_shutdown:
            try:
                self.cycle()
            except Exception as exc:  # one cycle failing must not kill the controller thread
                self.log.error("move_base: control cycle failed: %s: %s", type(exc).__name__, exc)
            try:
                rate.sleep()
            except ShutdownError:
                return

    def _robot_pose(self, cm: CostmapROS) -> Pose2D | None:
        """The robot's pose in ``cm``'s global frame, or None when unknown or too old (see _pose)."""
        return self._pose(cm)[0]

    def _pose(self, cm: CostmapROS) -> tuple[Pose2D | None, bool, float]:
        """``(pose, too_old, stamp)``: the robot's pose in ``cm``'s global frame and its ROS time;
        None when unknown, or when older than ``cm``'s ``transform_tolerance`` (then ``too_old``,
        warned as costmap_2d does, at most once a second)."""
        now = self.node.get_time()
        pose, stamp = self.tf.robot_pose(cm.global_frame, cm.robot_base_frame, now, cm.transform_tolerance)
        too_old = pose is None and stamp != 0.0
        if too_old:
            self.log.log_throttle(
                1.0,
                WARN,
                "Costmap2DROS transform timeout. Current time: %.4f, global_pose stamp: %.4f, tolerance: %.4f",
                now,
                stamp,
                cm.transform_tolerance,
            )
        return pose, too_old, stamp

    def _robot_poses(self) -> tuple[Pose2D | None, Pose2D | None, bool, float, float]:
        """The robot's pose in the global and in the local costmap's frame, and whether the local
        one was refused as too old. As in ROS 1, only the controller's own (local costmap) pose is
        held to its ``transform_tolerance`` here: dwa_local_planner refuses a stale one, while the
        plan is carried into its frame with the newest ``map -> odom``, however old (amcl's lags
        under load; the planner refuses that one, see _plan_once). The last two items are the local
        and the global pose's ROS times."""
        lp, too_old, stamp = self._pose(self.local_cm)
        if self.local_cm.global_frame == self.global_cm.global_frame:
            return lp, lp, too_old, stamp, stamp
        # the global pose is the local one carried by the newest map -> odom. Looked up at the chain's
        # latest common time instead (map -> base_link at time 0), it was the robot's pose of when
        # amcl last published, which under load is tenths of a second before the local pose: the plan
        # and the goal, carried into the local frame by local * global^-1, then turned with the robot
        # (0.4 rad of goal heading after a turn at 1 rad/s), and move_base stopped short of it.
        found = self.tf.lookup_stamped(self.global_cm.global_frame, self.local_cm.global_frame)
        if found is None or lp is None:
            return None, lp, too_old, stamp, 0.0
        return se2_compose(found[0], lp), lp, too_old, stamp, found[1]

    def cycle(self) -> None:
        """One control cycle: goals from the inbox, then the state machine on the robot's poses."""
        with self.lock:
            steps = self._take_inbox() if self.inbox else []
            idle = self.fsm.goal is None
        for step in steps:
            self._apply(step)
        if idle:
            return
        gpose, lpose, too_old, pose_stamp, global_stamp = self._robot_poses()
        if too_old:
            # too old to drive on (the local costmap's transform_tolerance): stand still, as ROS 1
            with self.lock:
                step = self.fsm.pose_too_old(self.node.get_time())
            self._apply(step)
            return
        if gpose is None or lpose is None:
            self.log.log_throttle(
                5.0,
                WARN,
                "move_base: no robot pose yet (waiting for TF %s -> %s)",
                self.global_cm.global_frame,
                self.global_cm.robot_base_frame,
            )
            # no pose at all is no better than one too old: stand still (the robot kept its last
            # command before, until the base's own timeout stopped it)
            with self.lock:
                step = self.fsm.pose_too_old(self.node.get_time())
            self._apply(step)
            return
        v, w, odom_stamp = self.odom
        # a static chain (stamp 0) or no odometry yet: the goal is judged on the pose as it is
        stamps = (pose_stamp, odom_stamp) if pose_stamp and odom_stamp else None
        with self.lock:
            handle = self.fsm.token
            step = self.fsm.cycle(self.node.get_time(), gpose, lpose, (v, w), stamps, global_stamp or None)
        if step.feedback is not None and handle is not None:
            self._feedback(handle, step.feedback)
        self._apply(step)

    def _feedback(self, handle: Any, gpose: Pose2D) -> None:
        from move_base_msgs.msg import MoveBaseFeedback

        fb = MoveBaseFeedback()
        fb.base_position.header.frame_id = self.global_cm.global_frame
        fb.base_position.header.stamp = self.node.now()
        fill_pose(fb.base_position.pose, gpose)
        handle.publish_feedback(fb)

    def planner_loop(self) -> None:
        """The global planner's own thread (as in ROS 1): the control loop keeps its rate meanwhile."""
        while not self.node.is_shutdown:
            if not self.plan_event.wait(0.5):
                continue
            self.plan_event.clear()
            try:
                self._plan_once()
            except Exception as exc:  # the planner thread must survive anything one plan does
                self.log.error("move_base: planning failed: %s: %s", type(exc).__name__, exc)
                with self.lock:
                    self.fsm.planner_busy = False

    def _plan_once(self) -> None:
        gpose = self._robot_pose(self.global_cm)
        if gpose is None:
            return
        now = self.node.get_time()
        with self.lock:
            job = self.fsm.take_plan_job(now)
        if job is None:
            return
        goal, seq = job
        try:
            plan, error = self._make_plan(gpose, goal), ""
        except PlanError as exc:
            plan, error = None, str(exc)
        with self.lock:
            step = self.fsm.plan_done(seq, now, plan, error)
        self._apply(step)

    def _clear_outside(self, gpose: Pose2D, lpose: Pose2D, size: float) -> None:
        """Forget obstacle marks outside a ``size`` x ``size`` square around the robot (0: all), in both
        costmaps, as clear_costmap_recovery does."""
        for cm, pose in ((self.global_cm, gpose), (self.local_cm, lpose)):
            c = cm.costmap
            if c.size_x == 0:
                continue
            if size <= 0:
                c.clear_obstacles()
                continue
            xs = c.origin_x + (np.arange(c.size_x) + 0.5) * c.resolution
            ys = c.origin_y + (np.arange(c.size_y) + 0.5) * c.resolution
            far = (np.abs(xs[None, :] - pose[0]) > size / 2) | (np.abs(ys[:, None] - pose[1]) > size / 2)
            c.obstacles[far] = 0


def main(argv: list[str] | None = None) -> int:
    return run_core_node("move_base", argv, MoveBase)
