"""joint_state_controller/JointStateController and diff_drive_controller/DiffDriveController.

Each controller is built from its parameters (the dict under ``<ns>/<name>`` on the parameter
server), publishes and subscribes under the names ROS 1's do, and is updated by the controller
manager once per simulation step. A parameter that is missing or unusable is a ControllerError whose
text is the line ROS 1's controller logs.
"""

from __future__ import annotations

import math
import threading
from typing import Any

from ninjemys.errors import NinjemysError
from ninjemys.idl.loader import get_message_class
from ninjemys.sim.ros_control.hardware import JOINT_STATE_INTERFACE, VELOCITY_INTERFACE, SimRobotHW
from ninjemys.sim.ros_control.limits import SpeedLimiter
from ninjemys.sim.ros_control.odometry import Odometry


class ControllerError(NinjemysError):
    """A controller that cannot be initialised: the reason, as the ROS 1 controller logs it."""


def _join(ns: str, name: str) -> str:
    return f"{ns.rstrip('/')}/{name}"


def _number(params: dict, key: str, default: float, where: str) -> float:
    value = params.get(key, default)
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise ControllerError(f"{where}: parameter '{key}' must be a number, got {value!r}")
    return float(value)


def _flag(params: dict, key: str, default: bool, where: str) -> bool:
    value = params.get(key, default)
    if not isinstance(value, bool):
        raise ControllerError(f"{where}: parameter '{key}' must be a bool, got {value!r}")
    return value


class Controller:
    """What the manager needs of a controller: claims, start, update, stop, close."""

    type_name = ""
    interface = JOINT_STATE_INTERFACE

    def __init__(self, name: str, node: Any, hw: SimRobotHW, root_ns: str, params: dict) -> None:
        self.name, self.node, self.hw, self.root_ns = name, node, hw, root_ns
        self.ns = _join(root_ns, name)

    @property
    def claimed(self) -> list[str]:
        return []

    def starting(self, now: float) -> None:
        """Called in the control loop just before the first update."""

    def update(self, now: float, period: float) -> None:
        """One control step."""

    def stopping(self, now: float) -> None:
        """Called in the control loop after the last update."""

    def close(self) -> None:
        """Release publishers and subscribers (the controller is unloaded)."""


class JointStateController(Controller):
    """Publishes every joint's position, velocity and effort on ``<ns>/joint_states`` at ``publish_rate``."""

    type_name = "joint_state_controller/JointStateController"

    def __init__(self, name: str, node: Any, hw: SimRobotHW, root_ns: str, params: dict) -> None:
        super().__init__(name, node, hw, root_ns, params)
        if "publish_rate" not in params:
            raise ControllerError("Parameter 'publish_rate' not set")
        self.period = 1.0 / _number(params, "publish_rate", 50.0, self.ns) if params["publish_rate"] else 0.0
        extra = params.get("extra_joints", [])
        self.extra: list[tuple[str, float, float, float]] = []
        for item in extra if isinstance(extra, list) else []:
            if isinstance(item, dict) and isinstance(item.get("name"), str):
                self.extra.append(
                    (
                        item["name"],
                        float(item.get("position", 0.0)),
                        float(item.get("velocity", 0.0)),
                        float(item.get("effort", 0.0)),
                    )
                )
        self._msg: Any = get_message_class("sensor_msgs/JointState")
        self.pub = node.publisher(_join(root_ns, "joint_states"), self._msg, queue_size=4)
        self.last: float | None = None

    def starting(self, now: float) -> None:
        self.last = now

    def update(self, now: float, period: float) -> None:
        if self.last is not None and self.period and now < self.last + self.period:
            return
        self.last = now if self.last is None else self.last + self.period
        if self.period and now - self.last > self.period:
            self.last = now  # fell behind: do not burst
        msg = self._msg()
        msg.header.stamp = _stamp(now)
        joints = list(self.hw.joints.values())
        msg.name = [j.name for j in joints] + [e[0] for e in self.extra]
        msg.position = [j.position for j in joints] + [e[1] for e in self.extra]
        msg.velocity = [j.velocity for j in joints] + [e[2] for e in self.extra]
        msg.effort = [j.effort for j in joints] + [e[3] for e in self.extra]
        self.pub.publish(msg)

    def close(self) -> None:
        self.pub.unregister()


def _stamp(now: float) -> Any:
    from ninjemys import rostime

    return rostime.Time.from_sec(now)


def _limiter(params: dict, axis: str, where: str) -> SpeedLimiter:
    node = params
    for part in axis.split("/"):
        node = node.get(part, {}) if isinstance(node, dict) else {}
    p = node if isinstance(node, dict) else {}
    w = f"{where}/{axis}"
    lim = SpeedLimiter(
        has_velocity_limits=_flag(p, "has_velocity_limits", False, w),
        has_acceleration_limits=_flag(p, "has_acceleration_limits", False, w),
        has_jerk_limits=_flag(p, "has_jerk_limits", False, w),
    )
    lim.max_velocity = _number(p, "max_velocity", 0.0, w)
    lim.min_velocity = _number(p, "min_velocity", -lim.max_velocity, w)
    lim.max_acceleration = _number(p, "max_acceleration", 0.0, w)
    lim.min_acceleration = _number(p, "min_acceleration", -lim.max_acceleration, w)
    lim.max_jerk = _number(p, "max_jerk", 0.0, w)
    lim.min_jerk = _number(p, "min_jerk", -lim.max_jerk, w)
    return lim


def _wheels(params: dict, key: str, where: str) -> list[str]:
    value = params.get(key)
    if isinstance(value, str) and value:
        return [value]
    if isinstance(value, list) and value and all(isinstance(v, str) and v for v in value):
        return list(value)
    if value is None:
        raise ControllerError(f"Couldn't retrieve {key.split('_')[0]} wheel name from param server.")
    raise ControllerError(f"{where}: {key} must be a joint name or a list of joint names, got {value!r}")


def _covariance(params: dict, key: str, where: str) -> list[float] | None:
    value = params.get(key)
    if value is None:
        return None
    if not isinstance(value, list) or len(value) != 6 or not all(isinstance(v, int | float) for v in value):
        raise ControllerError(f"{where}: {key} must be a list of 6 numbers, got {value!r}")
    return [float(v) for v in value]


class DiffDriveController(Controller):
    """``<ns>/<name>/cmd_vel`` (Twist) in, wheel velocities out; ``<ns>/<name>/odom`` and /tf from the wheels."""

    type_name = "diff_drive_controller/DiffDriveController"
    interface = VELOCITY_INTERFACE

    def __init__(self, name: str, node: Any, hw: SimRobotHW, root_ns: str, params: dict) -> None:
        super().__init__(name, node, hw, root_ns, params)
        w = self.ns
        self.left = _wheels(params, "left_wheel", w)
        self.right = _wheels(params, "right_wheel", w)
        if len(self.left) != len(self.right):
            raise ControllerError(f"#left wheels ({len(self.left)}) != #right wheels ({len(self.right)}).")
        for joint in self.left + self.right:
            if joint not in hw.joints:
                raise ControllerError(
                    f"Could not find joint '{joint}' in 'hardware_interface::VelocityJointInterface'."
                )
        self.publish_period = 1.0 / _number(params, "publish_rate", 50.0, w)
        self.open_loop = _flag(params, "open_loop", False, w)
        sep = _number(params, "wheel_separation", hw.wheel_separation, w)
        radius = _number(params, "wheel_radius", hw.wheel_radius, w)
        sep *= _number(params, "wheel_separation_multiplier", 1.0, w)
        common = _number(params, "wheel_radius_multiplier", 1.0, w)
        self.left_radius = radius * _number(params, "left_wheel_radius_multiplier", common, w)
        self.right_radius = radius * _number(params, "right_wheel_radius_multiplier", common, w)
        if sep <= 0 or self.left_radius <= 0 or self.right_radius <= 0:
            raise ControllerError(f"{w}: wheel_separation and wheel_radius must be > 0")
        self.separation = sep
        window = int(_number(params, "velocity_rolling_window_size", 10, w))
        self.odometry = Odometry(sep, self.left_radius, self.right_radius, max(window, 1))
        self.cmd_vel_timeout = _number(params, "cmd_vel_timeout", 0.5, w)
        self.base_frame = str(params.get("base_frame_id", "base_link"))
        self.odom_frame = str(params.get("odom_frame_id", "odom"))
        self.enable_odom_tf = _flag(params, "enable_odom_tf", True, w)
        self.pose_cov = _covariance(params, "pose_covariance_diagonal", w) or [0.0] * 6
        self.twist_cov = _covariance(params, "twist_covariance_diagonal", w) or [0.0] * 6
        self.linear_limiter = _limiter(params, "linear/x", w)
        self.angular_limiter = _limiter(params, "angular/z", w)
        self._twist: Any = get_message_class("geometry_msgs/Twist")
        self._odom_msg: Any = get_message_class("nav_msgs/Odometry")
        self._tf_msg: Any = get_message_class("tf2_msgs/TFMessage")
        self._tf_stamped: Any = get_message_class("geometry_msgs/TransformStamped")
        self._lock = threading.Lock()
        self._cmd: tuple[float, float, float | None] = (0.0, 0.0, None)  # linear, angular, stamp
        self._last = [(0.0, 0.0), (0.0, 0.0)]  # the last two limited commands (linear, angular)
        self.last_publish: float | None = None
        self.odom_pub = node.publisher(_join(self.ns, "odom"), self._odom_msg, queue_size=100)
        self.tf_pub = node.publisher("/tf", self._tf_msg, queue_size=100) if self.enable_odom_tf else None
        self.sub = node.subscriber(_join(self.ns, "cmd_vel"), self._twist, self._on_cmd, queue_size=1)
        # publish_cmd: the limited command, as TwistStamped on <name>/cmd_vel_out
        self._twist_stamped: Any = get_message_class("geometry_msgs/TwistStamped")
        self.cmd_pub = (
            node.publisher(_join(self.ns, "cmd_vel_out"), self._twist_stamped, queue_size=100)
            if _flag(params, "publish_cmd", False, w)
            else None
        )
        for unsupported in ("publish_wheel_joint_controller_state",):
            if params.get(unsupported):
                node.log.warn(f"{w}: parameter '{unsupported}' is not supported here and is ignored")
        self.now = 0.0

    @property
    def claimed(self) -> list[str]:
        return self.left + self.right

    def _on_cmd(self, msg: Any) -> None:
        if not all(math.isfinite(v) for v in (msg.linear.x, msg.angular.z)):
            self.node.log.warn("Received NaN in velocity command. Ignoring.")
            return
        with self._lock:
            self._cmd = (msg.linear.x, msg.angular.z, self.now)

    def starting(self, now: float) -> None:
        self.now = now
        self._brake()
        with self._lock:
            self._cmd = (0.0, 0.0, now)
        self.odometry.reset(now)
        self.last_publish = now

    def stopping(self, now: float) -> None:
        self._brake()

    def _brake(self) -> None:
        for j in self.left + self.right:
            self.hw.joints[j].command = 0.0

    def update(self, now: float, period: float) -> None:
        self.now = now
        joints = self.hw.joints
        if self.open_loop:
            self.odometry.update_open_loop(self._last[0][0], self._last[0][1], now)
        else:
            lp = sum(joints[j].position for j in self.left) / len(self.left)
            rp = sum(joints[j].position for j in self.right) / len(self.right)
            if math.isfinite(lp) and math.isfinite(rp):
                self.odometry.update(lp, rp, now)
        if self.last_publish is None or now >= self.last_publish + self.publish_period:
            self.last_publish = now
            self._publish(now)
        with self._lock:
            lin, ang, stamp = self._cmd
        if stamp is None or now - stamp > self.cmd_vel_timeout:
            lin = ang = 0.0
        (l0, a0), (l1, a1) = self._last
        lin = self.linear_limiter.limit(lin, l0, l1, period)
        ang = self.angular_limiter.limit(ang, a0, a1, period)
        self._last = [(lin, ang), (l0, a0)]
        if self.cmd_pub is not None:
            out = self._twist_stamped()
            out.header.stamp = _stamp(now)
            out.twist.linear.x, out.twist.angular.z = lin, ang
            self.cmd_pub.publish(out)
        left = (lin - ang * self.separation / 2.0) / self.left_radius
        right = (lin + ang * self.separation / 2.0) / self.right_radius
        for j in self.left:
            joints[j].command = left
        for j in self.right:
            joints[j].command = right

    def _publish(self, now: float) -> None:
        o = self.odometry
        half = o.heading / 2.0
        qz, qw = math.sin(half), math.cos(half)
        msg = self._odom_msg()
        msg.header.stamp = _stamp(now)
        msg.header.frame_id = self.odom_frame
        msg.child_frame_id = self.base_frame
        msg.pose.pose.position.x, msg.pose.pose.position.y = o.x, o.y
        msg.pose.pose.orientation.z, msg.pose.pose.orientation.w = qz, qw
        msg.twist.twist.linear.x = o.linear
        msg.twist.twist.angular.z = o.angular
        pose_cov = [0.0] * 36
        twist_cov = [0.0] * 36
        for i in range(6):
            pose_cov[i * 7] = self.pose_cov[i]
            twist_cov[i * 7] = self.twist_cov[i]
        msg.pose.covariance = pose_cov
        msg.twist.covariance = twist_cov
        self.odom_pub.publish(msg)
        if self.tf_pub is not None:
            t = self._tf_stamped()
            t.header.stamp = msg.header.stamp
            t.header.frame_id = self.odom_frame
            t.child_frame_id = self.base_frame
            t.transform.translation.x, t.transform.translation.y = o.x, o.y
            t.transform.rotation.z, t.transform.rotation.w = qz, qw
            self.tf_pub.publish(self._tf_msg(transforms=[t]))

    def close(self) -> None:
        self.sub.unregister()
        if self.cmd_pub is not None:
            self.cmd_pub.unregister()
        self.odom_pub.unregister()
        if self.tf_pub is not None:
            self.tf_pub.unregister()


CONTROLLER_TYPES: dict[str, type[Controller]] = {
    JointStateController.type_name: JointStateController,
    DiffDriveController.type_name: DiffDriveController,
}
