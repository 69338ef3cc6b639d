"""The seam between the simulator and ros_control: joint handles, and one call per physics step.

gazebo_ros_control's DefaultRobotHWSim exposes every joint with a transmission through a
JointStateInterface (position, velocity, effort) and, for velocity transmissions, a
VelocityJointInterface (a command in rad/s). :class:`SimRobotHW` is that for a wheeled base;
:class:`ControlLoop` is what the simulator node owns::

    loop = ControlLoop(node, model)                       # advertises <ns>/controller_manager/*
    commands = loop.step(sim_time, dt, {joint: (position, velocity), ...})   # every step
    # commands: {joint: rad/s} for each joint a running controller commands
    loop.step_robot(robot, sim_time, dt)   # the same for a simcore Robot (angles/speeds in, target out)
"""

from __future__ import annotations

import threading
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from ninjemys.sim.robot_model import RobotModel

JOINT_STATE_INTERFACE = "hardware_interface::JointStateInterface"
VELOCITY_INTERFACE = "hardware_interface::VelocityJointInterface"


@dataclass
class JointHandle:
    name: str
    position: float = 0.0
    velocity: float = 0.0
    effort: float = 0.0
    command: float = 0.0


class SimRobotHW:
    """The robot's joints as ros_control sees them, with the description's wheel geometry.

    ``wheel_separation`` and ``wheel_radius`` stand in for what diff_drive_controller reads from the
    URDF when its own parameters are absent.
    """

    def __init__(
        self,
        joints: Iterable[str],
        wheel_separation: float,
        wheel_radius: float,
        velocity_limits: Mapping[str, float] | None = None,
    ) -> None:
        self.joints = {name: JointHandle(name) for name in joints}
        self.wheel_separation = wheel_separation
        self.wheel_radius = wheel_radius
        #: the URDF's <limit velocity> per joint (rad/s), where it gives one
        self.velocity_limits = dict(velocity_limits or {})
        self.lock = threading.Lock()

    def read(self, states: Mapping[str, tuple[float, float]]) -> None:
        """Copy the simulator's joint (position, velocity) into the handles."""
        for name, (position, velocity) in states.items():
            handle = self.joints.get(name)
            if handle is not None:
                handle.position, handle.velocity = position, velocity

    def commands(self, claimed: Iterable[str]) -> dict[str, float]:
        return {name: self.joints[name].command for name in claimed if name in self.joints}


class ControlLoop:
    """gazebo_ros_control for one robot: a controller_manager over the robot's wheel joints."""

    def __init__(self, node: Any, model: RobotModel, namespace: str | None = None) -> None:
        from ninjemys.sim.ros_control.manager import ControllerManager

        named = [j for j in (model.left_joint, model.right_joint) if j]
        joints = list(dict.fromkeys(named + list(model.control_joints)))
        self.hw = SimRobotHW(joints, model.wheel_separation, model.wheel_radius, model.joint_velocity_limits)
        sides = dict(model.control_joints) or {model.left_joint: "left", model.right_joint: "right"}
        self.left = [j for j, side in sides.items() if side == "left"]
        self.right = [j for j, side in sides.items() if side == "right"]
        #: joints that are no wheel (an arm's): moved here, kinematically, at their commanded speed
        self.free = {j: JointHandle(j) for j, side in sides.items() if not side and j}
        #: beside a plugin drive: the wheels keep the plugin's targets unless a controller commands them
        beside = getattr(model, "control_beside", None)  # (a stand-in model may not have one)
        self.beside = beside is not None
        spec = beside or model.drive
        ns = namespace if namespace is not None else spec.controller_namespace
        self.manager = ControllerManager(node, self.hw, ns)

    def step(self, now: float, period: float, joints: Mapping[str, tuple[float, float]]) -> dict[str, float]:
        """Read the joints, update the running controllers, return the commanded joint velocities."""
        self.hw.read(joints)
        return self.manager.update(now, period)

    def step_robot(self, robot: Any, now: float, period: float) -> None:
        """:meth:`step` for a :class:`ninjemys.sim.simcore.Robot`: its wheel angles and speeds in, its
        wheel targets out. Every joint of a side (a four-wheel base) reads that side's wheel; the side's
        target is the mean of its commanded joints (0 when no running controller commands them)."""
        states = {j: (robot.left_angle, robot.wl) for j in self.left}
        states.update({j: (robot.right_angle, robot.wr) for j in self.right})
        states.update({j: (h.position, h.velocity) for j, h in self.free.items()})
        commands = self.step(now, period, states)
        for j, h in self.free.items():
            h.velocity = commands.get(j, 0.0)
            h.position += h.velocity * period
        left = [commands[j] for j in self.left if j in commands]
        right = [commands[j] for j in self.right if j in commands]
        if self.beside and not (left or right):
            return
        robot.target = (sum(left) / len(left) if left else 0.0, sum(right) / len(right) if right else 0.0)

    def close(self) -> None:
        self.manager.close()
