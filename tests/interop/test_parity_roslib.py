"""``roslib`` and ``rospkg`` as ROS 1 programs use them: ``roslib.load_manifest`` at the top of old
scripts (the tf tutorials), ``rospkg.RosPack().get_path`` to find a package's files."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from ninjemys import testing

PROGRAM = r"""
import sys
import roslib
roslib.load_manifest("learning_tf")
import rospkg
import roslib.packages
rp = rospkg.RosPack()
print(rp.get_path("learning_tf") == sys.argv[1])
print("learning_tf" in rp.list())
try:
    roslib.load_manifest("no_such_package_here")
except rospkg.ResourceNotFound as exc:
    print(type(exc).__name__, str(exc).splitlines()[0])
try:
    rp.get_path("no_such_package_here")
except rospkg.ResourceNotFound as exc:
    print(type(exc).__name__, str(exc).splitlines()[0])
from roslib.message import get_message_class
print(get_message_class("std_msgs/String")._type, get_message_class("nope/Nope"))
roslib.set_interactive(True)
print(roslib.is_interactive())
"""

#: checked on ours only: roslib.packages.get_pkg_dir runs the C++ rospack in ROS 1 (not installed
#: here), and Debian's rospkg lists no dependencies of format-2 package.xml files (rospack does)
PKG_DIR = r"""
print(rp.get_depends("learning_tf", implicit=False))
print(roslib.packages.get_pkg_dir("learning_tf") == sys.argv[1])
print(roslib.packages.get_pkg_dir("no_such_package_here", required=False))
try:
    roslib.packages.get_pkg_dir("no_such_package_here")
except roslib.packages.InvalidROSPkgException as exc:
    print(type(exc).__name__)
"""


def workspace(tmp_path: Path) -> Path:
    pkg = tmp_path / "src" / "learning_tf"
    pkg.mkdir(parents=True)
    (pkg / "package.xml").write_text(
        '<?xml version="1.0"?>\n<package format="2"><name>learning_tf</name><version>0.0.1</version>'
        "<description>d</description><maintainer email='ros@example.org'>Tutorial Author</maintainer><license>BSD</license>"
        "<buildtool_depend>catkin</buildtool_depend><depend>std_msgs</depend></package>\n"
    )
    return pkg


def run(python: str, pkg: Path, env: dict[str, str], program: str = PROGRAM) -> list[str]:
    env = {
        **env,
        "ROS_PACKAGE_PATH": str(pkg.parent)
        + (":" + env["ROS_PACKAGE_PATH"] if env.get("ROS_PACKAGE_PATH") else ""),
    }
    done = subprocess.run(
        [python, "-c", program, str(pkg)], capture_output=True, text=True, env=env, timeout=60
    )
    assert done.returncode == 0, done.stderr
    return done.stdout.splitlines()


def test_load_manifest_and_rospack(tmp_path: Path) -> None:
    import os

    pkg = workspace(tmp_path)
    env = {k: v for k, v in os.environ.items() if k != "ROS_PACKAGE_PATH"}
    lines = run(sys.executable, pkg, env, PROGRAM + PKG_DIR)
    assert lines == [
        "True",
        "True",
        "ResourceNotFound no_such_package_here",
        "ResourceNotFound no_such_package_here",
        "std_msgs/String None",
        "True",
        "['std_msgs']",
        "True",
        "None",
        "InvalidROSPkgException",
    ]


@pytest.mark.ros1
def test_same_answers_as_ros1(tmp_path: Path) -> None:
    import os

    pkg = workspace(tmp_path)
    theirs = run(
        testing.ROS1_PYTHON, pkg, testing.ros1_env("http://localhost:11311", ROS_PACKAGE_PATH="/usr/share")
    )
    ours = run(sys.executable, pkg, {k: v for k, v in os.environ.items() if k != "ROS_PACKAGE_PATH"})
    assert ours == theirs
