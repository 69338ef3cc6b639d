"""A robot read from its Gazebo description moves in the simulator as Gazebo would move it:
gazebo_ros_diff_drive's wheelSeparation sets the turning rate, and ros_control's diff_drive_controller
drives the wheels through ControlLoop.step_robot."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from ninjemys.sim.description.build import expand_xacro, model_from_description
from ninjemys.sim.ros_control.hardware import ControlLoop
from ninjemys.sim.ros_control.manager import STRICT
from ninjemys.sim.simcore import Simulation
from ninjemys.sim.world2d import World

PACKAGES = Path(__file__).parent / "packages"
XACRO = PACKAGES / "puzzlebot_gz_test" / "urdf" / "puzzlebot.urdf.xacro"


@pytest.fixture(autouse=True)
def _package_path(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(PACKAGES))


def _turn_rate(**args: str) -> float:
    model = model_from_description(expand_xacro(str(XACRO), args), str(XACRO))
    sim = Simulation(World("empty", bounds=(-5, -5, 5, 5)))
    r = sim.add_robot("pb", model, 0.0, 0.0, 0.0)
    r.command(0.0, 0.5)
    for _ in range(round(2.0 / sim.dt)):  # wheelAcceleration 1 m/s^2: settled well within 2 s
        sim.step()
    return r.w


def test_plugin_wheel_separation_changes_the_turning_rate_as_computed():
    # the plugin's wheel speeds are w * sep_plugin / 2 / r; the body turns at r * (wr - wl) / sep_urdf
    assert _turn_rate() == pytest.approx(0.5, rel=1e-6)
    assert _turn_rate(plugin_wheel_separation="0.38") == pytest.approx(0.5 * 0.38 / 0.19, rel=1e-6)
    assert _turn_rate(plugin_wheel_separation="0.095") == pytest.approx(0.5 * 0.095 / 0.19, rel=1e-6)


def test_ros_control_drives_the_simulated_robot_through_step_robot():
    from test_ros_control_core import DIFF, FakeNode

    model = model_from_description(expand_xacro(str(XACRO), {"control": "ros_control"}), str(XACRO))
    assert model.drive.kind == "ros_control"
    params = dict(DIFF, left_wheel="wheel_left_joint", right_wheel="wheel_right_joint")
    del params["wheel_separation"], params["wheel_radius"]  # taken from the description, as from the URDF
    params["linear"] = {}
    params["angular"] = {}
    node = FakeNode({"puzzlebot_controller": params})
    loop = ControlLoop(node, model)
    assert loop.manager.load("puzzlebot_controller")
    assert loop.manager.switch(["puzzlebot_controller"], [], STRICT)
    sim = Simulation(World("empty", bounds=(-5, -5, 5, 5)))
    r = sim.add_robot("pb", model, 0.0, 0.0, 0.0)
    cmd_vel = node.subs["/puzzlebot_controller/cmd_vel"]
    from test_ros_control_core import _twist

    t = 0.0
    for _ in range(round(1.0 / sim.dt)):
        cmd_vel(_twist(0.2, 0.0))
        loop.step_robot(r, t, sim.dt)
        sim.step()
        t += sim.dt
    assert r.x == pytest.approx(0.2, abs=0.01) and abs(r.y) < 1e-6
    odom = loop.manager.controllers["puzzlebot_controller"].controller.odometry
    assert odom.x == pytest.approx(r.x, abs=0.005)
    for _ in range(round(1.0 / sim.dt)):
        cmd_vel(_twist(0.0, math.pi / 2))
        loop.step_robot(r, t, sim.dt)
        sim.step()
        t += sim.dt
    assert r.yaw == pytest.approx(math.pi / 2, abs=0.03)
    assert odom.heading == pytest.approx(r.yaw, abs=0.02)  # odometry reads the wheels one step behind


FOUR_WHEELS = """<?xml version="1.0"?>
<robot name="rover">
  <link name="base_link"><collision><origin xyz="0 0 0.05"/><geometry><box size="0.4 0.3 0.1"/></geometry></collision></link>
  {wheels}
  <gazebo><plugin name="gazebo_ros_control" filename="libgazebo_ros_control.so">
    <robotNamespace>/rover</robotNamespace></plugin></gazebo>
</robot>"""
WHEEL = """<link name="{n}_link"><collision><geometry><cylinder radius="0.06" length="0.03"/></geometry></collision></link>
  <joint name="{n}" type="continuous"><parent link="base_link"/><child link="{n}_link"/>
    <origin xyz="{x} {y} 0" rpy="-1.5708 0 0"/><axis xyz="0 0 1"/></joint>
  <transmission name="{n}_tr"><type>transmission_interface/SimpleTransmission</type>
    <joint name="{n}"><hardwareInterface>hardware_interface/VelocityJointInterface</hardwareInterface></joint>
    <actuator name="{n}_motor"><mechanicalReduction>1</mechanicalReduction></actuator></transmission>"""


def test_four_wheel_ros_control_base_with_wheel_lists():
    from test_ros_control_core import DIFF, FakeNode, _twist

    wheels = "\n  ".join(
        WHEEL.format(n=n, x=x, y=y)
        for n, x, y in (("fl", 0.15, 0.2), ("fr", 0.15, -0.2), ("rl", -0.15, 0.2), ("rr", -0.15, -0.2))
    )
    model = model_from_description(FOUR_WHEELS.format(wheels=wheels), "rover.urdf")
    assert model.drive.kind == "ros_control" and model.drive.controller_namespace == "/rover"
    assert model.control_joints == {
        model.left_joint: "left",
        model.right_joint: "right",
        **{j: s for j, s in (("fl", "left"), ("fr", "right"), ("rl", "left"), ("rr", "right"))},
    }
    assert model.wheel_separation == pytest.approx(0.4) and model.wheel_radius == pytest.approx(0.06)
    params = dict(
        DIFF, left_wheel=["fl", "rl"], right_wheel=["fr", "rr"], wheel_separation=0.4, wheel_radius=0.06
    )
    params["linear"], params["angular"] = {}, {}
    node = FakeNode({"rover": {"base": params}})
    loop = ControlLoop(node, model)
    assert "/rover/controller_manager/load_controller" in node.services
    assert loop.manager.load("base") and loop.manager.switch(["base"], [], STRICT)
    sim = Simulation(World("empty", bounds=(-5, -5, 5, 5)))
    r = sim.add_robot("rover", model, 0.0, 0.0, 0.0)
    cmd_vel = node.subs["/rover/base/cmd_vel"]
    t = 0.0
    for _ in range(round(1.0 / sim.dt)):
        cmd_vel(_twist(0.0, 1.0))
        loop.step_robot(r, t, sim.dt)
        sim.step()
        t += sim.dt
    assert r.yaw == pytest.approx(1.0, abs=0.03)
    odom = loop.manager.controllers["base"].controller.odometry
    assert odom.heading == pytest.approx(r.yaw, abs=0.03)
