"""ros_control's pieces without a ROS graph: odometry, limits, the manager's rules, the step interface."""

from __future__ import annotations

import math
from typing import Any

import pytest

from ninjemys.sim.ros_control.hardware import SimRobotHW
from ninjemys.sim.ros_control.limits import SpeedLimiter
from ninjemys.sim.ros_control.manager import BEST_EFFORT, STRICT, ControllerManager
from ninjemys.sim.ros_control.odometry import Odometry


class _Handle:
    def __init__(self, topic: str) -> None:
        self.topic, self.sent, self.closed = topic, [], False

    def publish(self, msg: Any) -> None:
        self.sent.append(msg)

    def unregister(self) -> None:
        self.closed = True


class _Log:
    def __init__(self) -> None:
        self.lines: list[tuple[str, str]] = []

    def __getattr__(self, level: str):
        return lambda msg: self.lines.append((level, msg))


class FakeNode:
    """The slice of ninjemys.node.Node the controllers use, recording what they do."""

    def __init__(self, params: dict) -> None:
        self.params, self.log = params, _Log()
        self.pubs: dict[str, _Handle] = {}
        self.subs: dict[str, Any] = {}
        self.services: dict[str, Any] = {}

    def get_param(self, key: str) -> Any:
        node: Any = self.params
        for part in key.strip("/").split("/"):
            if not isinstance(node, dict) or part not in node:
                from ninjemys.errors import ParameterError

                raise ParameterError(key)
            node = node[part]
        return node

    def publisher(self, topic: str, cls: Any, queue_size: int = 10) -> _Handle:
        self.pubs[topic] = _Handle(topic)
        return self.pubs[topic]

    def subscriber(self, topic: str, cls: Any, cb: Any, queue_size: int = 1) -> _Handle:
        self.subs[topic] = cb
        return _Handle(topic)

    def service(self, name: str, cls: Any, handler: Any) -> str:
        self.services[name] = handler
        return name

    def release_service(self, s: Any) -> None:
        pass


DIFF = {
    "type": "diff_drive_controller/DiffDriveController",
    "left_wheel": "wl",
    "right_wheel": "wr",
    "wheel_separation": 0.2,
    "wheel_radius": 0.05,
    "publish_rate": 50.0,
    "cmd_vel_timeout": 0.25,
    "base_frame_id": "base_footprint",
    "enable_odom_tf": False,
    "pose_covariance_diagonal": [0.001, 0.001, 1e6, 1e6, 1e6, 1000.0],
    "twist_covariance_diagonal": [0.001, 0.001, 1e6, 1e6, 1e6, 1000.0],
    "linear": {"x": {"has_velocity_limits": True, "max_velocity": 0.5}},
    "angular": {"z": {"has_acceleration_limits": True, "max_acceleration": 2.0}},
}
JSC = {"type": "joint_state_controller/JointStateController", "publish_rate": 10}


def _manager(params: dict, ns: str = "/") -> tuple[FakeNode, ControllerManager, SimRobotHW]:
    node = FakeNode(params)
    hw = SimRobotHW(["wl", "wr"], 0.19, 0.05)
    return node, ControllerManager(node, hw, ns), hw


def _twist(lin: float, ang: float) -> Any:
    from ninjemys.idl.loader import get_message_class

    t = get_message_class("geometry_msgs/Twist")()
    t.linear.x, t.angular.z = lin, ang
    return t


def test_services_and_topics_under_the_controllers_namespace():
    node, cm, _ = _manager({"robot": {"base_controller": DIFF, "joint_state_controller": JSC}}, "/robot")
    assert set(node.services) == {
        f"/robot/controller_manager/{s}"
        for s in (
            "load_controller",
            "unload_controller",
            "switch_controller",
            "list_controllers",
            "list_controller_types",
            "reload_controller_libraries",
        )
    }
    assert cm.load("base_controller") and cm.load("joint_state_controller")
    assert "/robot/base_controller/cmd_vel" in node.subs
    assert "/robot/base_controller/odom" in node.pubs and "/robot/joint_states" in node.pubs
    assert "/tf" not in node.pubs  # enable_odom_tf: false


def test_diff_drive_turns_cmd_vel_into_wheel_velocities_with_limits_and_timeout():
    node, cm, hw = _manager({"base": DIFF})
    assert cm.load("base") and cm.switch(["base"], [], STRICT)
    cb = node.subs["/base/cmd_vel"]
    cm.update(0.0, 0.01)
    cb(_twist(1.0, 0.0))  # above max_velocity 0.5
    cmds = cm.update(0.01, 0.01)
    assert cmds == pytest.approx({"wl": 0.5 / 0.05, "wr": 0.5 / 0.05})
    cb(_twist(0.0, 1.0))
    cmds = cm.update(0.02, 0.01)  # angular acceleration 2 rad/s^2: 0.02 rad/s after 10 ms
    w = 0.02
    assert cmds["wr"] == pytest.approx(w * 0.1 / 0.05) and cmds["wl"] == pytest.approx(-w * 0.1 / 0.05)
    for i in range(3, 80):  # no new command for 0.25 s: the controller brakes (at the decel limit)
        cmds = cm.update(i * 0.01, 0.01)
    assert cmds["wl"] == pytest.approx(0.0, abs=1e-9) and cmds["wr"] == pytest.approx(0.0, abs=1e-9)


def test_publish_cmd_publishes_the_limited_command():
    node, cm, _ = _manager({"base": dict(DIFF, publish_cmd=True)})
    assert cm.load("base") and cm.switch(["base"], [], STRICT)
    node.subs["/base/cmd_vel"](_twist(2.0, 0.0))
    cm.update(0.01, 0.01)
    out = node.pubs["/base/cmd_vel_out"].sent
    assert len(out) == 1 and out[0].twist.linear.x == 0.5  # max_velocity


def test_odometry_follows_the_wheels_and_publishes_at_publish_rate():
    node, cm, hw = _manager({"base": DIFF})
    cm.load("base")
    cm.switch(["base"], [], STRICT)
    # both wheels at 10 rad/s (0.5 m/s) for 1 s, then a quarter turn in place
    t, pos = 0.0, 0.0
    for _ in range(100):
        t += 0.01
        pos += 0.1
        hw.read({"wl": (pos, 10.0), "wr": (pos, 10.0)})
        cm.update(t, 0.01)
    odom = node.pubs["/base/odom"].sent
    assert 49 <= len(odom) <= 52  # 50 Hz over 1 s
    last = odom[-1]
    assert last.pose.pose.position.x == pytest.approx(
        0.5, abs=0.015
    ) and last.twist.twist.linear.x == pytest.approx(0.5)
    assert last.child_frame_id == "base_footprint" and last.header.frame_id == "odom"
    assert last.pose.covariance[0] == 0.001 and last.pose.covariance[35] == 1000.0
    turn = (math.pi / 2) * 0.2 / 2 / 0.05  # wheel angle for a quarter turn on 0.2 m separation
    left, right = pos, pos
    for _ in range(100):
        t += 0.01
        left -= turn / 100
        right += turn / 100
        hw.read({"wl": (left, 0.0), "wr": (right, 0.0)})
        cm.update(t, 0.01)
    o = cm.controllers["base"].controller.odometry
    assert o.heading == pytest.approx(math.pi / 2) and o.x == pytest.approx(0.5, abs=0.01)


def test_manager_refuses_as_controller_manager_does():
    node, cm, _ = _manager({"base": DIFF, "base2": DIFF, "typo": {"type": "diff_drive_controller/Nope"}})
    assert not cm.load("missing")
    assert (
        "the type was not specified" in node.log.lines[-1][1]
        and "(namespace: '/missing')" in node.log.lines[-1][1]
    )
    assert not cm.load("typo")
    assert "controller type 'diff_drive_controller/Nope' does not exist" in node.log.lines[-2][1]
    assert cm.load("base") and not cm.load("base")
    assert cm.load("base2")
    assert cm.switch(["base"], [], STRICT)
    # both claim wl and wr
    assert not cm.switch(["base2"], [], STRICT)
    assert any("Resource conflict on [wl]" in line for _, line in node.log.lines)
    assert not cm.unload("base")  # still running
    assert not cm.switch(["ghost"], [], STRICT) and cm.switch(["ghost"], [], BEST_EFFORT)
    assert cm.switch(["base2"], ["base"], STRICT)
    assert cm.unload("base") and "base" not in cm.controllers
    listing = node.services["/controller_manager/list_controllers"](None).controller
    assert [(c.name, c.state, c.type) for c in listing] == [
        ("base2", "running", "diff_drive_controller/DiffDriveController")
    ]
    assert listing[0].claimed_resources[0].hardware_interface == "hardware_interface::VelocityJointInterface"
    assert listing[0].claimed_resources[0].resources == ["wl", "wr"]


@pytest.mark.parametrize(
    ("params", "line"),
    [
        ({"left_wheel": None}, "Couldn't retrieve left wheel name from param server."),
        (
            {"right_wheel": "nope"},
            "Could not find joint 'nope' in 'hardware_interface::VelocityJointInterface'.",
        ),
        ({"wheel_radius": "big"}, "/base: parameter 'wheel_radius' must be a number, got 'big'"),
        ({"pose_covariance_diagonal": [1, 2]}, "pose_covariance_diagonal must be a list of 6 numbers"),
    ],
)
def test_bad_diff_drive_parameters_are_refused_with_the_reason(params: dict, line: str):
    p = {k: v for k, v in {**DIFF, **params}.items() if v is not None}
    node, cm, _ = _manager({"base": p})
    assert not cm.load("base")
    assert any(line in text for _, text in node.log.lines), node.log.lines
    assert node.log.lines[-1][1] == "Initializing controller 'base' failed"


def test_joint_state_controller_needs_publish_rate_and_publishes_every_joint():
    node, cm, hw = _manager({"jsc": {"type": "joint_state_controller/JointStateController"}, "jsc2": JSC})
    assert not cm.load("jsc")
    assert ("error", "Parameter 'publish_rate' not set") in node.log.lines
    assert cm.load("jsc2") and cm.switch(["jsc2"], [], STRICT)
    for i in range(101):
        hw.read({"wl": (i * 0.1, 10.0), "wr": (-i * 0.1, -10.0)})
        assert cm.update(i * 0.01, 0.01) == {}  # it commands nothing
    sent = node.pubs["/joint_states"].sent
    assert len(sent) == 10  # 10 Hz over 1 s, the first one period after the start (as ROS 1)
    assert sent[-1].name == ["wl", "wr"] and sent[-1].position == pytest.approx([10.0, -10.0])


def test_speed_limiter_and_odometry_arithmetic():
    lim = SpeedLimiter(has_acceleration_limits=True, max_acceleration=1.0, min_acceleration=-2.0)
    assert lim.limit(5.0, 0.0, 0.0, 0.1) == pytest.approx(0.1)
    assert lim.limit(-5.0, 0.0, 0.0, 0.1) == pytest.approx(-0.2)
    jerk = SpeedLimiter(has_jerk_limits=True, max_jerk=10.0, min_jerk=-10.0)
    assert jerk.limit(1.0, 0.0, 0.0, 0.1) == pytest.approx(0.2)  # da <= jerk * 2 dt^2
    o = Odometry(0.2, 0.05, 0.05)
    assert not o.update(0.0, 0.0, 0.0)
    # an arc: the right wheel travels twice the left's
    assert o.update(1.0, 2.0, 1.0)
    assert o.heading == pytest.approx((0.1 - 0.05) / 0.2)
    r = 0.075 / o.heading
    assert o.x == pytest.approx(r * math.sin(o.heading)) and o.y == pytest.approx(
        r * (1 - math.cos(o.heading))
    )


def test_an_arms_position_controllers_move_its_joints_and_report_state():
    """RRBot's pattern: effort_controllers/JointPositionController (follows the command, at most at the
    URDF's velocity limit, state on <name>/state) and position_controllers/JointPositionController (set at
    once) on joints that are no wheels, moved by the control loop itself; the base does not move."""
    from types import SimpleNamespace

    from ninjemys.idl.loader import get_message_class
    from ninjemys.sim.ros_control.hardware import ControlLoop

    params = {
        "arm": {
            "shoulder_controller": {
                "type": "effort_controllers/JointPositionController",
                "joint": "shoulder",
                "pid": {"p": 100.0, "i": 0.01, "d": 10.0},
            },
            "elbow_controller": {"type": "position_controllers/JointPositionController", "joint": "elbow"},
            "joint_state_controller": JSC,
        }
    }
    node = FakeNode(params)
    model = SimpleNamespace(
        left_joint="",
        right_joint="",
        control_joints={"shoulder": "", "elbow": ""},
        joint_velocity_limits={"shoulder": 1.0},
        wheel_separation=0.34,
        wheel_radius=0.05,
        drive=SimpleNamespace(controller_namespace="/arm"),
    )
    loop = ControlLoop(node, model)  # type: ignore[arg-type]
    cm = loop.manager
    for name in ("shoulder_controller", "elbow_controller", "joint_state_controller"):
        assert cm.load(name), node.log.lines
    assert cm.switch(["shoulder_controller", "elbow_controller", "joint_state_controller"], [], STRICT)
    robot = SimpleNamespace(left_angle=0.0, right_angle=0.0, wl=0.0, wr=0.0, target=(9.0, 9.0))
    command = get_message_class("std_msgs/Float64")
    node.subs["/arm/shoulder_controller/command"](command(data=0.5))
    node.subs["/arm/elbow_controller/command"](command(data=-0.3))
    positions = []
    for i in range(100):  # 1 s at 100 Hz
        loop.step_robot(robot, i * 0.01, 0.01)
        positions.append(loop.free["shoulder"].position)
    assert robot.target == (0.0, 0.0)  # no wheels: the base stays
    assert loop.free["elbow"].position == pytest.approx(-0.3)  # the position interface sets it
    # the effort controller's joint never exceeds the 1 rad/s limit and settles on the command
    assert all(b - a <= 0.01 + 1e-12 for a, b in zip(positions, positions[1:], strict=False))
    assert positions[4] < 0.05 + 1e-9 and positions[-1] == pytest.approx(0.5, abs=1e-3)
    state = node.pubs["/arm/shoulder_controller/state"].sent[-1]
    assert state.set_point == 0.5 and state.process_value == pytest.approx(0.5, abs=1e-3)
    last = node.pubs["/arm/joint_states"].sent[-1]
    assert last.name == ["shoulder", "elbow"] and list(last.position) == pytest.approx([0.5, -0.3], abs=1e-3)
