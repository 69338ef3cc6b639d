"""ros_control in a ROS graph: the simulator's control loop (stood in for by a stepping thread), our
``rosrun controller_manager spawner`` loading the course's controllers from the parameter server,
and real ROS 1 (Debian's rospy and rosservice) driving ``/<controller>/cmd_vel`` and reading odometry."""

from __future__ import annotations

import os
import signal
import subprocess
import threading
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from ninjemys import testing
from ninjemys.node.node import Node
from ninjemys.paramyaml import load_yaml
from ninjemys.sim.robot_model import load_robot_model
from ninjemys.sim.ros_control.hardware import ControlLoop

PACKAGE = Path(__file__).parent / "packages" / "puzzlebot_gz_test"


class SteppedRobot:
    """What the simulator node does for a ros_control robot: wheels turn at the commanded speed."""

    def __init__(self, node: Node, loop: ControlLoop, joints: list[str]) -> None:
        self.loop, self.joints = loop, joints
        self.pos = dict.fromkeys(joints, 0.0)
        self.vel = dict.fromkeys(joints, 0.0)
        self.stop = threading.Event()
        self.thread = threading.Thread(target=self.run, daemon=True)
        self.thread.start()

    def run(self) -> None:
        t0 = time.monotonic()
        last = 0.0
        while not self.stop.wait(0.005):
            now = time.monotonic() - t0
            dt = now - last
            last = now
            # read as hardware is: the wheels turned at the last command until now. Moved after the
            # step, the positions lagged a step: the controller's odometry took one step's travel
            # over the next step's time, and a loaded machine's uneven steps made 0.2 m/s read 0.246
            for j in self.joints:
                self.pos[j] += self.vel[j] * dt
            states = {j: (self.pos[j], self.vel[j]) for j in self.joints}
            commands = self.loop.step(now, dt, states)
            for j in self.joints:
                self.vel[j] = commands.get(j, 0.0)


@pytest.fixture
def graph(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[tuple[str, Node, SteppedRobot]]:
    with testing.run_master() as uri:
        node = Node("gazebo", master_uri=uri)
        config = load_yaml((PACKAGE / "config" / "diff_drive.yaml").read_text())
        for key, value in config.items():
            node.set_param(f"/{key}", value)
        monkeypatch.setenv("ROS_PACKAGE_PATH", str(PACKAGE.parent))  # not left to later tests
        model = load_robot_model(str(PACKAGE / "urdf" / "puzzlebot.urdf.xacro"))
        model.drive.controller_namespace = "/"
        loop = ControlLoop(node, model)
        robot = SteppedRobot(node, loop, [model.left_joint, model.right_joint])
        try:
            yield uri, node, robot
        finally:
            robot.stop.set()
            robot.thread.join(5)
            loop.close()
            node.shutdown("test over")


def _spawner(uri: str, *names: str) -> subprocess.Popen:
    env = dict(os.environ, ROS_MASTER_URI=uri, ROS_HOSTNAME="localhost", PYTHONUNBUFFERED="1")
    return subprocess.Popen(
        [testing.ninjemys_bin("rosrun"), "controller_manager", "spawner", *names],
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        start_new_session=True,
    )


def _wait(pred, timeout: float = 20.0, what: str = "") -> None:
    deadline = time.monotonic() + timeout
    while not pred():
        assert time.monotonic() < deadline, f"timed out waiting for {what}"
        time.sleep(0.05)


def _states(node: Node) -> dict[str, str]:
    from ninjemys.idl.loader import get_service_class

    cls = get_service_class("controller_manager_msgs/ListControllers")
    resp = node.service_proxy("/controller_manager/list_controllers", cls)(cls._request_class())
    return {c.name: c.state for c in resp.controller}


def test_spawner_loads_starts_and_on_exit_unloads(graph):
    uri, node, robot = graph
    proc = _spawner(uri, "joint_state_controller", "puzzlebot_controller")
    try:
        _wait(
            lambda: _states(node) == {"joint_state_controller": "running", "puzzlebot_controller": "running"},
            what="both controllers running",
        )
        from ninjemys.idl.loader import get_message_class

        twist_cls = get_message_class("geometry_msgs/Twist")
        odom: list = []
        sub = node.subscriber(
            "/puzzlebot_controller/odom", get_message_class("nav_msgs/Odometry"), odom.append
        )
        pub = node.publisher("/puzzlebot_controller/cmd_vel", twist_cls)
        t = twist_cls()
        t.angular.z = 1.0
        sending = threading.Event()

        def send() -> (
            None
        ):  # keeps the command fresher than cmd_vel_timeout (0.5 s), however slow the machine
            while not sending.wait(0.05):
                pub.publish(t)

        sender = threading.Thread(target=send, daemon=True)
        sender.start()
        try:
            _wait(lambda: odom and odom[-1].twist.twist.angular.z > 0.8, what="odometry turning")
            # the wheels turn oppositely at w * separation / 2 / radius
            right, left = robot.vel["wheel_right_joint"], robot.vel["wheel_left_joint"]
        finally:
            sending.set()
            sender.join(5)
        assert right == pytest.approx(0.19 / 2 / 0.05, rel=0.05)
        assert left == pytest.approx(-0.19 / 2 / 0.05, rel=0.05)
        assert odom[-1].child_frame_id == "base_footprint"
        sub.unregister()
    finally:
        proc.send_signal(signal.SIGINT)
        out, _ = proc.communicate(timeout=20)
    assert "Loading controller: joint_state_controller" in out
    assert "Controller Spawner: Loaded controllers: joint_state_controller, puzzlebot_controller" in out
    assert "Started controllers: joint_state_controller, puzzlebot_controller" in out
    assert "Shutting down spawner. Stopping and unloading controllers..." in out
    _wait(lambda: _states(node) == {}, what="controllers unloaded")


def test_spawner_reports_a_controller_without_configuration(graph):
    uri, node, _ = graph
    proc = _spawner(uri, "no_such_controller", "joint_state_controller")
    try:
        _wait(lambda: _states(node).get("joint_state_controller") == "running", what="jsc running")
    finally:
        proc.send_signal(signal.SIGINT)
        out, _ = proc.communicate(timeout=20)
    assert "Failed to load no_such_controller" in out
    assert "Controller Spawner: Loaded controllers: joint_state_controller" in out


def test_spawner_stopped_loads_without_starting(graph):
    uri, node, _ = graph
    proc = _spawner(uri, "--stopped", "puzzlebot_controller")
    try:
        _wait(lambda: _states(node) == {"puzzlebot_controller": "initialized"}, what="loaded, not started")
    finally:
        proc.send_signal(signal.SIGINT)
        out, _ = proc.communicate(timeout=20)
    assert "Started controllers" not in out
    _wait(lambda: _states(node) == {}, what="controllers unloaded")


def test_controller_manager_command(graph):
    uri, node, _ = graph
    env = dict(os.environ, ROS_MASTER_URI=uri, ROS_HOSTNAME="localhost")
    cmd = [testing.ninjemys_bin("rosrun"), "controller_manager", "controller_manager"]

    def run(*args: str) -> str:
        return subprocess.run([*cmd, *args], env=env, capture_output=True, text=True, timeout=30).stdout

    assert run("list") == "No controllers are loaded in mechanism control\n"
    assert run("spawn", "puzzlebot_controller") == (
        "Loaded 'puzzlebot_controller'\nStarted ['puzzlebot_controller'] successfully\n"
    )
    assert run("list") == (
        "'puzzlebot_controller' - 'hardware_interface::VelocityJointInterface' ( running )\n"
    )
    assert "diff_drive_controller/DiffDriveController" in run("list-types")
    assert run("kill", "puzzlebot_controller") == (
        "Stopped ['puzzlebot_controller'] successfully\nUnloaded 'puzzlebot_controller' successfully\n"
    )


_ROSPY_DRIVER = r"""
import sys, rospy
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
rospy.init_node("rospy_driver")
got = []
rospy.Subscriber("/puzzlebot_controller/odom", Odometry, got.append)
pub = rospy.Publisher("/puzzlebot_controller/cmd_vel", Twist, queue_size=1)
t = Twist(); t.linear.x = 0.2
# drive until the odometry shows the move at the commanded speed, at most 20 s: a loaded machine
# steps the robot slowly, and a pause of this driver past the controller's cmd_vel_timeout (0.5 s)
# stops the wheels for a moment (then 10 more commands read 0.11 m/s)
end = rospy.get_time() + 20.0
def moving():
    return got and got[-1].pose.pose.position.x > 0.15 and abs(got[-1].twist.twist.linear.x - 0.2) < 0.01
while rospy.get_time() < end and not moving():
    pub.publish(t); rospy.sleep(0.05)
o = got[-1]
print("ODOM %.3f %.3f %s" % (o.pose.pose.position.x, o.twist.twist.linear.x, o.child_frame_id))
"""


@pytest.mark.ros1
@pytest.mark.skipif(not testing.have_ros1(), reason="needs Debian's ROS 1")
def test_real_rospy_drives_the_diff_drive_controller_and_rosservice_sees_the_manager(graph):
    uri, node, robot = graph
    proc = _spawner(uri, "joint_state_controller", "puzzlebot_controller")
    try:
        _wait(lambda: _states(node).get("puzzlebot_controller") == "running", what="controller running")
        env = testing.ros1_env(uri)
        out = subprocess.run(
            [testing.ROS1_PYTHON, "-c", _ROSPY_DRIVER], env=env, capture_output=True, text=True, timeout=60
        )
        assert out.returncode == 0, out.stderr
        x, v, child = out.stdout.split()[1:4]
        assert float(v) == pytest.approx(0.2, abs=0.03) and float(x) > 0.1 and child == "base_footprint"
        listed = subprocess.run(
            ["/usr/bin/rosservice", "list"], env=env, capture_output=True, text=True, timeout=30
        )
        for name in ("load_controller", "unload_controller", "switch_controller", "list_controllers"):
            assert f"/controller_manager/{name}" in listed.stdout.split()
        kind = subprocess.run(
            ["/usr/bin/rosservice", "type", "/controller_manager/switch_controller"],
            env=env,
            capture_output=True,
            text=True,
            timeout=30,
        )
        assert kind.stdout.strip() == "controller_manager_msgs/SwitchController"
        topics = subprocess.run(
            ["/usr/bin/rostopic", "list"], env=env, capture_output=True, text=True, timeout=30
        )
        assert {"/joint_states", "/puzzlebot_controller/odom", "/puzzlebot_controller/cmd_vel"} <= set(
            topics.stdout.split()
        )
    finally:
        proc.send_signal(signal.SIGINT)
        proc.communicate(timeout=20)


_ROSPY_SERVICES = r"""
import json, sys, rospy, genpy.dynamic
spec = json.loads(sys.argv[1])

def service_class(name):
    s = spec[name]
    req = genpy.dynamic.generate_dynamic(s["req_type"], s["req_text"])[s["req_type"]]
    resp = genpy.dynamic.generate_dynamic(s["resp_type"], s["resp_text"])[s["resp_type"]]
    return type(name, (object,), {"_type": s["type"], "_md5sum": s["md5"], "_request_class": req, "_response_class": resp})

rospy.init_node("rospy_cm_client")
ListControllers = service_class("ListControllers")
SwitchController = service_class("SwitchController")
listing = rospy.ServiceProxy("/controller_manager/list_controllers", ListControllers)
switch = rospy.ServiceProxy("/controller_manager/switch_controller", SwitchController)
before = listing(ListControllers._request_class())
print("BEFORE", sorted((c.name, c.state, c.claimed_resources[0].hardware_interface) for c in before.controller))
r = switch(SwitchController._request_class(stop_controllers=["puzzlebot_controller"], strictness=2))
print("SWITCH", r.ok)
after = listing(ListControllers._request_class())
print("AFTER", sorted((c.name, c.state) for c in after.controller))
"""


@pytest.mark.ros1
@pytest.mark.skipif(not testing.have_ros1(), reason="needs Debian's ROS 1")
def test_real_rospy_calls_the_controller_manager_services(graph):
    """Debian has no controller_manager_msgs: genpy generates the classes from our full texts, and
    rospy's handshake checks our md5sums against them (the md5s themselves are checked by genmsg)."""
    import json

    from ninjemys.idl.loader import get_service_class

    uri, node, _ = graph
    spec = {}
    for name in ("ListControllers", "SwitchController"):
        cls = get_service_class(f"controller_manager_msgs/{name}")
        spec[name] = {
            "type": cls._type,
            "md5": cls._md5sum,
            "req_type": cls._request_class._type,
            "req_text": cls._request_class._full_text,
            "resp_type": cls._response_class._type,
            "resp_text": cls._response_class._full_text,
        }
    proc = _spawner(uri, "joint_state_controller", "puzzlebot_controller")
    try:
        _wait(lambda: _states(node).get("puzzlebot_controller") == "running", what="controller running")
        out = subprocess.run(
            [testing.ROS1_PYTHON, "-c", _ROSPY_SERVICES, json.dumps(spec)],
            env=testing.ros1_env(uri),
            capture_output=True,
            text=True,
            timeout=60,
        )
        assert out.returncode == 0, out.stderr
        lines = dict(line.split(" ", 1) for line in out.stdout.splitlines())
        assert lines["BEFORE"] == str(
            [
                ("joint_state_controller", "running", "hardware_interface::JointStateInterface"),
                ("puzzlebot_controller", "running", "hardware_interface::VelocityJointInterface"),
            ]
        )
        assert lines["SWITCH"] == "True"
        assert lines["AFTER"] == str(
            [("joint_state_controller", "running"), ("puzzlebot_controller", "stopped")]
        )
    finally:
        proc.send_signal(signal.SIGINT)
        proc.communicate(timeout=20)
