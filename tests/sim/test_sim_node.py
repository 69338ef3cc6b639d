"""sim_node as a process on our master: topics and namespaces, sim time at a factor, rospy.Rate in a
user node, services, spawn refusals, bad input. The simulations run on sim time, faster than real time."""

from __future__ import annotations

import math
import os
import subprocess
import sys
import textwrap
import threading
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from ninjemys.packages.shipped import shipped_executable
from ninjemys.sim.worlds import WORLDS_DIR
from ninjemys.testing import NodeProcess, run_master, wait_until


class SimProcess(NodeProcess):
    """A running sim_node (stderr merged into stdout); ``log()`` is everything it printed so far."""

    def log(self) -> str:
        return self.text()

    def wait_for_log(self, text: str, timeout: float = 20.0) -> str:
        """The output so far, once it contains ``text`` (fails the test if it never does)."""
        self.wait_for(lambda _line: text in self.text(), timeout)
        return self.text()


def start_sim(master: str, tmp_path: Path, *params: str, wait: bool = True) -> SimProcess:
    env = dict(os.environ, ROS_MASTER_URI=master, PYTHONUNBUFFERED="1")
    cmd = shipped_executable("puzzlebot_sim", "sim_node").command([*params, "_gui:=false"])
    sim = SimProcess(cmd, env=env, cwd=tmp_path, merge_stderr=True)
    if wait:
        try:
            sim.wait_for_log("PuzzleBot simulator:")
        except BaseException:
            sim.stop()
            raise
    return sim


@pytest.fixture
def master() -> Iterator[str]:
    with run_master() as uri:
        yield uri


@pytest.fixture
def sims(master: str, tmp_path: Path) -> Iterator:
    started: list[SimProcess] = []

    def start(*params: str, wait: bool = True) -> SimProcess:
        s = start_sim(master, tmp_path, *params, wait=wait)
        started.append(s)
        return s

    try:
        yield start
    finally:
        for s in started:
            s.stop()


@pytest.fixture
def client(master: str):  # type: ignore[no-untyped-def]
    from ninjemys.node import Node

    node = Node("sim_test_client", anonymous=True, master_uri=master)
    try:
        yield node
    finally:
        node.shutdown("test over")


class Latest:
    """The newest message of a topic, with a count."""

    def __init__(self, node, topic: str, msg_class) -> None:  # type: ignore[no-untyped-def]
        self.msg = None
        self.count = 0
        self._lock = threading.Lock()
        self.sub = node.subscriber(topic, msg_class, self._on, queue_size=10)

    def _on(self, msg) -> None:  # type: ignore[no-untyped-def]
        with self._lock:
            self.msg = msg
            self.count += 1

    def wait(self, timeout: float = 15.0, what: str = "a message"):  # type: ignore[no-untyped-def]
        return wait_until(lambda: self.msg, timeout, what)


def test_two_robots_in_namespaces(sims, client, master):
    from geometry_msgs.msg import Twist
    from nav_msgs.msg import Odometry
    from sensor_msgs.msg import LaserScan

    sims(f"_world:={WORLDS_DIR / 'two_robots.yaml'}", "_rate:=4.0")
    topics = {t for t, _ in client.master.get_published_topics("/")}
    for ns in ("/robot1", "/robot2"):
        assert {
            f"{ns}/odom",
            f"{ns}/scan",
            f"{ns}/wl",
            f"{ns}/wr",
            f"{ns}/camera/color/image_raw",
            f"{ns}/imu",
        } <= topics
    assert "/scan" not in topics and "/odom" not in topics
    scan1 = Latest(client, "/robot1/scan", LaserScan)
    scan2 = Latest(client, "/robot2/scan", LaserScan)
    gt1 = Latest(client, "/robot1/base_pose_ground_truth", Odometry)
    gt2 = Latest(client, "/robot2/base_pose_ground_truth", Odometry)
    odom1 = Latest(client, "/robot1/odom", Odometry)
    s1, s2 = scan1.wait(), scan2.wait()
    assert s1.header.frame_id == "robot1/laser" and s2.header.frame_id == "robot2/laser"
    # facing each other 2 m apart: the forward beam sees the other robot's body (radius 0.11)
    assert s1.ranges[180] == pytest.approx(1.89, abs=0.05)
    assert s2.ranges[180] == pytest.approx(1.89, abs=0.05)
    assert odom1.wait().header.frame_id == "robot1/odom" and odom1.msg.child_frame_id == "robot1/base_link"
    start2 = gt2.wait().pose.pose.position.x
    pub = client.publisher("/robot1/cmd_vel", Twist, queue_size=1)
    wait_until(lambda: pub.get_num_connections(), what="sim subscribed to /robot1/cmd_vel")
    twist = Twist()
    twist.linear.x = 0.3
    pub.publish(twist)
    wait_until(lambda: gt1.msg and gt1.msg.pose.pose.position.x > -0.8, what="robot1 moving")
    assert gt2.msg.pose.pose.position.x == pytest.approx(start2, abs=1e-6)  # robot2 did not hear it


def test_sim_time_factor_and_rospy_rate_follow_it(sims, master, tmp_path, client):
    sim = sims("_world:=empty", "_rate:=3.0")
    assert client.get_param("/use_sim_time") is True  # set by the simulator when nobody had
    assert "/use_sim_time was not set" in sim.log()
    script = tmp_path / "rate_user.py"
    script.write_text(
        textwrap.dedent(
            """
            import time
            import rospy
            rospy.init_node("rate_user")
            while rospy.get_time() == 0.0:
                time.sleep(0.01)
            rate = rospy.Rate(10)
            t0, w0 = rospy.get_time(), time.monotonic()
            for _ in range(30):
                rate.sleep()
            print("SIM %.3f WALL %.3f" % (rospy.get_time() - t0, time.monotonic() - w0), flush=True)
            """
        )
    )
    done = subprocess.run(
        [sys.executable, str(script)],
        env=dict(os.environ, ROS_MASTER_URI=master),
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert done.returncode == 0, done.stderr
    words = done.stdout.split()
    sim_elapsed, wall_elapsed = float(words[1]), float(words[3])
    # 30 periods of 0.1 s of *simulated* time, at 3x: about 1 s of wall time
    assert sim_elapsed == pytest.approx(3.0, abs=0.11)
    # paced at 3x: never faster than asked (the pacing), faster than real time (how much depends on
    # the CPU the simulator gets: a CI run with both cores busy got under 1.2x)
    assert 1.0 < sim_elapsed / wall_elapsed < 3.3


def test_services_pause_reset_spawn_delete(sims, client):
    from gazebo_msgs.srv import DeleteModel, GetWorldProperties, SpawnModel
    from rosgraph_msgs.msg import Clock
    from std_srvs.srv import Empty

    sim = sims("_world:=office", "_rate:=5.0")
    # /clock is judged in its callback, on every message in order, not by polling the latest: at 5x
    # real time the clock climbed back past the pause's time after the reset before a loaded poll
    # looked (20 s of "time back near 0" timed out at load 12); and the pause's time is the world's,
    # not the newest /clock received 0.3 s later (a loaded machine may still be delivering older ones)
    paused_at: list[float] = []
    newest, ran_on, back = [0.0], threading.Event(), threading.Event()

    def on_clock(msg) -> None:  # type: ignore[no-untyped-def]
        newest[0] = t = msg.clock.to_sec()
        if paused_at and t > paused_at[0] + 1e-6:  # (the world's float time vs. /clock's nanoseconds)
            ran_on.set()
        elif ran_on.is_set() and t < paused_at[0]:
            back.set()

    client.subscriber("/clock", Clock, on_clock, queue_size=1000)

    def call(name, cls, **fields):  # type: ignore[no-untyped-def]
        client.wait_for_service(name, 10)
        proxy = client.service_proxy(name, cls)
        req = cls._request_class()
        for k, v in fields.items():
            setattr(req, k, v)
        return proxy(req)

    wait_until(lambda: newest[0] > 0.0, what="/clock in the test's callback")
    call("/gazebo/pause_physics", Empty)
    t_paused = call("/gazebo/get_world_properties", GetWorldProperties).sim_time
    time.sleep(0.5)  # paused: nothing moves meanwhile
    assert call("/gazebo/get_world_properties", GetWorldProperties).sim_time == t_paused
    assert newest[0] <= t_paused + 1e-6
    paused_at.append(t_paused)
    call("/gazebo/unpause_physics", Empty)
    assert ran_on.wait(20.0), "no /clock past the pause's time after unpause_physics"
    call("/gazebo/reset_simulation", Empty)
    assert back.wait(20.0), "no /clock back below the pause's time after reset_simulation"

    req = SpawnModel._request_class()
    req.model_name = "intruder"
    req.initial_pose.position.x, req.initial_pose.position.y = -1.2, 3.8  # inside desk_1
    resp = call("/gazebo/spawn_urdf_model", SpawnModel, model_name="intruder", initial_pose=req.initial_pose)
    assert not resp.success and "inside 'desk_1'" in resp.status_message
    sim.wait_for_log("spawn refused: cannot spawn [intruder]")
    req.initial_pose.position.x, req.initial_pose.position.y = 0.5, -0.5
    resp = call("/gazebo/spawn_urdf_model", SpawnModel, model_name="guest", initial_pose=req.initial_pose)
    assert resp.success, resp.status_message
    topics = {t for t, _ in client.master.get_published_topics("/")}
    assert "/guest/scan" in topics and "/scan" in topics
    box = '<sdf version="1.6"><model name="crate"><link name="l"><collision name="c"><geometry><box><size>0.4 0.4 0.5</size></box></geometry></collision></link></model></sdf>'
    req.initial_pose.position.x, req.initial_pose.position.y = 2.0, 0.0
    resp = call(
        "/gazebo/spawn_sdf_model",
        SpawnModel,
        model_name="crate",
        model_xml=box,
        initial_pose=req.initial_pose,
    )
    assert resp.success, resp.status_message
    assert call("/gazebo/delete_model", DeleteModel, model_name="crate").success
    assert call("/gazebo/delete_model", DeleteModel, model_name="guest").success
    wait_until(
        lambda: "/guest/scan" not in {t for t, _ in client.master.get_published_topics("/")},
        what="guest topics gone",
    )
    gone = call("/gazebo/delete_model", DeleteModel, model_name="crate")
    assert (
        not gone.success
        and "no model named [crate]" in gone.status_message
        and gone.status_message.startswith("DeleteModel: model does not exist")
    )


def test_non_finite_cmd_vel_ignored_with_one_warning(sims, client):
    from geometry_msgs.msg import Twist
    from nav_msgs.msg import Odometry

    sim = sims("_world:=square", "_rate:=4.0")
    gt = Latest(client, "/base_pose_ground_truth", Odometry)
    gt.wait()
    pub = client.publisher("/cmd_vel", Twist, queue_size=10)
    wait_until(lambda: pub.get_num_connections(), what="sim subscribed to /cmd_vel")
    for value in (math.nan, math.inf, -math.inf):
        bad = Twist()
        bad.linear.x = value
        pub.publish(bad)
        time.sleep(0.1)
    sim.wait_for_log("ignoring a command with a non-finite value")
    time.sleep(0.3)
    assert sim.log().count("non-finite") == 1
    assert gt.msg.pose.pose.position.x == 0.0
    good = Twist()
    good.angular.z = 0.5
    pub.publish(good)
    wait_until(
        lambda: abs(gt.msg.pose.pose.orientation.z) > 0.05, what="the robot turning after a valid command"
    )
    assert sim.proc.poll() is None


@pytest.mark.parametrize(
    ("content", "expected"),
    [
        (
            "walls:\n  - {from: [0, 0], to: [1, 0], height: tall}\n",
            "bad.yaml:2: walls[0].height: expected a number, got 'tall'",
        ),
        ("walls: [\n", "bad.yaml:2: invalid YAML"),
    ],
)
def test_malformed_world_fails_with_file_line_field(sims, tmp_path, content, expected):
    bad = tmp_path / "bad.yaml"
    bad.write_text(content)
    sim = sims(f"_world:={bad}", wait=False)
    assert sim.wait(30) == 1
    assert expected in sim.log()
    assert "Traceback" not in sim.log()


def test_map_argument_uses_a_map_server_map(sims, client):
    from ninjemys.sim.worlds import map_path
    from sensor_msgs.msg import LaserScan

    sims(f"_map:={map_path('maze')}", "_rate:=4.0")
    scan = Latest(client, "/scan", LaserScan).wait()
    finite = [r for r in scan.ranges if math.isfinite(r)]
    assert len(finite) == 360 and min(finite) > 0.15 and max(finite) < 6.0  # walls all around in the maze


def test_roslaunch_puzzlebot_launch_sets_pose_and_sim_time(master, client, tmp_path):
    from nav_msgs.msg import Odometry
    from ninjemys.testing import ninjemys_bin

    log = tmp_path / "launch.log"
    with open(log, "wb") as out:
        proc = subprocess.Popen(
            [
                ninjemys_bin("roslaunch"),
                "puzzlebot_sim",
                "puzzlebot.launch",
                "world:=maze",
                "gui:=false",
                "rate:=3",
                "x:=1",
                "y:=2",
                "yaw:=1.5708",
            ],
            env=dict(os.environ, ROS_MASTER_URI=master),
            stdout=out,
            stderr=subprocess.STDOUT,
            stdin=subprocess.DEVNULL,
        )
    try:
        gt = Latest(client, "/base_pose_ground_truth", Odometry).wait(30)
        p = gt.pose.pose
        assert (p.position.x, p.position.y) == pytest.approx((1.0, 2.0))
        assert 2 * math.atan2(p.orientation.z, p.orientation.w) == pytest.approx(1.5708, abs=1e-4)
        assert client.get_param("/use_sim_time") is True
        assert "world 'maze'" in log.read_text()
    finally:
        proc.send_signal(2)
        try:
            proc.wait(15)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()


def test_as_fast_as_possible_still_answers(sims, client):
    """rate 0: time runs flat out, yet commands and services get through between steps."""
    from geometry_msgs.msg import Twist
    from nav_msgs.msg import Odometry
    from rosgraph_msgs.msg import Clock
    from std_srvs.srv import Empty

    sim = sims("_world:=empty", "_rate:=0")
    clock = Latest(client, "/clock", Clock)
    gt = Latest(client, "/base_pose_ground_truth", Odometry)
    gt.wait()
    first = clock.wait().clock.to_sec()
    w0 = time.monotonic()
    pub = client.publisher("/cmd_vel", Twist, queue_size=1)
    wait_until(lambda: pub.get_num_connections(), what="sim subscribed to /cmd_vel")
    twist = Twist()
    twist.linear.x = 0.2
    pub.publish(twist)
    wait_until(lambda: gt.msg.pose.pose.position.x > 0.5, what="the robot moving")
    client.wait_for_service("/gazebo/reset_world", 10)
    client.service_proxy("/gazebo/reset_world", Empty)(Empty._request_class())
    elapsed_sim = clock.msg.clock.to_sec() - first
    assert elapsed_sim > 2 * (time.monotonic() - w0)  # faster than real time
    sim.stop()
    assert "simulated s per CPU s" in sim.log()  # the exit summary says how fast it ran


def test_scan_topic_matches_a_wall_in_a_generated_map(sims, client, tmp_path):
    """/scan over ROS against a map_server map made here: a wall face at x = 1.5 m, robot turned 0.4 rad."""
    from sensor_msgs.msg import LaserScan

    res, n = 0.05, 160  # an 8 x 8 m map, origin (-4, -4)
    img = bytearray([254]) * (n * n)
    for row in range(n):
        for col in range(round((1.5 + 4) / res), round((1.5 + 4) / res) + 4):
            img[row * n + col] = 0
    (tmp_path / "wall.pgm").write_bytes(f"P5\n{n} {n}\n255\n".encode() + bytes(img))
    (tmp_path / "wall.yaml").write_text(
        "image: wall.pgm\nresolution: 0.05\norigin: [-4.0, -4.0, 0.0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n"
    )
    sims(f"_map:={tmp_path / 'wall.yaml'}", "_yaw:=0.4", "_rate:=4.0")
    scan = Latest(client, "/scan", LaserScan).wait()
    assert scan.header.frame_id == "laser" and len(scan.ranges) == 360
    checked = 0
    for i, measured in enumerate(scan.ranges):
        world_angle = 0.4 + scan.angle_min + i * scan.angle_increment
        if math.cos(world_angle) > 0.2 and abs(1.5 * math.tan(world_angle)) < 3.9:
            assert measured == pytest.approx(1.5 / math.cos(world_angle), abs=0.05)  # 5 sigma of 0.01 m
            checked += 1
        elif math.cos(world_angle) < -0.05:
            assert math.isinf(measured) and measured > 0  # nothing behind within 12 m: +inf (REP 117)
    assert checked > 100


def test_camera_offers_compressed_subtopic(sims, client):
    """image_transport's ``camera/color/image_raw/compressed``: JPEG by default, PNG by parameter,
    the same pixels as the raw image (PNG exactly)."""
    import numpy as np

    from ninjemys.cv_bridge import CvBridge
    from sensor_msgs.msg import CompressedImage, Image

    client.set_param("/camera/color/image_raw/compressed/format", "png")
    sims("_world:=office", "_rate:=2.0")
    comp = Latest(client, "/camera/color/image_raw/compressed", CompressedImage)
    c = comp.wait(what="a compressed camera frame")
    assert c.format == "rgb8; png compressed bgr8" and c.header.frame_id.endswith(
        "camera_color_optical_frame"
    )
    raw = Latest(client, "/camera/color/image_raw", Image)
    r = raw.wait(what="a raw camera frame")
    bridge = CvBridge()
    decoded = bridge.compressed_imgmsg_to_cv2(c, "rgb8")
    assert decoded.shape == (r.height, r.width, 3) and decoded.std() > 0  # a real scene, not blank
    # the same frame on both topics (matched by stamp) has the same pixels
    by_stamp: dict = {}
    client.subscriber(
        "/camera/color/image_raw",
        Image,
        lambda m: by_stamp.setdefault(m.header.stamp, [None, None]).__setitem__(0, m),
    )
    client.subscriber(
        "/camera/color/image_raw/compressed",
        CompressedImage,
        lambda m: by_stamp.setdefault(m.header.stamp, [None, None]).__setitem__(1, m),
    )
    pair = wait_until(
        lambda: next((p for p in list(by_stamp.values()) if None not in p), None), what="one frame on both"
    )
    assert np.array_equal(bridge.compressed_imgmsg_to_cv2(pair[1], "rgb8"), bridge.imgmsg_to_cv2(pair[0]))
