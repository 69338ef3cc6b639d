"""``rosrun puzzlebot_safety safety_monitor``: the one node between every command source and the robot.

Inputs are twist_mux-style (``~topics``: a list of ``{name, topic, timeout, priority}``; by default
``teleop`` on ``teleop/cmd_vel`` with priority 100 and ``navigation`` on ``nav/cmd_vel`` with
priority 10, both with a 0.5 s timeout), and so are ``~locks`` (std_msgs/Bool topics that mask the
inputs below their priority while true or silent past their timeout). Every ``1 / ~rate`` seconds
the fresh, unmasked input of highest priority goes out on ``cmd_vel``, after these guards:

- watchdog: an input older than its timeout does not count; with none left the robot is stopped
  (zero twists for one second, then silence; the stop is logged once with the last command's age);
- stop zone: the linear velocity is cut to zero when driving the commanded arc for ``~reaction_time``
  and then braking (``~max_decel``) would bring the footprint (``~robot_radius`` or ``~footprint``)
  within ``~safety_margin`` (+ ``~obstacle_speed`` x that time, for people walking in) of a point of
  the latest ``scan`` it is not already moving away from; turning in place stays allowed;
- scan watchdog: once a scan has come, a latest scan older than ``~scan_timeout`` (1 s; 0: off) no
  longer shows the way ahead, so linear motion is cut until scans come again (turning stays allowed);
- localization: when ``amcl_pose``'s position variance (xx + yy) exceeds ``~max_position_covariance``
  (or is not a number), inputs named in ``~localization_inputs`` (default ``[navigation]``) may only
  turn in place until an ``amcl_pose`` within the limit comes: their linear velocity is cut to zero and
  their angular velocity passes (a turn in place sweeps nothing new, and it is how move_base's
  rotate recovery gives amcl the new views it needs to find itself again; stopping turns as well
  would deadlock that recovery). They still win over lower priorities, as in twist_mux;
- e-stop: ``e_stop`` (std_msgs/Bool, true) or the ``~e_stop`` service (std_srvs/SetBool, true) latches
  a stop of everything until ``~e_stop`` is called with false (or ``~reset_e_stop``, std_srvs/Trigger);
  the state is latched on ``~e_stop_active``.

Status goes out as diagnostic_msgs/DiagnosticArray on ``/diagnostics`` every ``~diagnostic_period``
seconds (1), laid out as diagnostic_updater does: one status named ``<node name>: Safety`` with a
level, a message, ``~hardware_id`` (``puzzlebot``) and key/values.
"""

from __future__ import annotations

import math
import threading
from typing import Any

import numpy as np
import yaml

from ninjemys.errors import ShutdownError
from ninjemys.nav.costmap import footprint_radii, parse_footprint
from ninjemys.nav.rosglue import Tf2D, node_sleep, param, run_core_node, scan_arrays
from ninjemys.nav.safety import (
    NEVER,
    MuxInput,
    MuxLock,
    StopZone,
    TwistMux,
    blocked_arcs,
    judged_speed,
    scan_points,
)
from ninjemys.node.log import ERROR, WARN
from ninjemys.node.timers import TimeMovedBackwardsError

DEFAULT_TOPICS = [
    {"name": "teleop", "topic": "teleop/cmd_vel", "timeout": 0.5, "priority": 100},
    {"name": "navigation", "topic": "nav/cmd_vel", "timeout": 0.5, "priority": 10},
]


def _parse_handles(value: Any, param: str, cls: type[Any]) -> tuple[list[Any], list[str]]:
    """twist_mux's ``topics``/``locks`` layout (a list of ``{name, topic, timeout, priority}``, or a
    dict keyed by name) -> handles of ``cls``, and one error line per bad entry. Priorities are
    clamped to 0..255 and a missing timeout is 0.5 s for topics, none for locks."""
    if value is None:
        return [], []
    if not isinstance(value, (list, dict)):
        return [], [
            f"~{param}: expected a list of mappings with name, topic, timeout, priority, got {value!r}"
        ]
    items = list(value.items()) if isinstance(value, dict) else list(enumerate(value))
    handles, errors = [], []
    for key, entry in items:
        if not isinstance(entry, dict):
            errors.append(f"~{param}[{key}]: expected a mapping with name, topic, timeout, priority")
            continue
        if "topic" not in entry:
            errors.append(f"~{param}[{key}]: missing 'topic'")
            continue
        try:
            priority = min(255, max(0, int(entry.get("priority", 0))))
            timeout = float(entry.get("timeout", 0.5 if cls is MuxInput else 0.0))
        except (TypeError, ValueError) as exc:
            errors.append(f"~{param}[{key}]: {exc}")
            continue
        handles.append(cls(str(entry.get("name", key)), str(entry["topic"]), priority, timeout))
    return handles, errors


def _float_param(node: Any, name: str, default: float) -> float:
    """A float parameter by full or ``~`` name, as :func:`~ninjemys.nav.rosglue.param` reads one."""
    value = node.get_param(name, default)
    try:
        return float(value)
    except (TypeError, ValueError):
        node.log.error(
            "%s: parameter %s: expected a float, got %r; using %r",
            node.name,
            node.resolve_name(name),
            value,
            default,
        )
        return default


def read_stop_zone(node: Any, prefix: str) -> StopZone:
    """The stop zone from the parameters under ``prefix`` (``~`` for the monitor itself, the monitor's
    namespace for move_base's planner, so the two read one set): ``robot_radius`` or the circumscribed
    radius of ``footprint``, ``safety_margin``, ``max_decel``, ``reaction_time``, ``obstacle_speed``."""
    radius = _float_param(node, prefix + "robot_radius", 0.12)
    fp = node.get_param(prefix + "footprint", None)
    if fp:
        try:
            radius = footprint_radii(parse_footprint(fp), radius)[1]
        except (ValueError, TypeError, yaml.YAMLError) as exc:
            reason = " ".join(str(exc).split())  # a YAML error spans lines: one line here
            node.log.error(
                "%s: %sfootprint: %s; using robot_radius %.3f", node.name.lstrip("/"), prefix, reason, radius
            )
    return StopZone(
        radius=radius,
        margin=_float_param(node, prefix + "safety_margin", 0.05),
        max_decel=_float_param(node, prefix + "max_decel", 1.0),
        reaction_time=_float_param(node, prefix + "reaction_time", 0.15),
        obstacle_speed=_float_param(node, prefix + "obstacle_speed", 0.0),
    )


def parse_topics(value: Any) -> tuple[list[MuxInput], list[str]]:
    """twist_mux's ``topics`` parameter -> inputs, and error lines."""
    return _parse_handles(value, "topics", MuxInput)


def parse_locks(value: Any) -> tuple[list[MuxLock], list[str]]:
    """twist_mux's ``locks`` parameter -> locks, and error lines."""
    return _parse_handles(value, "locks", MuxLock)


class SafetyMonitor:
    def __init__(self, node: Any) -> None:
        from diagnostic_msgs.msg import DiagnosticArray
        from geometry_msgs.msg import PoseWithCovarianceStamped, Twist
        from nav_msgs.msg import Odometry
        from sensor_msgs.msg import LaserScan
        from std_msgs.msg import Bool
        from std_srvs.srv import SetBool, Trigger

        self.node = node
        self.lock = threading.Lock()
        self.out_lock = threading.Lock()  # one twist decided and published at a time
        inputs, errors = parse_topics(node.get_param("~topics", DEFAULT_TOPICS))
        locks, lock_errors = parse_locks(node.get_param("~locks", []))
        for line in errors + lock_errors:
            self.node.log.error("safety_monitor: %s", line)
        self.mux = TwistMux(inputs or parse_topics(DEFAULT_TOPICS)[0], locks)
        for inp in self.mux.inputs:
            if inp.timeout <= 0.0:
                self.node.log.warn(
                    "safety_monitor: input %s (%s) has no timeout: its last command holds until "
                    "another input takes over",
                    inp.name,
                    node.resolve_name(inp.topic),
                )
        self.zone = read_stop_zone(node, "~")
        self.scan_timeout = param(node, "scan_timeout", 1.0)
        self.max_cov = param(node, "max_position_covariance", 0.5)
        self.loc_inputs = self._input_names(node.get_param("~localization_inputs", ["navigation"]))
        self.rate = max(1.0, param(node, "rate", 20.0))
        self.base_frame = param(node, "base_frame", "base_link")
        self.diag_period = param(node, "diagnostic_period", 1.0)
        self.hardware_id = param(node, "hardware_id", "puzzlebot")
        # diagnostic_updater names a status "<node name without the leading slash>: <task>"
        self.diag_name = f"{node.name.lstrip('/')}: Safety"
        self.tf = Tf2D(node)
        self.points = np.zeros((0, 2))
        self.scan_time: float | None = None
        self.velocity = 0.0
        self.cov: float | None = None
        self.scan_stale = False
        self.e_stop = False
        self.blocked = False
        self.active: str | None = None
        self.stale_since: float | None = None
        self.last_now = NEVER
        self.bad_scan_reported = False
        self._twist, self._diag_cls = Twist, DiagnosticArray
        self.cmd_pub = node.publisher("cmd_vel", Twist, queue_size=1)
        self.diag_pub = node.publisher("/diagnostics", DiagnosticArray, queue_size=1)
        self.estop_pub = node.publisher("~e_stop_active", Bool, queue_size=1, latch=True)
        self.estop_pub.publish(Bool(data=False))
        for inp in self.mux.inputs:
            node.subscriber(inp.topic, Twist, self.on_cmd, callback_args=inp, queue_size=1)
        for lock in self.mux.locks:
            node.subscriber(lock.topic, Bool, self.on_lock, callback_args=lock, queue_size=1)
        node.subscriber("scan", LaserScan, self.on_scan, queue_size=1)
        node.subscriber("odom", Odometry, self.on_odom, queue_size=1)
        node.subscriber("amcl_pose", PoseWithCovarianceStamped, self.on_pose, queue_size=1)
        node.subscriber("e_stop", Bool, self.on_e_stop_topic, queue_size=10)
        node.service("~e_stop", SetBool, self.on_e_stop_service)
        node.service("~reset_e_stop", Trigger, self.on_reset)
        threading.Thread(target=self.loop, name="safety-loop", daemon=True).start()
        threading.Thread(target=self.diag_loop, name="safety-diagnostics", daemon=True).start()

    def _input_names(self, value: Any) -> set[str]:
        """``~localization_inputs``: a list of input names (one name alone is taken as a list of one);
        names that are no input are reported, as they would never be stopped."""
        if isinstance(value, str):
            value = [value]
        if not isinstance(value, list):
            self.node.log.error(
                "safety_monitor: ~localization_inputs: expected a list of input names, got %r; using [navigation]",
                value,
            )
            value = ["navigation"]
        names = {str(name) for name in value}
        known = {inp.name for inp in self.mux.inputs}
        for name in sorted(names - known):
            self.node.log.error(
                "safety_monitor: ~localization_inputs: %s is not one of the inputs (%s)",
                name,
                ", ".join(sorted(known)),
            )
        return names

    # -- inputs -------------------------------------------------------------------------------------

    def on_cmd(self, msg: Any, inp: MuxInput) -> None:
        v, w = float(msg.linear.x), float(msg.angular.z)
        if not (math.isfinite(v) and math.isfinite(w)):
            self.node.log.log_throttle(
                5.0, WARN, "safety_monitor: %s: NaN/inf velocity ignored", self.node.resolve_name(inp.topic)
            )
            return
        with self.lock:
            inp.v, inp.w, inp.last_time = v, w, self.node.get_time()

    def on_lock(self, msg: Any, lock: MuxLock) -> None:
        with self.lock:
            lock.data, lock.last_time = bool(msg.data), self.node.get_time()

    def on_scan(self, scan: Any) -> None:
        ranges, angles = scan_arrays(scan)
        # REP 117: -inf is "closer than range_min": something is right at the robot (scan_points)
        bad = ~np.isfinite(np.where(np.isneginf(ranges), scan.range_min, ranges))
        if not self.bad_scan_reported and bad.any():
            self.bad_scan_reported = True
            self.node.log.warn(
                "safety_monitor: scan from %s has NaN/inf ranges (%d of %d); they are treated as no return",
                scan.header.frame_id,
                int(bad.sum()),
                len(ranges),
            )
        laser = self.tf.lookup(self.base_frame, scan.header.frame_id or self.base_frame, 0.0) or (
            0.0,
            0.0,
            0.0,
        )
        pts = scan_points(ranges, angles, scan.range_min, scan.range_max, laser)
        with self.lock:
            self.points = pts
            self.scan_time = self.node.get_time()

    def on_odom(self, msg: Any) -> None:
        self.velocity = float(msg.twist.twist.linear.x)

    def on_pose(self, msg: Any) -> None:
        c = msg.pose.covariance
        self.cov = float(c[0]) + float(c[7])
        if math.isnan(self.cov):
            self.node.log.log_throttle(
                5.0, WARN, "safety_monitor: amcl_pose: NaN position covariance; treated as localization lost"
            )

    def localization_lost(self) -> bool:
        """A variance over the limit, or NaN (which compares false with everything), is lost."""
        return self.cov is not None and not self.cov <= self.max_cov

    def _set_e_stop(self, on: bool, why: str) -> None:
        from std_msgs.msg import Bool

        with self.out_lock:  # no twist decided before the e-stop goes out after its stop
            with self.lock:
                changed = self.e_stop != on
                self.e_stop = on
            if changed:
                self.estop_pub.publish(Bool(data=on))
                if on:
                    self.cmd_pub.publish(self._twist())
        if changed:
            (self.node.log.warn if on else self.node.log.info)(
                "safety_monitor: e-stop %s (%s)", "ENGAGED" if on else "reset", why
            )

    def on_e_stop_topic(self, msg: Any) -> None:
        if msg.data:
            self._set_e_stop(True, "e_stop topic")

    def on_e_stop_service(self, req: Any) -> Any:
        from std_srvs.srv import SetBoolResponse

        self._set_e_stop(bool(req.data), "~e_stop service")
        return SetBoolResponse(success=True, message="e-stop engaged" if req.data else "e-stop reset")

    def on_reset(self, _req: Any) -> Any:
        from std_srvs.srv import TriggerResponse

        self._set_e_stop(False, "~reset_e_stop service")
        return TriggerResponse(success=True, message="e-stop reset")

    # -- output -------------------------------------------------------------------------------------

    def decide(self, now: float) -> tuple[float, float, bool]:
        """(v, w, publish?) for this cycle."""
        with self.lock:
            if now < self.last_now:
                self._time_moved_backwards(now)
            self.last_now = now
            self.blocked = False
            if self.e_stop:
                self.active = "e_stop"
                return 0.0, 0.0, True
            self._check_scan_age(now)
            inp = self.mux.select(now)
            if inp is None:
                self.active = None
                if self.stale_since is None:
                    self.stale_since = now
                    self._report_timeout(now)
                return 0.0, 0.0, now - self.stale_since <= 1.0
            self.stale_since = None
            self.active = inp.name
            v, w = inp.v, inp.w
            # lost: an input that needs localization may still turn in place (the footprint sweeps
            # nothing new, and amcl needs the rotate recovery's new views to find itself again)
            if inp.name in self.loc_inputs and self.localization_lost():
                v = 0.0
            self.blocked = v != 0.0 and bool(
                blocked_arcs(
                    self.points, judged_speed(v, self.velocity).reshape(1), np.array([w]), self.zone
                )[0]
            )
            if self.blocked or self.scan_stale:
                v = 0.0
            return v, w, True

    def _report_timeout(self, now: float) -> None:
        """Say once why the robot stops when every input went silent, with the newest command's age on
        this node's clock (the watchdog's own measure, as the scan watchdog's line: a command that
        reached a loaded node late is timed from its arrival, as in twist_mux). A stop by a lock, or
        before any command came, is not the watchdog's and says nothing."""
        heard = [inp for inp in self.mux.inputs if inp.last_time != NEVER]
        if not heard or any(inp.fresh(now) for inp in heard):
            return
        last = max(heard, key=lambda inp: inp.last_time)
        self.node.log.info(
            "safety_monitor: no fresh command: %s (%s) last came %.3f s ago (timeout %.2f s); stopping",
            last.name,
            self.node.resolve_name(last.topic),
            now - last.last_time,
            last.timeout,
        )

    def _time_moved_backwards(self, now: float) -> None:
        """A simulation reset or a looping bag: every age measured before is meaningless now, and a
        command stamped in the old future would otherwise stay fresh until time caught up with it."""
        self.node.log.info(
            "safety_monitor: ROS time moved backwards (%.3f -> %.3f); inputs and scan forgotten",
            self.last_now,
            now,
        )
        handles: list[Any] = [*self.mux.inputs, *self.mux.locks]  # inputs and locks: both keep last_time
        for handle in handles:
            handle.last_time = NEVER
        self.scan_time = None
        self.stale_since = None

    def _check_scan_age(self, now: float) -> None:
        """Update ``scan_stale`` (no scan yet is not stale: a robot may run without a laser)."""
        stale = (
            self.scan_timeout > 0.0
            and self.scan_time is not None
            and now - self.scan_time > self.scan_timeout
        )
        if stale != self.scan_stale:
            if stale:
                self.node.log.warn(
                    "safety_monitor: no scan on %s for %.2f s (~scan_timeout %.2f); linear motion stopped",
                    self.node.resolve_name("scan"),
                    now - (self.scan_time or 0.0),
                    self.scan_timeout,
                )
            else:
                self.node.log.info("safety_monitor: scans again on %s", self.node.resolve_name("scan"))
        self.scan_stale = stale

    def loop(self) -> None:
        rate = self.node.rate(self.rate)
        while not self.node.is_shutdown:
            with self.out_lock:
                try:
                    v, w, publish = self.decide(self.node.get_time())
                except Exception as exc:  # the guard must keep guarding: stop and report
                    self.node.log.log_throttle(
                        5.0, ERROR, "safety_monitor: %s: %s; stopping the robot", type(exc).__name__, exc
                    )
                    v, w, publish = 0.0, 0.0, True
                if publish:
                    msg = self._twist()
                    msg.linear.x, msg.angular.z = v, w
                    self.cmd_pub.publish(msg)
            try:
                rate.sleep()
            except TimeMovedBackwardsError:
                continue
            except ShutdownError:
                return

    def diag_loop(self) -> None:
        from diagnostic_msgs.msg import DiagnosticStatus, KeyValue

        while node_sleep(self.node, self.diag_period):  # goes on across a simulation reset
            now = self.node.get_time()
            with self.lock:
                e_stop, active, is_blocked, cov = self.e_stop, self.active, self.blocked, self.cov
                lost, scan_stale = self.localization_lost(), self.scan_stale
                floor = self.mux.lock_priority(now)
                # twist_mux's own keys: each input masked or not, each lock locked or free
                mux_values = [
                    (
                        f"velocity {inp.name}",
                        f"{'masked' if self.mux.masked(inp, now) else 'unmasked'} (listening to "
                        f"{self.node.resolve_name(inp.topic)} @ {inp.timeout:f}s with priority #{inp.priority})",
                    )
                    for inp in self.mux.inputs
                ] + [
                    (
                        f"lock {lock.name}",
                        f"{'locked' if lock.locked(now) else 'free'} (listening to "
                        f"{self.node.resolve_name(lock.topic)} @ {lock.timeout:f}s with priority #{lock.priority})",
                    )
                    for lock in self.mux.locks
                ]
            status = DiagnosticStatus(name=self.diag_name, hardware_id=self.hardware_id)
            if e_stop:
                status.level, status.message = DiagnosticStatus.ERROR, "E-stop engaged"
            elif scan_stale:
                status.level, status.message = DiagnosticStatus.WARN, "Scan stale: linear motion stopped"
            elif is_blocked:
                status.level, status.message = DiagnosticStatus.WARN, "Obstacle in the stop zone"
            elif lost:
                status.level, status.message = (
                    DiagnosticStatus.WARN,
                    "Localization lost: navigation may only turn in place",
                )
            elif active is None and floor > 0:
                status.level, status.message = DiagnosticStatus.OK, f"Locked below priority {floor}"
            elif active is None:
                status.level, status.message = DiagnosticStatus.OK, "Idle (no fresh command)"
            else:
                status.level, status.message = DiagnosticStatus.OK, f"Passing {active}"
            status.values = [
                KeyValue(key="active_input", value=str(active)),
                KeyValue(key="e_stop", value=str(e_stop)),
                KeyValue(key="stop_zone_blocked", value=str(is_blocked)),
                KeyValue(key="scan_stale", value=str(scan_stale)),
                KeyValue(key="position_covariance", value="unknown" if cov is None else f"{cov:.4f}"),
                *(KeyValue(key=key, value=value) for key, value in mux_values),
                KeyValue(key="current priority", value=str(floor)),
            ]
            arr = self._diag_cls(status=[status])
            arr.header.stamp = self.node.now()
            self.diag_pub.publish(arr)


def main(argv: list[str] | None = None) -> int:
    return run_core_node("safety_monitor", argv, SafetyMonitor)
