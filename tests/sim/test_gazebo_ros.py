"""Gazebo's names on our simulator, read and called by Debian's real ROS 1: ``roslaunch gazebo_ros
empty_world.launch`` (paused), ``rosrun gazebo_ros spawn_model -urdf -param robot_description ...
-unpause``, the /gazebo services through /usr/bin/rosservice and a rospy node under /usr/bin/python3,
/gazebo/model_states following set_model_state, spawn and delete of URDF and SDF models with refusals
inside a wall, spawn_model's bad input with gazebo_ros' texts, and gzclient attaching to the view."""

from __future__ import annotations

import math
import os
import subprocess
import textwrap
import time
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest
from gazebo_helpers import Launched, genpy_gazebo_msgs

from ninjemys.idl.loader import get_message_class, get_service_class
from ninjemys.node import Node
from ninjemys.sim.worlds import ROBOTS_DIR
from ninjemys.testing import have_ros1, ninjemys_bin, ros1_env, run_master, wait_until

pytestmark = [pytest.mark.ros1, pytest.mark.skipif(not have_ros1(), reason="needs Debian's ROS 1")]

ModelStates = get_message_class("gazebo_msgs/ModelStates")
SpawnModel = get_service_class("gazebo_msgs/SpawnModel")
DeleteModel = get_service_class("gazebo_msgs/DeleteModel")
GetModelState = get_service_class("gazebo_msgs/GetModelState")
ApplyBodyWrench = get_service_class("gazebo_msgs/ApplyBodyWrench")
Clock = get_message_class("rosgraph_msgs/Clock")
URDF = (ROBOTS_DIR / "puzzlebot.urdf").read_text()
BOX_SDF = (
    '<sdf version="1.6"><model name="crate"><static>true</static><link name="link"><collision name="c">'
    "<geometry><box><size>0.6 0.6 0.5</size></box></geometry></collision></link></model></sdf>"
)


class Gazebo:
    def __init__(self, master: str, tmp: Path, launch: Launched, genpy: Path, client: Node) -> None:
        self.master, self.tmp, self.launch, self.genpy, self.client = master, tmp, launch, genpy, client

    def env(self) -> dict[str, str]:
        return dict(os.environ, ROS_MASTER_URI=self.master, PYTHONUNBUFFERED="1")

    def real_env(self) -> dict[str, str]:
        return ros1_env(self.master, PYTHONPATH=str(self.genpy))

    def real(self, *argv: str, timeout: float = 60) -> subprocess.CompletedProcess[str]:
        return subprocess.run(
            list(argv), env=self.real_env(), capture_output=True, text=True, timeout=timeout
        )

    def spawn_model(self, *args: str) -> subprocess.CompletedProcess[str]:
        return subprocess.run(
            [ninjemys_bin("rosrun"), "gazebo_ros", "spawn_model", *args],
            env=self.env(),
            capture_output=True,
            text=True,
            timeout=60,
        )

    def call(self, name: str, cls, **fields):  # type: ignore[no-untyped-def]
        self.client.wait_for_service(name, 10)
        req = cls._request_class()
        for k, v in fields.items():
            setattr(req, k, v)
        return self.client.service_proxy(name, cls)(req)

    def model_states(self) -> dict[str, tuple[float, float, float]]:
        got: list = []
        sub = self.client.subscriber("/gazebo/model_states", ModelStates, got.append, queue_size=1)
        try:
            wait_until(lambda: got, 10, "/gazebo/model_states")
        finally:
            sub.unregister()
        msg = got[-1]
        return {
            n: (p.position.x, p.position.y, 2 * math.atan2(p.orientation.z, p.orientation.w))
            for n, p in zip(msg.name, msg.pose, strict=True)
        }


@pytest.fixture(scope="module")
def gazebo(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Gazebo]:
    tmp = tmp_path_factory.mktemp("gazebo")
    genpy = genpy_gazebo_msgs(tmp / "genpy")
    with run_master() as master:
        env = dict(os.environ, ROS_MASTER_URI=master, PYTHONUNBUFFERED="1")
        launch = Launched(
            [ninjemys_bin("roslaunch"), "gazebo_ros", "empty_world.launch", "paused:=true", "gui:=false"],
            env,
            tmp / "launch.log",
        )
        client = Node("gazebo_test_client", anonymous=True, master_uri=master)
        try:
            launch.wait_for("physics paused")
            yield Gazebo(master, tmp, launch, genpy, client)
        finally:
            client.shutdown("test over")
            launch.stop()


def test_spawn_model_from_robot_description_then_unpause(gazebo: Gazebo) -> None:
    clock: list = []
    sub = gazebo.client.subscriber("/clock", Clock, clock.append, queue_size=1)
    time.sleep(0.5)
    assert not clock or clock[-1].clock.to_sec() == 0.0  # paused:=true: no time passes
    gazebo.client.set_param("/robot_description", URDF)
    out = gazebo.spawn_model(
        "-urdf", "-param", "robot_description", "-model", "puzzlebot", "-x", "0.5", "-y", "-0.25", "-Y", "0.3",
        "-J", "wheel_left_joint", "0.7", "-unpause",
    )  # fmt: skip
    assert out.returncode == 0, out.stdout + out.stderr
    for line in (
        "Loading model XML from ros parameter robot_description",
        "Waiting for service /gazebo/spawn_urdf_model",
        "Spawn status: SpawnModel: Successfully spawned entity",
        "Unpausing physics",
    ):
        assert line in out.stdout
    wait_until(lambda: clock and clock[-1].clock.to_sec() > 0.2, 15, "time running after -unpause")
    sub.unregister()
    # Debian's rostopic reads the robot's topics under the description's names
    scan = gazebo.real("/usr/bin/rostopic", "echo", "-n1", "/scan/angle_min")
    assert scan.returncode == 0 and float(scan.stdout.split()[0]) == pytest.approx(-math.pi), scan.stderr
    names = gazebo.real("/usr/bin/rostopic", "echo", "-n1", "/gazebo/model_states/name")
    assert "puzzlebot" in names.stdout, names.stderr
    x, y, yaw = gazebo.model_states()["puzzlebot"]
    assert (x, y, yaw) == pytest.approx((0.5, -0.25, 0.3), abs=1e-3)


def test_real_rosservice_and_rospy_move_a_model_and_model_states_follow(gazebo: Gazebo) -> None:
    out = gazebo.real(
        "/usr/bin/rosservice", "call", "/gazebo/set_model_state",
        "{model_state: {model_name: puzzlebot, pose: {position: {x: 2.0, y: -1.0}, orientation: {z: 0.7071068, w: 0.7071068}}}}",
    )  # fmt: skip
    assert out.returncode == 0, out.stderr
    assert "success: True" in out.stdout and "SetModelState: set model state done" in out.stdout
    x, y, yaw = gazebo.model_states()["puzzlebot"]
    assert (x, y, yaw) == pytest.approx((2.0, -1.0, math.pi / 2), abs=1e-3)
    script = textwrap.dedent(
        """
        import rospy
        from gazebo_msgs.srv import GetModelState, GetWorldProperties
        rospy.init_node("gazebo_probe", anonymous=True)
        rospy.wait_for_service("/gazebo/get_model_state", 10)
        state = rospy.ServiceProxy("/gazebo/get_model_state", GetModelState)("puzzlebot", "")
        world = rospy.ServiceProxy("/gazebo/get_world_properties", GetWorldProperties)()
        print(state.success, round(state.pose.position.x, 3), round(state.pose.position.y, 3), state.status_message)
        print(sorted(world.model_names), world.status_message)
        missing = rospy.ServiceProxy("/gazebo/get_model_state", GetModelState)("nobody", "")
        print(missing.success, missing.status_message)
        """
    )
    out = gazebo.real("/usr/bin/python3", "-c", script)
    assert out.returncode == 0, out.stderr
    lines = out.stdout.splitlines()
    assert lines[0] == "True 2.0 -1.0 GetModelState: got properties"
    # empty.world's ground plane is a model, listed first, as Gazebo lists it
    assert lines[1] == "['ground_plane', 'puzzlebot'] GetWorldProperties: got properties"
    assert lines[2] == "False GetModelState: model does not exist"
    # the topic form of set_model_state
    pub = gazebo.real(
        "/usr/bin/rostopic", "pub", "-1", "/gazebo/set_model_state", "gazebo_msgs/ModelState",
        "{model_name: puzzlebot, pose: {position: {x: -1.5, y: 0.5}, orientation: {w: 1.0}}}",
    )  # fmt: skip
    assert pub.returncode == 0, pub.stderr
    wait_until(lambda: abs(gazebo.model_states()["puzzlebot"][0] + 1.5) < 1e-3, 10, "moved by the topic")


def test_spawn_and_delete_sdf_and_urdf_models_refused_inside_a_wall(gazebo: Gazebo) -> None:
    box = gazebo.tmp / "crate.sdf"
    box.write_text(BOX_SDF)
    out = gazebo.spawn_model("-sdf", "-file", str(box), "-model", "crate", "-x", "3.0", "-y", "2.0")
    assert out.returncode == 0, out.stdout + out.stderr
    assert "Loading model XML from file" in out.stdout
    assert "crate" in gazebo.model_states()
    # a robot inside the crate, and a second crate inside the robot: both refused, clearly
    pose = SpawnModel._request_class().initial_pose
    pose.position.x, pose.position.y, pose.orientation.w = 3.0, 2.0, 1.0
    resp = gazebo.call(
        "/gazebo/spawn_urdf_model", SpawnModel, model_name="intruder", model_xml=URDF, initial_pose=pose
    )
    assert not resp.success and "inside 'crate'" in resp.status_message
    assert resp.status_message.startswith("SpawnModel: Failure - ")
    x, y, _ = gazebo.model_states()["puzzlebot"]
    pose.position.x, pose.position.y = x, y
    resp = gazebo.call(
        "/gazebo/spawn_sdf_model", SpawnModel, model_name="crate2", model_xml=BOX_SDF, initial_pose=pose
    )
    assert not resp.success and "overlap robot [puzzlebot]" in resp.status_message
    resp = gazebo.call(
        "/gazebo/spawn_sdf_model", SpawnModel, model_name="crate", model_xml=BOX_SDF, initial_pose=pose
    )
    assert (resp.success, resp.status_message) == (False, "SpawnModel: Failure - entity already exists.")
    # a second URDF robot, namespaced by spawn_model's -robot_namespace, then deleted
    out = gazebo.spawn_model(
        "-urdf",
        "-param",
        "robot_description",
        "-model",
        "guest",
        "-x",
        "-3",
        "-y",
        "-3",
        "-robot_namespace",
        "/guest",
    )
    assert out.returncode == 0, out.stdout + out.stderr
    topics = {t for t, _ in gazebo.client.master.get_published_topics("/")}
    assert "/guest/scan" in topics and "/guest/odom" in topics
    for name in ("guest", "crate"):
        resp = gazebo.call("/gazebo/delete_model", DeleteModel, model_name=name)
        assert (resp.success, resp.status_message) == (True, "DeleteModel: successfully deleted model")
    assert set(gazebo.model_states()) == {"ground_plane", "puzzlebot"}
    resp = gazebo.call("/gazebo/delete_model", DeleteModel, model_name="crate")
    assert not resp.success and resp.status_message.startswith("DeleteModel: model does not exist")


def test_apply_body_wrench_pushes_the_robot(gazebo: Gazebo) -> None:
    GetWorldProperties = get_service_class("gazebo_msgs/GetWorldProperties")

    def sim_time() -> float:
        return float(gazebo.call("/gazebo/get_world_properties", GetWorldProperties).sim_time)

    x0, y0, _ = gazebo.model_states()["puzzlebot"]
    start = sim_time()
    req = ApplyBodyWrench._request_class()
    req.wrench.force.y = 4.0
    req.duration.secs = 1
    resp = gazebo.call(
        "/gazebo/apply_body_wrench", ApplyBodyWrench, body_name="puzzlebot::base_link", wrench=req.wrench,
        duration=req.duration,
    )  # fmt: skip
    assert resp.success, resp.status_message
    wait_until(lambda: gazebo.model_states()["puzzlebot"][1] > y0 + 0.5, 20, "pushed along +y")
    # the push lasts a second of sim time: waited for on sim time (a loaded simulator runs slower than
    # the wall clock, and half a second of it could end before the push did)
    wait_until(lambda: sim_time() > start + 1.0 + 0.5, 60, "the push's second of sim time over")
    y1 = gazebo.model_states()["puzzlebot"][1]
    then = sim_time()
    wait_until(lambda: sim_time() > then + 0.5, 60, "half a second more of sim time")
    assert gazebo.model_states()["puzzlebot"][1] == pytest.approx(y1, abs=1e-3)  # the push ended: it stopped
    resp = gazebo.call("/gazebo/apply_body_wrench", ApplyBodyWrench, body_name="nobody::link")
    assert (resp.success, resp.status_message) == (False, "ApplyBodyWrench: body does not exist")


def test_spawn_model_bad_input_gives_gazebo_ros_texts(gazebo: Gazebo) -> None:
    out = gazebo.spawn_model("-urdf", "-param", "no_such_description", "-model", "x")
    assert out.returncode == 1 and "Error: param does not exist or is empty" in out.stdout + out.stderr
    out = gazebo.spawn_model("-urdf", "-param", "robot_description")
    assert out.returncode == 2 and "the following arguments are required: -model" in out.stderr
    out = gazebo.spawn_model("-param", "robot_description", "-model", "x")
    assert out.returncode == 2 and "one of the arguments -urdf -sdf is required" in out.stderr
    out = gazebo.spawn_model("-sdf", "-file", "/no/such.sdf", "-model", "x")
    assert (
        out.returncode == 1 and "Error: specified file /no/such.sdf does not exist" in out.stdout + out.stderr
    )
    bad = gazebo.tmp / "bad.urdf"
    bad.write_text("<robot name='x'><link name='a'>")
    out = gazebo.spawn_model("-urdf", "-file", str(bad), "-model", "x")
    assert out.returncode == 1 and "Invalid XML: " in out.stdout + out.stderr
    # a joint naming a link that is not there (a xacro's unexpanded macro): urdfdom refuses the URDF,
    # and with it Gazebo; ours said nothing and spawned a plain box
    missing = gazebo.tmp / "missing_link.urdf"
    missing.write_text(
        "<robot name='m'><link name='base_link'><collision><geometry><box size='0.2 0.2 0.1'/></geometry>"
        "</collision></link><mrobot_body/><joint name='rplidar_joint' type='fixed'>"
        "<parent link='plate_2_link'/><child link='base_link'/></joint></robot>"
    )
    out = gazebo.spawn_model("-urdf", "-file", str(missing), "-model", "mrobot")
    assert out.returncode == 1, out.stdout + out.stderr
    assert (
        "Spawn status: SpawnModel: Failure - model_xml: Failed to build tree: parent link [plate_2_link] of"
        " joint [rplidar_joint] not found.  This is not valid according to the URDF spec." in out.stdout
    )
    assert "mrobot" not in gazebo.model_states()
    out = gazebo.spawn_model("-urdf", "-param", "robot_description", "-model", "puzzlebot")
    assert out.returncode == 1
    assert "Spawn status: SpawnModel: Failure - entity already exists." in out.stdout
    assert "Spawn service failed. Exiting." in out.stdout + out.stderr
    assert gazebo.launch.proc.poll() is None  # nothing crashed the simulator


def test_gzclient_attaches_to_the_servers_view(gazebo: Gazebo) -> None:
    env = {k: v for k, v in gazebo.env().items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    client = Launched([ninjemys_bin("gzclient")], env, gazebo.tmp / "gzclient.log")
    try:
        out = client.wait_for("gzclient: simulator view http://")
        assert "/puzzlebot" in out
    finally:
        client.stop()


def test_spawn_model_wait_and_bond(gazebo: Gazebo) -> None:
    """-wait MODEL spawns once MODEL is in model_states; -b deletes the model again on Ctrl-C."""
    box = gazebo.tmp / "bonded.sdf"
    box.write_text(BOX_SDF)
    out = gazebo.spawn_model(
        "-sdf", "-file", str(box), "-model", "early", "-x", "4", "-y", "-4", "-wait", "puzzlebot"
    )
    assert out.returncode == 0, out.stdout + out.stderr
    assert "Waiting for model puzzlebot before proceeding." in out.stdout
    assert gazebo.call("/gazebo/delete_model", DeleteModel, model_name="early").success
    bonded = Launched(
        [ninjemys_bin("rosrun"), "gazebo_ros", "spawn_model", "-sdf", "-file", str(box), "-model", "bonded",
         "-x", "-4", "-y", "4", "-b"],
        gazebo.env(),
        gazebo.tmp / "bonded.log",
    )  # fmt: skip
    try:
        bonded.wait_for("Waiting for shutdown to delete model bonded")
        assert "bonded" in gazebo.model_states()
    finally:
        bonded.stop()
    assert "Deleting model bonded" in bonded.log()
    assert "bonded" not in gazebo.model_states()


@pytest.mark.parametrize("args", [(), ("gui:=false",), ("use_clock_frequency:=true", "paused:=true")])
def test_debian_roslaunch_reads_empty_world_launch_as_ours_does(args: tuple[str, ...]) -> None:
    """The same nodes and parameters from Debian's roslaunch and ours (the file is plain roslaunch XML)."""
    from ninjemys.sim.gazebo_worlds import GAZEBO_ROS_SHARE

    launch = str(GAZEBO_ROS_SHARE / "launch" / "empty_world.launch")
    env = ros1_env("http://localhost:1", ROS_PACKAGE_PATH=str(GAZEBO_ROS_SHARE.parent))
    for flag in ("--nodes", "--dump-params"):
        real = subprocess.run(
            ["/usr/bin/roslaunch", flag, launch, *args], env=env, capture_output=True, text=True
        )
        ours = subprocess.run(
            [ninjemys_bin("roslaunch"), flag, launch, *args], capture_output=True, text=True
        )
        assert real.returncode == 0 and ours.returncode == 0, real.stderr + ours.stderr
        assert sorted(ours.stdout.splitlines()) == sorted(real.stdout.splitlines()), flag


SQUARE = """
import math, sys
import rospy
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from gazebo_msgs.msg import ModelStates

rospy.init_node("square_driver")
state = {}
rospy.Subscriber("/odom", Odometry, lambda m: state.__setitem__("odom", m))
pub = rospy.Publisher("/cmd_vel", Twist, queue_size=1)
rate = rospy.Rate(50)
while "odom" not in state and not rospy.is_shutdown():
    rate.sleep()

def pose():
    p = state["odom"].pose.pose
    return p.position.x, p.position.y, 2 * math.atan2(p.orientation.z, p.orientation.w)

def drive(v, w, done):
    cmd = Twist()
    cmd.linear.x, cmd.angular.z = v, w
    while not rospy.is_shutdown() and not done():
        pub.publish(cmd)
        rate.sleep()

for side in range(4):
    x0, y0, th0 = pose()
    drive(0.3, 0.0, lambda: math.hypot(pose()[0] - x0, pose()[1] - y0) >= 1.0)
    target = th0 + math.pi / 2
    drive(0.0, 0.8, lambda: math.atan2(math.sin(target - pose()[2]), math.cos(target - pose()[2])) <= 0.0)
drive(0.0, 0.0, lambda: True)
for _ in range(10):
    pub.publish(Twist())
    rate.sleep()
truth = rospy.wait_for_message("/gazebo/model_states", ModelStates, 10)
p = truth.pose[truth.name.index("puzzlebot")]
yaw = 2 * math.atan2(p.orientation.z, p.orientation.w)
print("final %.4f %.4f %.4f" % (p.position.x, p.position.y, math.atan2(math.sin(yaw), math.cos(yaw))))
"""


def test_a_real_rospy_controller_drives_a_square_checked_against_model_states(gazebo: Gazebo) -> None:
    """Debian's rospy drives a 1 m square on cmd_vel from odom feedback, on sim time at twice real
    time (set_physics_properties' max_update_rate); the end pose is read from /gazebo/model_states."""
    SetModelState = get_service_class("gazebo_msgs/SetModelState")
    SetPhysicsProperties = get_service_class("gazebo_msgs/SetPhysicsProperties")
    state = SetModelState._request_class().model_state
    state.model_name, state.pose.orientation.w = "puzzlebot", 1.0
    GetWorldProperties = get_service_class("gazebo_msgs/GetWorldProperties")
    # run alone: spawn it (the first test does otherwise); asked by service, which answers while paused
    if "puzzlebot" not in gazebo.call("/gazebo/get_world_properties", GetWorldProperties).model_names:
        gazebo.client.set_param("/robot_description", URDF)
        out = gazebo.spawn_model("-urdf", "-param", "robot_description", "-model", "puzzlebot", "-unpause")
        assert out.returncode == 0, out.stdout + out.stderr
    resp = gazebo.call("/gazebo/set_model_state", SetModelState, model_state=state)
    assert resp.success, resp.status_message
    resp = gazebo.call("/gazebo/set_physics_properties", SetPhysicsProperties, max_update_rate=200.0)
    assert (resp.success, resp.status_message) == (True, "physics engine updated")
    GetPhysicsProperties = get_service_class("gazebo_msgs/GetPhysicsProperties")
    assert gazebo.call("/gazebo/get_physics_properties", GetPhysicsProperties).max_update_rate == 200.0
    try:
        out = gazebo.real("/usr/bin/python3", "-c", SQUARE, timeout=180)
    finally:
        gazebo.call("/gazebo/set_physics_properties", SetPhysicsProperties, max_update_rate=100.0)
    assert out.returncode == 0, out.stderr
    x, y, yaw = (float(v) for v in out.stdout.split("final")[1].split())
    error = math.hypot(x, y)
    print(f"1 m square: end position error {error:.3f} m, heading error {abs(yaw):.3f} rad")
    # the controller reacts in wall time: on a loaded machine a corner costs a few cm (0.125 m at load 17)
    assert error < 0.3 and abs(yaw) < 0.3


def test_set_physics_properties_takes_another_time_step(gazebo: Gazebo) -> None:
    """A time_step other than ours is taken, as Gazebo does: get_physics_properties reports it,
    /clock goes on from where it was in steps of that size, and a step out of range is refused."""
    SetPhysicsProperties = get_service_class("gazebo_msgs/SetPhysicsProperties")
    GetPhysicsProperties = get_service_class("gazebo_msgs/GetPhysicsProperties")
    Unpause = get_service_class("std_srvs/Empty")
    gazebo.call("/gazebo/unpause_physics", Unpause)
    stamps: list[int] = []
    sub = gazebo.client.subscriber(
        "/clock", Clock, lambda m: stamps.append(m.clock.to_nsec()), queue_size=1000
    )
    try:
        resp = gazebo.call(
            "/gazebo/set_physics_properties", SetPhysicsProperties, time_step=0.002, max_update_rate=500.0
        )
        assert (resp.success, resp.status_message) == (True, "physics engine updated")
        props = gazebo.call("/gazebo/get_physics_properties", GetPhysicsProperties)
        assert props.time_step == 0.002 and props.max_update_rate == 500.0
        before = len(stamps)
        wait_until(lambda: len(stamps) > before + 50, 30, "/clock in 2 ms steps")
        steps = np.diff(np.array(stamps[before + 1 :]))
        assert (steps > 0).all()  # time went on, never back
        assert np.median(steps) == 2_000_000  # /clock every step: 2 ms apart
        bad = gazebo.call("/gazebo/set_physics_properties", SetPhysicsProperties, time_step=0.5)
        assert not bad.success and "time_step 0.5 must be in (0, 0.1]" in bad.status_message
    finally:
        sub.unregister()
        gazebo.call(
            "/gazebo/set_physics_properties", SetPhysicsProperties, time_step=0.01, max_update_rate=100.0
        )
    assert gazebo.call("/gazebo/get_physics_properties", GetPhysicsProperties).time_step == 0.01


def test_spawn_model_database_puts_a_shipped_model_in(gazebo: Gazebo) -> None:
    """``spawn_model -sdf -database unit_cylinder``: the shipped model, at the spawn pose, in
    model_states; deleted again by name."""
    # model_states goes out as the world steps (Gazebo's world update), not while physics is paused
    gazebo.call("/gazebo/unpause_physics", get_service_class("std_srvs/Empty"))
    out = gazebo.spawn_model("-sdf", "-database", "unit_cylinder", "-model", "pillar", "-x", "-4", "-y", "3")
    assert out.returncode == 0, out.stdout + out.stderr
    assert gazebo.model_states()["pillar"][:2] == pytest.approx((-4.0, 3.0), abs=1e-6)
    resp = gazebo.call("/gazebo/delete_model", DeleteModel, model_name="pillar")
    assert resp.success, resp.status_message
    assert "pillar" not in gazebo.model_states()
    out = gazebo.spawn_model("-sdf", "-database", "no_such_model", "-model", "ghost")
    assert out.returncode == 1 and "no_such_model" in out.stdout + out.stderr
