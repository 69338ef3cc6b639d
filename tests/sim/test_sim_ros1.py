"""Debian's real ROS 1 drives the simulator: /usr/bin/rostopic, /usr/bin/rosservice and a rospy node
under /usr/bin/python3 read its sensors and move the robot (sim time throughout)."""

from __future__ import annotations

import os
import subprocess
import textwrap
import time
from pathlib import Path

import pytest

from ninjemys.packages.shipped import shipped_executable
from ninjemys.testing import have_ros1, ros1_env, run_master

pytestmark = [pytest.mark.ros1, pytest.mark.skipif(not have_ros1(), reason="needs Debian's ROS 1")]


@pytest.fixture
def sim(tmp_path: Path):  # type: ignore[no-untyped-def]
    with run_master() as master:
        log = tmp_path / "sim.log"
        cmd = shipped_executable("puzzlebot_sim", "sim_node").command(
            ["_world:=square", "_rate:=2.0", "_gui:=false"]
        )
        with open(log, "wb") as out:
            proc = subprocess.Popen(
                cmd, env=dict(os.environ, ROS_MASTER_URI=master), stdout=out, stderr=subprocess.STDOUT
            )
        try:
            deadline = time.monotonic() + 20
            while "PuzzleBot simulator:" not in log.read_text():
                assert proc.poll() is None and time.monotonic() < deadline, log.read_text()
                time.sleep(0.05)
            yield master
        finally:
            proc.terminate()
            try:
                proc.wait(10)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()


def real(master: str, *argv: str, timeout: float = 30) -> subprocess.CompletedProcess[str]:
    return subprocess.run(list(argv), env=ros1_env(master), capture_output=True, text=True, timeout=timeout)


def test_real_rostopic_and_rosservice(sim):
    scan = real(sim, "/usr/bin/rostopic", "echo", "-n1", "/scan/range_max")
    assert scan.returncode == 0, scan.stderr
    assert scan.stdout.split()[0] == "12.0"
    info = real(sim, "/usr/bin/rostopic", "echo", "-n1", "/camera/color/camera_info/width")
    assert info.stdout.split()[0] == "320"
    pub = real(sim, "/usr/bin/rostopic", "pub", "-1", "/cmd_vel", "geometry_msgs/Twist", "{linear: {x: 0.2}}")
    assert pub.returncode == 0, pub.stderr
    deadline = time.monotonic() + 20
    x = 0.0
    while time.monotonic() < deadline and x < 0.05:
        out = real(sim, "/usr/bin/rostopic", "echo", "-n1", "/base_pose_ground_truth/pose/pose/position/x")
        x = float(out.stdout.split()[0])
    assert x > 0.05
    reset = real(sim, "/usr/bin/rosservice", "call", "/gazebo/reset_world")
    assert reset.returncode == 0, reset.stderr
    out = real(sim, "/usr/bin/rostopic", "echo", "-n1", "/base_pose_ground_truth/pose/pose/position/x")
    assert abs(float(out.stdout.split()[0])) < 0.05
    types = real(sim, "/usr/bin/rosservice", "type", "/gazebo/pause_physics")
    assert types.stdout.strip() == "std_srvs/Empty"


def test_real_tf2_sees_the_robot_frames(sim, tmp_path):
    script = tmp_path / "tf_user.py"
    script.write_text(
        textwrap.dedent(
            """
            import rospy
            import tf2_ros

            rospy.init_node("tf_user")
            buf = tf2_ros.Buffer()
            tf2_ros.TransformListener(buf)
            for target, source in (("odom", "laser"), ("base_link", "camera_color_optical_frame"), ("odom", "imu_link")):
                t = buf.lookup_transform(target, source, rospy.Time(0), rospy.Duration(20))
                tr = t.transform.translation
                print(target, source, "%.3f %.3f %.3f" % (tr.x, tr.y, tr.z), flush=True)
            """
        )
    )
    done = real(sim, "/usr/bin/python3", str(script), timeout=90)
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert lines[0] == "odom laser 0.000 0.000 0.170"
    assert lines[1] == "base_link camera_color_optical_frame 0.080 0.000 0.120"
    assert lines[2] == "odom imu_link 0.000 0.000 0.050"


def test_real_rospy_node_drives_the_robot(sim, tmp_path):
    script = tmp_path / "driver.py"
    script.write_text(
        textwrap.dedent(
            """
            import rospy
            from geometry_msgs.msg import Twist
            from nav_msgs.msg import Odometry
            from sensor_msgs.msg import LaserScan, Image
            from std_msgs.msg import Float32

            rospy.init_node("real_driver")
            assert rospy.get_param("/use_sim_time") is True
            got = {}
            rospy.Subscriber("odom", Odometry, lambda m: got.__setitem__("odom", m))
            rospy.Subscriber("wr", Float32, lambda m: got.__setitem__("wr", m.data))
            scan = rospy.wait_for_message("scan", LaserScan, timeout=20)
            depth = rospy.wait_for_message("camera/depth/image_rect_raw", Image, timeout=20)
            pub = rospy.Publisher("cmd_vel", Twist, queue_size=1)
            rate = rospy.Rate(10)
            t0 = rospy.get_time()
            while rospy.get_time() - t0 < 2.0 and not rospy.is_shutdown():
                twist = Twist()
                twist.linear.x = 0.1
                pub.publish(twist)
                rate.sleep()
            pub.publish(Twist())
            rospy.sleep(0.3)
            print("SCAN", len(scan.ranges), "DEPTH", depth.encoding, depth.width, depth.height,
                  "X %.3f" % got["odom"].pose.pose.position.x, "WR %.2f" % got["wr"], flush=True)
            """
        )
    )
    done = real(sim, "/usr/bin/python3", str(script), timeout=90)
    assert done.returncode == 0, done.stderr
    words = done.stdout.split()
    assert words[:6] == ["SCAN", "360", "DEPTH", "16UC1", "320", "240"]
    assert 0.1 < float(words[7]) < 0.3  # about 2 s at 0.1 m/s, on the robot's odometry
