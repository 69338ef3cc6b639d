"""The turtlebot3_gazebo pattern, unchanged under roslaunch (tests/sim/packages/arena_bot_test).

ROBOTIS' ``turtlebot3_world.launch`` (and the courses that copy it): the model type from an
environment variable (``$(env TURTLEBOT3_MODEL)``), ``xacro --inorder``, ``empty_world.launch`` with a
world of the package's own models (found through its ``gazebo_model_path`` export) beside Gazebo's
``sun`` and ``ground_plane``, and ``spawn_model -urdf -model NAME -x -y -z -param robot_description``
of a robot whose root link is its footprint. Student code then reads ``/gazebo/model_states`` by
index (``msg.pose[2]``): Gazebo lists the ground plane first, the world's models in the file's
order, then the robot, standing on the floor. Debian's rospy reads it and drives the robot."""

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

_READ_AND_DRIVE = """
import rospy
from geometry_msgs.msg import Twist
from gazebo_msgs.msg import ModelStates
from sensor_msgs.msg import LaserScan
rospy.init_node("arena_reader")
m = rospy.wait_for_message("/gazebo/model_states", ModelStates, timeout=30)
print("NAMES", ",".join(m.name))
p = m.pose[2].position
print("ROBOT %.4f %.4f %.4f" % (p.x, p.y, p.z))
scan = rospy.wait_for_message("/scan", LaserScan, timeout=30)
ahead = scan.ranges[0]
print("SCAN %d %.7f %.3f %s" % (len(scan.ranges), scan.angle_increment, ahead, scan.header.frame_id))
pub = rospy.Publisher("/cmd_vel", Twist, queue_size=1)
cmd = Twist(); cmd.linear.x = 0.2
deadline = rospy.get_time() + 20.0
while rospy.get_time() < deadline:
    pub.publish(cmd); rospy.sleep(0.05)
    m = rospy.wait_for_message("/gazebo/model_states", ModelStates, timeout=30)
    if m.pose[2].position.x > p.x + 0.5:
        break
pub.publish(Twist())
print("MOVED %.3f" % (m.pose[2].position.x - p.x), flush=True)
"""


@pytest.fixture(scope="module")
def genpy(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return genpy_gazebo_msgs(tmp_path_factory.mktemp("genpy"))


@pytest.fixture
def master(tmp_path: Path) -> Iterator[str]:
    env = dict(os.environ, ROS_HOME=str(tmp_path), ROS_LOG_DIR=str(tmp_path))
    with run_master(env=env) as uri:
        yield uri


def test_the_turtlebot3_world_pattern_lists_models_as_gazebo_and_drives(
    master: str, genpy: Path, tmp_path: Path
) -> None:
    env = dict(os.environ, ROS_MASTER_URI=master, ROS_HOME=str(tmp_path), ROS_LOG_DIR=str(tmp_path),
               ROS_PACKAGE_PATH=str(PACKAGES), PYTHONUNBUFFERED="1", GAZEBO_MODEL_PATH="",
               ARENA_BOT_MODEL="small")  # fmt: skip
    launch = Launched(
        [ninjemys_bin("roslaunch"), "arena_bot_test", "arena.launch"], env, tmp_path / "launch.log"
    )
    try:
        # spawn_model's own output goes to its log file (no output="screen" in this pattern)
        launch.wait_for("spawned robot [arena_bot_small]", timeout=60)
        real = ros1_env(master, PYTHONPATH=str(genpy))
        run = subprocess.run(["/usr/bin/python3", "-c", _READ_AND_DRIVE], env=real, capture_output=True,
                             text=True, timeout=120)  # fmt: skip
        assert run.returncode == 0, run.stderr[-2000:]
        out = dict(line.split(" ", 1) for line in run.stdout.splitlines() if " " in line)
        # Gazebo's order: the ground plane, the world's model (named by its model.sdf), the robot
        assert out["NAMES"] == "ground_plane,arena,arena_bot_small"
        # the robot's root is its footprint: it stands at z 0 where -x -y put it
        assert [float(v) for v in out["ROBOT"].split()] == pytest.approx([-1.0, -0.5, 0.0], abs=1e-3)
        beams, increment, ahead, frame = out["SCAN"].split()
        assert (int(beams), frame) == (360, "base_scan")
        assert float(increment) == pytest.approx(
            6.28319 / 359, rel=1e-5
        )  # Gazebo's (max - min) / (samples - 1)
        # straight ahead (beam 0: +x, at y -0.5: past the pillar): the east wall's face at x 1.95,
        # from the lidar at x -1.0 - 0.032
        assert float(ahead) == pytest.approx(1.95 - (-1.0 - 0.032), abs=0.03)
        assert float(out["MOVED"]) >= 0.5
    finally:
        launch.stop()
