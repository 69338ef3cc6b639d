"""A PuzzleBot Gazebo package written the way the maker's course packages are (tests/sim/packages/
puzzlebot_gz_test: a xacro description with gazebo_ros_diff_drive or ros_control, a ray sensor turned
by pi and a camera, a .world with included models, a launch file including empty_world.launch with
spawn_model, robot_state_publisher and the controller spawner) starts unchanged under roslaunch;
Debian's rostopic and rospy read its topics under the description's names, and a rospy controller
drives it on its cmd_vel, checked against /gazebo/model_states."""

from __future__ import annotations

import os
import subprocess
from collections.abc import Iterator
from pathlib import Path

import pytest
from gazebo_helpers import Launched, genpy_gazebo_msgs

from ninjemys.testing import have_ros1, ninjemys_bin, ros1_env, run_master

pytestmark = [pytest.mark.ros1, pytest.mark.skipif(not have_ros1(), reason="needs Debian's ROS 1")]

PACKAGES = Path(__file__).parent / "packages"

_DRIVE = """
import sys, rospy
from geometry_msgs.msg import Twist
from gazebo_msgs.msg import ModelStates
from sensor_msgs.msg import Image, LaserScan
rospy.init_node("course_controller")
scan = rospy.wait_for_message("/scan", LaserScan, timeout=60)
image = rospy.wait_for_message("/camera/image_raw", Image, timeout=60)
print("SCAN", scan.header.frame_id, len(scan.ranges), "IMAGE", image.width, image.height, flush=True)
def x():
    m = rospy.wait_for_message("/gazebo/model_states", ModelStates, timeout=30)
    return m.pose[m.name.index("puzzlebot")].position.x
start = x()
pub = rospy.Publisher(sys.argv[1], Twist, queue_size=1)
t = Twist(); t.linear.x = 0.3
deadline = rospy.get_time() + 20.0
while rospy.get_time() < deadline and x() - start < 0.3:
    pub.publish(t); rospy.sleep(0.05)
pub.publish(Twist())
print("MOVED %.3f" % (x() - start), flush=True)
"""


@pytest.fixture(scope="module")
def genpy(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return genpy_gazebo_msgs(tmp_path_factory.mktemp("genpy"))


@pytest.fixture
def master(tmp_path: Path) -> Iterator[str]:
    env = dict(os.environ, ROS_HOME=str(tmp_path), ROS_LOG_DIR=str(tmp_path))
    with run_master(env=env) as uri:
        yield uri


@pytest.mark.parametrize(
    ("control", "cmd_vel"), [("gazebo", "/cmd_vel"), ("ros_control", "/puzzlebot_controller/cmd_vel")]
)
def test_the_course_package_runs_unchanged(
    master: str, genpy: Path, tmp_path: Path, control: str, cmd_vel: str
) -> None:
    env = dict(os.environ, ROS_MASTER_URI=master, ROS_HOME=str(tmp_path), ROS_LOG_DIR=str(tmp_path),
               ROS_PACKAGE_PATH=str(PACKAGES), PYTHONUNBUFFERED="1")  # fmt: skip
    launch = Launched(
        [ninjemys_bin("roslaunch"), "puzzlebot_gz_test", "puzzlebot_gazebo.launch", f"control:={control}"],
        env,
        tmp_path / "launch.log",
    )
    try:
        launch.wait_for("Successfully spawned", timeout=60)
        if control == "ros_control":
            launch.wait_for("Started controllers", timeout=60)
        real = ros1_env(master, PYTHONPATH=str(genpy))
        echo = subprocess.run(["/usr/bin/rostopic", "echo", "-n", "1", "/scan/header/frame_id"], env=real,
                              capture_output=True, text=True, timeout=60)  # fmt: skip
        assert "laser_frame" in echo.stdout, echo
        # what Gazebo publishes for this description: its p3d plugin's ground truth, no contact topic
        listed = subprocess.run(["/usr/bin/rostopic", "list"], env=real, capture_output=True, text=True,
                                timeout=60).stdout.split()  # fmt: skip
        assert "/ground_truth/state" in listed and "/contact" not in listed, listed
        assert "/base_pose_ground_truth" not in listed, listed
        truth = subprocess.run(["/usr/bin/rostopic", "echo", "-n", "1", "/ground_truth/state/child_frame_id"],
                               env=real, capture_output=True, text=True, timeout=60)  # fmt: skip
        assert "base_link" in truth.stdout, truth
        drive = subprocess.run(["/usr/bin/python3", "-c", _DRIVE, cmd_vel], env=real, capture_output=True,
                               text=True, timeout=120)  # fmt: skip
        assert drive.returncode == 0, drive.stderr[-2000:]
        words = drive.stdout.split()
        assert words[:3] == ["SCAN", "laser_frame", "360"] and words[4:6] == ["640", "480"], drive.stdout
        moved = float(drive.stdout.split("MOVED")[1])
        print(f"{control}: moved {moved:.3f} m on {cmd_vel}")
        assert moved >= 0.3
    finally:
        launch.stop()
