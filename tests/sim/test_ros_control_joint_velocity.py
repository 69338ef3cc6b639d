"""effort_controllers/JointVelocityController and velocity_controllers/JointVelocityController, as the
maker's Gazebo PuzzleBot uses them (one per wheel, puzzlebot_diff_control.yaml): a wheel speed on
``<name>/command``, the wheel's control_msgs/JointControllerState on ``<name>/state``; refused with
ROS 1's lines when the joint or the PID gains are missing."""

from __future__ import annotations

from typing import Any

import pytest
from test_ros_control_core import FakeNode

from ninjemys.idl.loader import get_message_class
from ninjemys.sim.ros_control.hardware import SimRobotHW
from ninjemys.sim.ros_control.manager import STRICT, ControllerManager

EFFORT = "effort_controllers/JointVelocityController"
VELOCITY = "velocity_controllers/JointVelocityController"
MAKER = {  # the maker's configuration, joint names and gains as in the course
    "joint_state_controller": {"type": "joint_state_controller/JointStateController", "publish_rate": 50},
    "right_wheel_velocity_controller": {"type": EFFORT, "joint": "base_to_right_w", "pid": {"p": 0.07, "i": 10.0, "d": 0.0}},
    "left_wheel_velocity_controller": {"type": EFFORT, "joint": "base_to_left_w", "pid": {"p": 0.07, "i": 10.0, "d": 0.0}},
}  # fmt: skip


def _float(value: float) -> Any:
    return get_message_class("std_msgs/Float64")(data=value)


def _manager(params: dict) -> tuple[FakeNode, ControllerManager, SimRobotHW]:
    node = FakeNode(params)
    hw = SimRobotHW(["base_to_left_w", "base_to_right_w"], 0.19, 0.05)
    return node, ControllerManager(node, hw, "/"), hw


def test_each_wheel_follows_its_command_and_reports_its_state() -> None:
    node, cm, hw = _manager(MAKER)
    names = list(MAKER)
    assert all(cm.load(n) for n in names) and cm.switch(names, [], STRICT)
    node.subs["/right_wheel_velocity_controller/command"](_float(5.0))
    node.subs["/left_wheel_velocity_controller/command"](_float(-2.5))
    for i in range(100):  # 1 s of 100 Hz steps; the wheels are at 1 and -1 rad/s
        hw.read({"base_to_right_w": (0.0, 1.0), "base_to_left_w": (0.0, -1.0)})
        commands = cm.update(i * 0.01, 0.01)
    assert commands == {"base_to_right_w": 5.0, "base_to_left_w": -2.5}
    states = node.pubs["/right_wheel_velocity_controller/state"].sent
    assert len(states) == 100  # 100 Hz, as Gazebo's 1 kHz loop publishes every 10th update
    last = states[-1]
    assert (last.set_point, last.process_value, last.error) == pytest.approx((5.0, 1.0, 4.0))
    assert (last.p, last.i, last.d, last.time_step) == pytest.approx((0.07, 10.0, 0.0, 0.01))
    # the effort the PID asks for: p * error + i * (the error integrated over the second)
    assert last.command == pytest.approx(0.07 * 4.0 + 10.0 * 4.0 * 1.0, rel=1e-9)
    listing = node.services["/controller_manager/list_controllers"](None).controller
    wheel = [c for c in listing if c.name == "right_wheel_velocity_controller"][0]
    assert wheel.claimed_resources[0].hardware_interface == "hardware_interface::EffortJointInterface"
    assert wheel.claimed_resources[0].resources == ["base_to_right_w"]
    # stopped: the wheel is no longer commanded
    assert cm.switch([], ["right_wheel_velocity_controller"], STRICT)
    assert cm.update(1.0, 0.01) == {"base_to_left_w": -2.5}
    types = node.services["/controller_manager/list_controller_types"](None).types
    assert EFFORT in types and VELOCITY in types


def test_a_velocity_controller_forwards_the_command_and_a_nan_stops_the_wheel() -> None:
    node, cm, hw = _manager({"w": {"type": VELOCITY, "joint": "base_to_left_w"}})
    assert cm.load("w") and cm.switch(["w"], [], STRICT)
    node.subs["/w/command"](_float(3.0))
    assert cm.update(0.0, 0.01) == {"base_to_left_w": 3.0}
    node.subs["/w/command"](_float(float("nan")))
    assert cm.update(0.01, 0.01) == {"base_to_left_w": 0.0}
    assert "/w/state" not in node.pubs


@pytest.mark.parametrize(
    ("params", "line"),
    [
        ({"type": EFFORT, "pid": {"p": 1.0}}, "No joint given (namespace: /wheel)"),
        ({"type": EFFORT, "joint": "base_to_left_w"}, "No p gain specified for pid.  Namespace: /wheel/pid"),
        (
            {"type": EFFORT, "joint": "nope", "pid": {"p": 1.0}},
            "Could not find joint 'nope' in 'hardware_interface::EffortJointInterface'.",
        ),
        (
            {"type": EFFORT, "joint": "base_to_left_w", "pid": {"p": "x"}},
            "/wheel/pid: gain 'p' must be a number",
        ),
    ],
)
def test_bad_parameters_are_refused_with_the_reason(params: dict, line: str) -> None:
    node, cm, _ = _manager({"wheel": params})
    assert not cm.load("wheel")
    assert any(line in text for _, text in node.log.lines), node.log.lines
    assert node.log.lines[-1][1] == "Initializing controller 'wheel' failed"


def test_a_course_control_package_naming_ros_control_builds(
    tmp_path: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The course's puzzlebot_control asks catkin for ros_control's packages (a Python node beside
    them): they are known, so catkin_make builds it, as on a machine with Gazebo and ros_control.
    A book's description package (ros_exploring's mrobot_gazebo) also names gazebo_plugins."""
    from pathlib import Path

    from ninjemys.packages.discovery import find_package
    from ninjemys.tools import catkin_make

    monkeypatch.delenv("ROS_PACKAGE_PATH", raising=False)
    monkeypatch.delenv("CMAKE_PREFIX_PATH", raising=False)
    names = (
        "controller_manager", "diff_drive_controller", "hardware_interface", "transmission_interface",
        "effort_controllers", "velocity_controllers", "joint_state_controller", "gazebo_ros_control",
        "gazebo_plugins", "gazebo_ros",
    )  # fmt: skip
    for name in names:
        assert (find_package(name, {}) / "package.xml").is_file(), name
    ws = Path(str(tmp_path))
    pkg = ws / "src" / "course_control"
    pkg.mkdir(parents=True)
    (pkg / "package.xml").write_text(
        '<?xml version="1.0"?>\n<package format="2"><name>course_control</name><version>0.0.1</version>'
        '<description>d</description><maintainer email="a@b.c">a</maintainer><license>BSD</license>'
        "<buildtool_depend>catkin</buildtool_depend>"
        + "".join(f"<depend>{n}</depend>" for n in names)
        + "</package>\n"
    )
    (pkg / "CMakeLists.txt").write_text(
        "cmake_minimum_required(VERSION 3.0.2)\nproject(course_control)\n"
        f"find_package(catkin REQUIRED COMPONENTS\n  rospy\n  {' '.join(names)}\n  std_msgs\n)\n"
        "catkin_package()\n"
    )
    monkeypatch.chdir(ws)
    assert catkin_make.main([]) == 0
