"""roslint, as the ETH ros_package_template and many C++ packages use it: ``find_package(catkin REQUIRED
COMPONENTS roscpp roslint)`` and ``roslint_cpp()`` in CMakeLists.txt. The package builds (its C++
node too, where a toolchain exists), and ``catkin_make roslint_<pkg>`` lints with the ROS style
rules (braces on their own lines, 120 columns, ROS header guards) and fails on an error, as make does.
Debian has no roslint, so there is nothing to run beside; the rules are read from the ROS style guide."""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

import pytest

from ninjemys.packages.cpp_build import find_toolchain
from ninjemys.testing import CatkinWorkspace, ninjemys_bin

PACKAGE_XML = """<?xml version="1.0"?>
<package format="2">
  <name>{name}</name>
  <version>0.1.0</version>
  <description>a package in the style of a lab template, linted with roslint</description>
  <maintainer email="t@example.com">t</maintainer>
  <license>BSD</license>
  <buildtool_depend>catkin</buildtool_depend>
  <depend>roscpp</depend>
  <depend>sensor_msgs</depend>
  <build_depend>roslint</build_depend>
</package>
"""

CMAKE = """cmake_minimum_required(VERSION 3.10)
project(lint_probe)
set(CMAKE_CXX_STANDARD 14)
find_package(catkin REQUIRED
  COMPONENTS
    roscpp
    sensor_msgs
    roslint
)
catkin_package(INCLUDE_DIRS include LIBRARIES ${PROJECT_NAME}_core CATKIN_DEPENDS roscpp sensor_msgs)
include_directories(include ${catkin_INCLUDE_DIRS})
add_library(${PROJECT_NAME}_core src/running_mean.cpp)
add_executable(${PROJECT_NAME} src/lint_probe_node.cpp)
target_link_libraries(${PROJECT_NAME} ${PROJECT_NAME}_core ${catkin_LIBRARIES})
roslint_cpp()
"""

HEADER = """// Copyright 2026 ninjemys tests
#ifndef LINT_PROBE_RUNNING_MEAN_H
#define LINT_PROBE_RUNNING_MEAN_H

namespace lint_probe
{
class RunningMean
{
public:
  void add(double value);
  double mean() const;

private:
  double sum_ = 0.0;
  int count_ = 0;
};
}  // namespace lint_probe

#endif  // LINT_PROBE_RUNNING_MEAN_H
"""

LIBRARY = """// Copyright 2026 ninjemys tests
#include "lint_probe/running_mean.h"

namespace lint_probe
{
void RunningMean::add(double value)
{
  sum_ += value;
  ++count_;
}

double RunningMean::mean() const
{
  return count_ == 0 ? 0.0 : sum_ / count_;
}
}  // namespace lint_probe
"""

NODE = """// Copyright 2026 ninjemys tests
#include <ros/ros.h>
#include <sensor_msgs/Temperature.h>
#include "lint_probe/running_mean.h"

lint_probe::RunningMean mean;

void onTemperature(const sensor_msgs::Temperature& msg)
{
  mean.add(msg.temperature);
  ROS_INFO("mean %f", mean.mean());
}

int main(int argc, char** argv)
{
  ros::init(argc, argv, "lint_probe");
  ros::NodeHandle nh("~");
  ros::Subscriber sub = nh.subscribe("/temperature", 10, onTemperature);
  ros::spin();
  return 0;
}
"""

needs_toolchain = pytest.mark.skipif(find_toolchain(os.environ)[0] is None, reason="no C++ toolchain")


def _workspace(root: Path, extra: dict[str, str] | None = None, cmake: str = CMAKE) -> CatkinWorkspace:
    ws = CatkinWorkspace(root)
    files = {
        "package.xml": PACKAGE_XML.format(name="lint_probe"),
        "CMakeLists.txt": cmake,
        "include/lint_probe/running_mean.h": HEADER,
        "src/running_mean.cpp": LIBRARY,
        "src/lint_probe_node.cpp": NODE,
        **(extra or {}),
    }
    ws.package("lint_probe", files)
    return ws


def _catkin_make(ws: CatkinWorkspace, *targets: str, cpp: bool) -> subprocess.CompletedProcess[str]:
    env = dict(ws.env(), NINJEMYS_CATKIN_CPP="1" if cpp else "0")
    return subprocess.run(
        [str(ninjemys_bin("catkin_make")), *targets],
        cwd=ws.root,
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
    )


def test_roslint_is_a_known_package(tmp_path: Path) -> None:
    ws = CatkinWorkspace(tmp_path)
    found = subprocess.run(
        [str(ninjemys_bin("rospack")), "find", "roslint"], env=ws.env(), capture_output=True, text=True
    )
    assert found.returncode == 0 and found.stdout.strip().endswith("roslint"), found.stderr
    listed = subprocess.run(
        [str(ninjemys_bin("rospack")), "list"], env=ws.env(), capture_output=True, text=True
    )
    assert any(line.split()[0] == "roslint" for line in listed.stdout.splitlines())


def test_a_package_on_roslint_builds_without_the_cpp_build(tmp_path: Path) -> None:
    result = _catkin_make(_workspace(tmp_path), cpp=False)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "roslint" not in result.stderr


@needs_toolchain
def test_its_cpp_node_is_built_by_catkins_cmake_with_roslints_functions(tmp_path: Path) -> None:
    ws = _workspace(tmp_path)
    result = _catkin_make(ws, cpp=True)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "lint_probe: C++ program(s) built by catkin's CMake: lint_probe" in result.stdout
    assert "not built" not in result.stdout
    program = tmp_path / "devel" / "lib" / "lint_probe" / "lint_probe"
    assert os.access(program.resolve(), os.X_OK)
    # the CMake target roslint_cpp() made runs the same linter (make in catkin's build tree)
    lint = subprocess.run(
        ["make", "roslint_lint_probe"],
        cwd=tmp_path / "build" / "ninjemys_cpp" / "build",
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert lint.returncode == 0, lint.stdout + lint.stderr
    assert "Total errors found" not in lint.stdout + lint.stderr


BAD = """// Copyright 2026 ninjemys tests
#include <vector>
#include <string>
#include <iostream>

int sum(const std::vector<int>& values) {
  int total = 0;
  for (int v : values)
  {
    total += v;
  }
  std::cout << "a line that is long but still within the one hundred and twenty columns of ROS style" << total;
  std::cout << "a line that is longer than the one hundred and twenty columns which the ROS C++ style guide allows, by far" << total;
  return total; }
"""

GUARD = """// Copyright 2026 ninjemys tests
#ifndef THING_H
#define THING_H
#endif  // THING_H
"""


def test_catkin_make_roslint_reports_ros_style_errors_and_fails(tmp_path: Path) -> None:
    ws = _workspace(tmp_path, {"src/bad.cpp": BAD, "include/lint_probe/thing.h": GUARD})
    assert _catkin_make(ws, cpp=False).returncode == 0
    result = _catkin_make(ws, "roslint_lint_probe", cpp=False)
    assert result.returncode == 1
    out = result.stdout + result.stderr
    bad = tmp_path / "src" / "lint_probe" / "src" / "bad.cpp"
    assert (
        f"{bad}:6:  when starting a new scope, {{ should be on a line by itself  [whitespace/braces] [4]"
        in out
    )
    assert f"{bad}:14:  }} should be on a line by itself  [whitespace/braces] [4]" in out
    assert f"{bad}:13:  Lines should be <= 120 characters long  [whitespace/line_length] [2]" in out
    assert f"{bad}:12:" not in out  # 110 columns are fine in ROS style (Google's limit is 80)
    assert "include_order" not in out and "runtime/references" not in out
    guard = tmp_path / "src" / "lint_probe" / "include" / "lint_probe" / "thing.h"
    assert f"{guard}:2:  #ifndef header guard has wrong style, please use: LINT_PROBE_THING_H" in out
    assert "Total errors found: 5" in out
    assert 'Invoking "make roslint_lint_probe" failed' in result.stderr
    # the package's own files are clean: the same target passes once the bad ones are gone
    bad.unlink()
    guard.unlink()
    result = _catkin_make(ws, "roslint", cpp=False)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "[100%] Built target roslint" in result.stdout


def test_roslint_python_and_its_options(tmp_path: Path) -> None:
    cmake = CMAKE.replace(
        "roslint_cpp()", 'set(ROSLINT_PYTHON_OPTS "--ignore=E226")\nroslint_python(scripts/node.py)'
    )
    script = "import os\nx=1\ny = x*2\n" + "z = '" + "a" * 100 + "'\n"
    ws = _workspace(tmp_path, {"scripts/node.py": script}, cmake=cmake)
    result = _catkin_make(ws, "roslint", cpp=False)
    assert result.returncode == 1
    assert "scripts/node.py:2:2: E225 missing whitespace around operator" in result.stdout
    assert "E226" not in result.stdout and "E501" not in result.stdout  # 110 columns: within 120
    assert "F401" not in result.stdout  # pycodestyle, not a full linter


def test_rosrun_roslint_cpplint_and_an_unknown_target(tmp_path: Path) -> None:
    ws = _workspace(tmp_path)
    source = tmp_path / "src" / "lint_probe" / "src" / "running_mean.cpp"
    result = subprocess.run(
        [str(ninjemys_bin("rosrun")), "roslint", "cpplint", str(source)],
        env=ws.env(),
        capture_output=True,
        text=True,
    )
    assert result.returncode == 0, result.stderr
    assert f"Done processing {source}" in result.stdout + result.stderr
    result = _catkin_make(ws, "roslint_other_pkg", cpp=False)
    assert result.returncode == 1
    assert "make: *** No rule to make target 'roslint_other_pkg'.  Stop." in result.stderr
