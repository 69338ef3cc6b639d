"""rviz and the rqt tools take the node name, namespace and remappings roslaunch gives them.

ROS 1's rviz and rqt ask for an anonymous node, but ``__name:=`` cancels that (roscpp's and
rospy's rule): ``<node pkg="rviz" type="rviz" name="viz" ns="robot1"/>`` is ``/robot1/viz`` on the
graph, so ``rosnode kill /robot1/viz`` and ``required="true"`` find it. Books' robot-description
launch files all start rviz this way (``name="rviz"``)."""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

from ninjemys.testing import CatkinWorkspace, kill_tree, ninjemys_bin, run_master, wait_until
from ninjemys.web.launched_name import launched_name


def test_name_ns_and_remappings_come_from_the_command_line() -> None:
    plain = launched_name("rviz", ["-d", "x.rviz"])
    assert (plain.name, plain.namespace, plain.remappings, plain.anonymous) == ("rviz", "/", {}, True)
    named = launched_name("rviz", ["-d", "x.rviz", "__name:=viz", "__ns:=/robot1", "tf:=/robot1/tf"])
    assert (named.name, named.namespace, named.anonymous) == ("viz", "/robot1/", False)
    assert named.remappings == {"tf": "/robot1/tf"}


def _nodes(env: dict[str, str]) -> list[str]:
    out = subprocess.run(
        [ninjemys_bin("rosnode"), "list"], env=env, capture_output=True, text=True, timeout=30, check=False
    )
    return out.stdout.split()


LAUNCH = """<launch>
  <group ns="robot1">
    <node pkg="rviz" type="rviz" name="viz" args="--no-browser"/>
  </group>
  <node pkg="rqt_plot" type="rqt_plot" name="plotter" args="--no-browser /odom/twist"/>
  <node pkg="rqt_graph" type="rqt_graph" name="graph" args="--no-browser"/>
</launch>
"""

PACKAGE_XML = """<?xml version="1.0"?>
<package format="2"><name>viewers</name><version>0.1.0</version><description>launch only</description>
  <maintainer email="t@example.com">t</maintainer><license>BSD</license>
  <buildtool_depend>catkin</buildtool_depend><exec_depend>rviz</exec_depend></package>
"""


def test_launched_rviz_and_rqt_tools_are_named_as_in_the_launch_file(tmp_path: Path) -> None:
    ws = CatkinWorkspace(tmp_path)
    ws.package(
        "viewers",
        {
            "package.xml": PACKAGE_XML,
            "CMakeLists.txt": "cmake_minimum_required(VERSION 3.0.2)\nproject(viewers)\n"
            "find_package(catkin REQUIRED)\ncatkin_package()\n",
            "launch/view.launch": LAUNCH,
        },
    )
    assert ws.catkin_make().returncode == 0
    with run_master() as uri:
        env = ws.env(uri)
        proc = subprocess.Popen(
            [ninjemys_bin("roslaunch"), "viewers", "view.launch"],
            env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, start_new_session=True,
        )  # fmt: skip
        try:
            wanted = {"/robot1/viz", "/plotter", "/graph"}
            wait_until(
                lambda: wanted <= set(_nodes(env)), timeout=60, what=f"nodes {sorted(wanted)}", step=0.5
            )
            assert not [n for n in _nodes(env) if n.startswith(("/rviz_", "/robot1/rviz_", "/rqt_plot_"))]
        finally:
            kill_tree(proc)


def test_rosrun_without_a_name_stays_anonymous() -> None:
    with run_master() as uri:
        env = dict(os.environ, ROS_MASTER_URI=uri)
        proc = subprocess.Popen(
            [ninjemys_bin("rosrun"), "rviz", "rviz", "--no-browser"],
            env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True,
        )  # fmt: skip
        try:
            wait_until(
                lambda: any(n.startswith("/rviz_") for n in _nodes(env)), timeout=60, what="/rviz_*", step=0.5
            )
        finally:
            kill_tree(proc)
