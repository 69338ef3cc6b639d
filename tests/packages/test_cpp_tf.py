"""C++ nodes on tf's C++ library (the navigation tutorials' robot_setup_tf and odometry_publisher, the
tf tutorials): with Debian's libtf-dev, which ``make test`` installs, catkin_make builds them, and they
exchange transforms with Python nodes through ninjemys' master both ways: a C++ TransformBroadcaster
read by a rospy ``tf.TransformListener``, and a rospy ``tf.TransformBroadcaster`` read by a C++
TransformListener that transforms a point, as the tutorial's listener does."""

from __future__ import annotations

import os
import re
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

from ninjemys.packages.cpp_build import find_toolchain
from ninjemys.packages.cpp_msgs import has_cpp_side, installed_prefixes
from ninjemys.testing import CatkinWorkspace, NodeProcess, run_master

PACKAGE_XML = """<?xml version="1.0"?>
<package format="2">
  <name>frames_probe</name>
  <version>0.1.0</version>
  <description>a robot's fixed laser frame in C++, as the navigation setup tutorial writes it</description>
  <maintainer email="t@example.com">t</maintainer>
  <license>BSD</license>
  <buildtool_depend>catkin</buildtool_depend>
  <depend>roscpp</depend>
  <depend>tf</depend>
  <depend>geometry_msgs</depend>
</package>
"""

CMAKE = """cmake_minimum_required(VERSION 3.0.2)
project(frames_probe)
find_package(catkin REQUIRED COMPONENTS roscpp tf geometry_msgs)
catkin_package()
include_directories(${catkin_INCLUDE_DIRS})
add_executable(laser_frame src/laser_frame.cpp)
target_link_libraries(laser_frame ${catkin_LIBRARIES})
add_executable(point_in_base src/point_in_base.cpp)
target_link_libraries(point_in_base ${catkin_LIBRARIES})
"""

BROADCASTER = r"""// base_link -> laser_mount, 0.15 m ahead and 0.25 m up, at 50 Hz
#include <ros/ros.h>
#include <tf/transform_broadcaster.h>

int main(int argc, char** argv)
{
  ros::init(argc, argv, "laser_frame");
  ros::NodeHandle n;
  tf::TransformBroadcaster broadcaster;
  ros::Rate rate(50);
  while (n.ok())
  {
    broadcaster.sendTransform(tf::StampedTransform(
        tf::Transform(tf::createQuaternionFromYaw(0.5), tf::Vector3(0.15, 0.0, 0.25)),
        ros::Time::now(), "base_link", "laser_mount"));
    rate.sleep();
  }
  return 0;
}
"""

LISTENER = r"""// a point 1 m ahead of the camera frame, in base_link, once a second
#include <ros/ros.h>
#include <geometry_msgs/PointStamped.h>
#include <tf/transform_listener.h>
#include <cstdio>

int main(int argc, char** argv)
{
  ros::init(argc, argv, "point_in_base");
  ros::NodeHandle n;
  tf::TransformListener listener;
  ros::Rate rate(5);
  while (n.ok())
  {
    geometry_msgs::PointStamped in;
    in.header.frame_id = "camera";
    in.header.stamp = ros::Time();
    in.point.x = 1.0;
    try
    {
      geometry_msgs::PointStamped out;
      listener.transformPoint("base_link", in, out);
      printf("in base_link: %.3f %.3f %.3f\n", out.point.x, out.point.y, out.point.z);
      fflush(stdout);
    }
    catch (tf::TransformException& ex)
    {
      printf("waiting: %s\n", ex.what());
      fflush(stdout);
    }
    rate.sleep();
  }
  return 0;
}
"""

PY_LISTENER = """
import rospy, tf
rospy.init_node("py_tf_reader")
listener = tf.TransformListener()
listener.waitForTransform("base_link", "laser_mount", rospy.Time(0), rospy.Duration(10))
trans, rot = listener.lookupTransform("base_link", "laser_mount", rospy.Time(0))
yaw = tf.transformations.euler_from_quaternion(rot)[2]
print("laser_mount %.3f %.3f %.3f yaw %.3f" % (trans[0], trans[1], trans[2], yaw), flush=True)
"""

PY_BROADCASTER = """
import rospy, tf
rospy.init_node("py_camera_frame")
broadcaster = tf.TransformBroadcaster()
rate = rospy.Rate(20)
while not rospy.is_shutdown():
    q = tf.transformations.quaternion_from_euler(0, 0, 1.5707963267948966)
    broadcaster.sendTransform((0.1, 0.0, 0.3), q, rospy.Time.now(), "camera", "base_link")
    rate.sleep()
"""

needs_tf_cpp = pytest.mark.skipif(
    find_toolchain(os.environ)[0] is None or not has_cpp_side("tf", installed_prefixes(os.environ)),
    reason="no C++ toolchain or no tf C++ side (Debian: libtf-dev, installed by make test)",
)


@pytest.fixture(scope="module")
def workspace(tmp_path_factory: pytest.TempPathFactory) -> CatkinWorkspace:
    ws = CatkinWorkspace(tmp_path_factory.mktemp("tf_cpp_ws"))
    files = {
        "package.xml": PACKAGE_XML,
        "CMakeLists.txt": CMAKE,
        "src/laser_frame.cpp": BROADCASTER,
        "src/point_in_base.cpp": LISTENER,
    }
    ws.package("frames_probe", files)
    result = ws.catkin_make(timeout=600)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "frames_probe: C++ program(s) built by catkin's CMake: laser_frame point_in_base" in result.stdout
    return ws


@pytest.fixture
def master() -> Iterator[str]:
    with run_master() as uri:
        yield uri


def _start(cmd: list[str], ws: CatkinWorkspace, master: str, cwd: Path) -> NodeProcess:
    return NodeProcess(cmd, ws.env(master), cwd)


@pytest.mark.ros1
@needs_tf_cpp
def test_a_cpp_tf_broadcaster_is_read_by_a_rospy_listener(workspace: CatkinWorkspace, master: str) -> None:
    broadcaster = _start(
        [str(workspace.root / "devel/lib/frames_probe/laser_frame")], workspace, master, workspace.root
    )
    script = workspace.root / "py_listener.py"
    script.write_text(PY_LISTENER)
    reader = _start([sys.executable, str(script)], workspace, master, workspace.root)
    try:
        reader.wait_for(r"^laser_mount 0\.150 0\.000 0\.250 yaw 0\.500$", timeout=30)
    finally:
        reader.kill()
        broadcaster.kill()


@pytest.mark.ros1
@needs_tf_cpp
def test_a_rospy_tf_broadcaster_is_read_by_a_cpp_listener(workspace: CatkinWorkspace, master: str) -> None:
    script = workspace.root / "py_broadcaster.py"
    script.write_text(PY_BROADCASTER)
    broadcaster = _start([sys.executable, str(script)], workspace, master, workspace.root)
    listener = _start(
        [str(workspace.root / "devel/lib/frames_probe/point_in_base")], workspace, master, workspace.root
    )
    try:
        # the camera is turned a quarter to the left: its x axis is base_link's y axis
        match = listener.wait_for(r"^in base_link: (\S+) (\S+) (\S+)$", timeout=30)
        assert [float(v) for v in match.groups()] == pytest.approx([0.1, 1.0, 0.3], abs=1e-3)
    finally:
        listener.kill()
        broadcaster.kill()


def test_the_tf_cpp_side_is_found_where_debian_installs_it() -> None:
    """The skip above is not silent on a machine set up by ``make test``: libtf-dev is in the Makefile."""
    makefile = Path(__file__).resolve().parents[2] / "Makefile"
    assert re.search(r"^ROS1_DEBS \+= libtf-dev$", makefile.read_text(), re.M)
