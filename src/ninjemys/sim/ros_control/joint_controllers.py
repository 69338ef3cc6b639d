"""One-joint controllers: ``effort_controllers/JointVelocityController`` and
``velocity_controllers/JointVelocityController`` for wheels, ``effort_controllers/JointPositionController``
and ``position_controllers/JointPositionController`` for an arm's joints (RRBot in gazebo_ros_demos).

The maker's Gazebo PuzzleBot (puzzlebot_control's ``puzzlebot_diff_control.yaml``) drives each
wheel with an effort_controllers/JointVelocityController: a wheel speed in rad/s on
``<name>/command`` (std_msgs/Float64), the wheel's state on ``<name>/state``
(control_msgs/JointControllerState), read back by the course's ``puzzlebot_control_node``.

In Gazebo a PID turns the speed error into a motor effort and the wheel follows; the simulator's
wheels are velocity-driven (they reach the commanded speed at the model's wheel acceleration), so
the command is the wheel's target speed, and the PID is computed from the gains only for what the
state message reports (``command``: the effort it would ask for). The state is published every 10
updates of a 1 kHz Gazebo loop (100 Hz): here at 100 Hz of simulated time.

velocity_controllers/JointVelocityController forwards ``<name>/command`` to the joint as is.

The simulator has no link dynamics for an arm: a position-controlled joint is moved kinematically.
effort_controllers/JointPositionController's joint closes the position error with a time constant of
:data:`POSITION_TIME_CONSTANT` (a well-damped PID in Gazebo settles in a few tenths of a second), at most
at the joint's URDF velocity limit; position_controllers/JointPositionController's joint is set to the
command at the next step, as Gazebo's position interface sets it. Every command reaching the simulator
is a joint velocity in rad/s.
"""

from __future__ import annotations

import math
import threading
from typing import Any

from ninjemys.idl.loader import get_message_class
from ninjemys.sim.ros_control.controllers import Controller, ControllerError, _join, _stamp
from ninjemys.sim.ros_control.hardware import VELOCITY_INTERFACE, SimRobotHW

EFFORT_INTERFACE = "hardware_interface::EffortJointInterface"
POSITION_INTERFACE = "hardware_interface::PositionJointInterface"
#: JointControllerState is published this often (s of simulated time): Gazebo's 1 kHz loop / 10
STATE_PERIOD = 0.01
#: how fast an effort-controlled arm joint closes its position error (s)
POSITION_TIME_CONSTANT = 0.1


def _joint(params: dict, ns: str, hw: SimRobotHW, interface: str) -> str:
    joint = params.get("joint")
    if not isinstance(joint, str) or not joint:
        raise ControllerError(f"No joint given (namespace: {ns})")
    if joint not in hw.joints:
        raise ControllerError(f"Could not find joint '{joint}' in '{interface}'.")
    return joint


class _Pid:
    """control_toolbox::Pid's gains (p, i, d, i_clamp, antiwindup) and its computeCommand."""

    def __init__(self, params: Any, ns: str) -> None:
        where = f"{ns}/pid"
        if not isinstance(params, dict) or "p" not in params:
            raise ControllerError(f"No p gain specified for pid.  Namespace: {where}")

        def gain(key: str) -> float:
            value = params.get(key, 0.0)
            if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
                raise ControllerError(f"{where}: gain '{key}' must be a number, got {value!r}")
            return float(value)

        self.p, self.i, self.d = gain("p"), gain("i"), gain("d")
        self.i_clamp = max(abs(gain("i_clamp_max")), abs(gain("i_clamp_min")), abs(gain("i_clamp")))
        antiwindup = params.get("antiwindup", False)
        self.antiwindup = bool(antiwindup) if isinstance(antiwindup, bool) else False
        self.reset()

    def reset(self) -> None:
        self.integral = 0.0
        self.last_error = 0.0

    def compute(self, error: float, dt: float) -> float:
        if dt <= 0 or not math.isfinite(error):
            return 0.0
        self.integral += error * dt
        if self.i_clamp:
            limit = self.i_clamp / self.i if self.i else 0.0
            self.integral = max(-limit, min(limit, self.integral))
        derivative = (error - self.last_error) / dt
        self.last_error = error
        return self.p * error + self.i * self.integral + self.d * derivative


class _StateReport:
    """An effort controller's PID and its ``control_msgs/JointControllerState`` on ``<name>/state``, sent
    every :data:`STATE_PERIOD` of simulated time (what both effort controllers publish)."""

    def __init__(self, node: Any, ns: str, pid: _Pid) -> None:
        self.pid = pid
        self._msg: Any = get_message_class("control_msgs/JointControllerState")
        self.pub = node.publisher(_join(ns, "state"), self._msg, queue_size=1)
        self.last: float | None = None

    def reset(self) -> None:
        self.pid.reset()
        self.last = None

    def update(
        self, now: float, period: float, set_point: float, value: float, value_dot: float | None
    ) -> None:
        """Run the PID on ``set_point - value``; publish the state when it is due."""
        error = set_point - value
        effort = self.pid.compute(error, period)
        if self.last is not None and now < self.last + STATE_PERIOD - 1e-9:
            return
        self.last = now
        msg = self._msg()
        msg.header.stamp = _stamp(now)
        msg.set_point = set_point
        msg.process_value = value
        if value_dot is not None:
            msg.process_value_dot = value_dot
        msg.error = error
        msg.time_step = period
        msg.command = effort
        msg.p, msg.i, msg.d, msg.i_clamp = self.pid.p, self.pid.i, self.pid.d, self.pid.i_clamp
        msg.antiwindup = self.pid.antiwindup
        self.pub.publish(msg)

    def close(self) -> None:
        self.pub.unregister()


class _JointVelocity(Controller):
    """A wheel speed (rad/s) on ``<ns>/<name>/command``; the joint is driven at it."""

    def __init__(self, name: str, node: Any, hw: SimRobotHW, root_ns: str, params: dict) -> None:
        super().__init__(name, node, hw, root_ns, params)
        self.joint = _joint(params, self.ns, hw, self.interface)
        self._lock = threading.Lock()
        self._command = 0.0
        self._float: Any = get_message_class("std_msgs/Float64")
        self.sub = node.subscriber(_join(self.ns, "command"), self._float, self._on_command, queue_size=1)

    @property
    def claimed(self) -> list[str]:
        return [self.joint]

    def _on_command(self, msg: Any) -> None:
        with self._lock:
            self._command = float(msg.data)

    def command(self) -> float:
        with self._lock:
            return self._command

    def starting(self, now: float) -> None:
        with self._lock:
            self._command = 0.0

    def stopping(self, now: float) -> None:
        self.hw.joints[self.joint].command = 0.0

    def update(self, now: float, period: float) -> None:
        target = self.command()
        # a NaN or inf speed would poison the simulated wheel: the wheel stops instead
        self.hw.joints[self.joint].command = target if math.isfinite(target) else 0.0

    def close(self) -> None:
        self.sub.unregister()


class VelocityJointVelocityController(_JointVelocity):
    """velocity_controllers/JointVelocityController: the command goes to the joint as it is."""

    type_name = "velocity_controllers/JointVelocityController"
    interface = VELOCITY_INTERFACE


class _Reported(_JointVelocity):
    """An effort controller's PID gains and its JointControllerState on ``<name>/state``: read,
    reset at start and closed with the controller (the subclass's ``update`` reports)."""

    def __init__(self, name: str, node: Any, hw: SimRobotHW, root_ns: str, params: dict) -> None:
        pid = _Pid(params.get("pid"), _join(root_ns, name))  # before subscribing: nothing to undo
        super().__init__(name, node, hw, root_ns, params)
        self.report = _StateReport(node, self.ns, pid)

    def starting(self, now: float) -> None:
        super().starting(now)
        self.report.reset()

    def close(self) -> None:
        super().close()
        self.report.close()


class EffortJointVelocityController(_Reported):
    """effort_controllers/JointVelocityController: a PID around the joint's speed, its state published."""

    type_name = "effort_controllers/JointVelocityController"
    interface = EFFORT_INTERFACE

    def update(self, now: float, period: float) -> None:
        super().update(now, period)
        handle = self.hw.joints[self.joint]
        self.report.update(now, period, handle.command, handle.velocity, None)


class _JointPosition(_JointVelocity):
    """A joint angle (rad) on ``<ns>/<name>/command``; the joint is moved to it."""

    def starting(self, now: float) -> None:
        with self._lock:  # ros_control's position controllers hold the joint where it is on start
            self._command = self.hw.joints[self.joint].position

    def speed_to(self, target: float, period: float) -> float:
        """The joint velocity that moves it toward ``target`` this step."""
        handle = self.hw.joints[self.joint]
        if not math.isfinite(target) or period <= 0:
            return 0.0
        return (target - handle.position) / period

    def update(self, now: float, period: float) -> None:
        self.hw.joints[self.joint].command = self.speed_to(self.command(), period)


class PositionJointPositionController(_JointPosition):
    """position_controllers/JointPositionController: the joint is set to the command."""

    type_name = "position_controllers/JointPositionController"
    interface = POSITION_INTERFACE


class EffortJointPositionController(_Reported, _JointPosition):
    """effort_controllers/JointPositionController: the joint follows the command, its state published."""

    type_name = "effort_controllers/JointPositionController"
    interface = EFFORT_INTERFACE

    def __init__(self, name: str, node: Any, hw: SimRobotHW, root_ns: str, params: dict) -> None:
        super().__init__(name, node, hw, root_ns, params)
        self.limit = hw.velocity_limits.get(self.joint)

    def speed_to(self, target: float, period: float) -> float:
        handle = self.hw.joints[self.joint]
        if not math.isfinite(target):
            return 0.0
        speed = (target - handle.position) / max(POSITION_TIME_CONSTANT, period)
        if self.limit:
            speed = max(-self.limit, min(self.limit, speed))
        return speed

    def update(self, now: float, period: float) -> None:
        target = self.command()
        handle = self.hw.joints[self.joint]
        handle.command = self.speed_to(target, period)
        self.report.update(now, period, target, handle.position, handle.velocity)


JOINT_CONTROLLER_TYPES: dict[str, type[Controller]] = {
    EffortJointPositionController.type_name: EffortJointPositionController,
    PositionJointPositionController.type_name: PositionJointPositionController,
    EffortJointVelocityController.type_name: EffortJointVelocityController,
    VelocityJointVelocityController.type_name: VelocityJointVelocityController,
}
