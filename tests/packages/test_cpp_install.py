"""``catkin_make install`` installs C++ programs and libraries as catkin does: a package's
``install(TARGETS ...)`` rules put the node in ``lib/<pkg>/`` and its library in ``lib/``, the same
files as Debian's catkin_make install lays out, and after ``source install/setup.bash`` (sources and
build gone) ``rosrun pkg node`` runs the installed program against ninjemys' master."""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import pytest

from ninjemys.packages.cpp_build import cmake_env, find_toolchain
from ninjemys.testing import CatkinWorkspace, kill_tree, ninjemys_bin, run_master

PACKAGE_XML = """<?xml version="1.0"?>
<package format="2">
  <name>cpp_inst</name>
  <version>0.1.0</version>
  <description>A C++ node and library with install rules</description>
  <maintainer email="t@example.com">t</maintainer>
  <license>BSD</license>
  <buildtool_depend>catkin</buildtool_depend>
  <depend>roscpp</depend>
  <depend>std_msgs</depend>
</package>
"""

CMAKE = """cmake_minimum_required(VERSION 3.0.2)
project(cpp_inst)
find_package(catkin REQUIRED COMPONENTS roscpp std_msgs)
catkin_package(INCLUDE_DIRS include LIBRARIES greeting CATKIN_DEPENDS roscpp std_msgs)
include_directories(include ${catkin_INCLUDE_DIRS})
add_library(greeting src/greeting.cpp)
target_link_libraries(greeting ${catkin_LIBRARIES})
add_executable(talker_node src/talker.cpp)
target_link_libraries(talker_node greeting ${catkin_LIBRARIES})
install(TARGETS greeting
  ARCHIVE DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  LIBRARY DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  RUNTIME DESTINATION ${CATKIN_GLOBAL_BIN_DESTINATION})
install(TARGETS talker_node RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})
install(DIRECTORY include/${PROJECT_NAME}/ DESTINATION ${CATKIN_PACKAGE_INCLUDE_DESTINATION})
install(DIRECTORY launch DESTINATION ${CATKIN_PACKAGE_SHARE_DESTINATION})
"""

FILES = {
    "package.xml": PACKAGE_XML,
    "CMakeLists.txt": CMAKE,
    "include/cpp_inst/greeting.h": "#include <string>\nstd::string greeting(int n);\n",
    "src/greeting.cpp": (
        "#include <cpp_inst/greeting.h>\n#include <sstream>\n"
        'std::string greeting(int n) { std::ostringstream o; o << "installed hello " << n; return o.str(); }\n'
    ),
    "src/talker.cpp": """// Publishes the shared library's greeting on /chatter.
#include <ros/ros.h>
#include <std_msgs/String.h>
#include <cpp_inst/greeting.h>
int main(int argc, char **argv) {
  ros::init(argc, argv, "installed_talker");
  ros::NodeHandle nh;
  ros::Publisher pub = nh.advertise<std_msgs::String>("chatter", 10);
  ros::Rate rate(10);
  for (int i = 0; ros::ok(); ++i) {
    std_msgs::String m;
    m.data = greeting(i);
    pub.publish(m);
    ros::spinOnce();
    rate.sleep();
  }
  return 0;
}
""",
    "launch/talk.launch": '<launch>\n  <node pkg="cpp_inst" type="talker_node" name="talker"/>\n</launch>\n',
}

pytestmark = [
    pytest.mark.ros1,
    pytest.mark.skipif(find_toolchain(os.environ)[0] is None, reason="no C++ toolchain"),
    pytest.mark.skipif(not Path("/usr/bin/catkin_make").exists(), reason="no Debian catkin"),
]


def _package_files(prefix: Path) -> set[str]:
    """The installed files of the package (catkin's own top-level files and ours differ by design)."""
    return {
        str(p.relative_to(prefix))
        for p in prefix.rglob("*")
        if p.is_file() and ("cpp_inst" in p.relative_to(prefix).parts or p.name.startswith("libgreeting"))
    }


def test_cpp_programs_install_like_debians_catkin_make_and_run_from_the_install_space(tmp_path: Path) -> None:
    debian = tmp_path / "debian"
    CatkinWorkspace(debian).package("cpp_inst", FILES)
    result = subprocess.run(
        ["/usr/bin/catkin_make", "install"],
        cwd=debian, env={"PATH": "/usr/bin:/bin", "HOME": str(tmp_path), "LANG": "C.UTF-8"},
        capture_output=True, text=True, timeout=600, check=False,
    )  # fmt: skip
    assert result.returncode == 0, result.stdout + result.stderr
    ours = CatkinWorkspace(tmp_path / "ours")
    ours.package("cpp_inst", FILES)
    result = ours.catkin_make("install")
    assert result.returncode == 0, result.stdout + result.stderr
    expected = _package_files(debian / "install")
    assert {"lib/cpp_inst/talker_node", "lib/libgreeting.so", "include/cpp_inst/greeting.h"} <= expected
    assert "share/cpp_inst/launch/talk.launch" in expected
    assert _package_files(ours.root / "install") == expected
    assert os.access(ours.root / "install" / "lib" / "cpp_inst" / "talker_node", os.X_OK)

    # the install space is a copy: it works with the sources, build and devel spaces gone
    for space in ("src", "build", "devel"):
        shutil.rmtree(ours.root / space)
    env = {
        k: v
        for k, v in ours.env().items()
        if k not in ("ROS_PACKAGE_PATH", "PYTHONPATH", "CMAKE_PREFIX_PATH")
    }
    env.pop("LD_LIBRARY_PATH", None)
    setup = ours.root / "install" / "setup.bash"
    with run_master() as uri:
        env["ROS_MASTER_URI"] = uri
        talker = subprocess.Popen(
            ["bash", "-c", f'source "{setup}" && exec rosrun cpp_inst talker_node'],
            env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, start_new_session=True,
        )  # fmt: skip
        try:
            heard = subprocess.run(
                ["bash", "-c", f'source "{setup}" && exec {ninjemys_bin("rostopic")} echo -n 1 /chatter'],
                env=env, capture_output=True, text=True, timeout=90, check=False,
            )  # fmt: skip
        finally:
            kill_tree(talker)
        output = talker.stdout.read() if talker.stdout else ""
        assert 'data: "installed hello ' in heard.stdout, heard.stdout + heard.stderr + output


def test_cmake_install_prefix_moves_the_cpp_programs_too(tmp_path: Path) -> None:
    ours = CatkinWorkspace(tmp_path)
    ours.package("cpp_inst", FILES)
    result = ours.catkin_make("install", "-DCMAKE_INSTALL_PREFIX=elsewhere")
    assert result.returncode == 0, result.stdout + result.stderr
    assert (tmp_path / "elsewhere" / "lib" / "cpp_inst" / "talker_node").is_file()
    assert (tmp_path / "elsewhere" / "lib" / "libgreeting.so").is_file()
    assert not (tmp_path / "install").exists()
    assert f"prefix {tmp_path / 'elsewhere'}" in result.stdout
    # the everyday loop: a shell that sourced the workspace (ROS_DISTRO=noetic, the install space on
    # CMAKE_PREFIX_PATH) builds again; Debian's catkin env hook must not break the C++ configure
    for setup in ("devel/setup.bash", "elsewhere/setup.bash"):
        again = subprocess.run(
            ["bash", "-c", f"source {setup} && exec catkin_make install -DCMAKE_INSTALL_PREFIX=elsewhere"],
            cwd=tmp_path, env=ours.env(), capture_output=True, text=True, timeout=600, check=False,
        )  # fmt: skip
        assert again.returncode == 0, setup + again.stdout + again.stderr


def test_catkins_cmake_runs_without_the_shells_ros_distro() -> None:
    env = cmake_env({"ROS_DISTRO": "noetic", "PATH": "/usr/bin"})
    assert env == {"PATH": "/usr/bin"}
